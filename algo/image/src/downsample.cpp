// YUYV → low-resolution luma and chroma by block averaging (§3.4: 640x480 → 160x120).
#include "algo/image/low_res_frame.h"

namespace boticelli::image {

bool downsample_yuyv(const std::uint8_t* yuyv, std::uint32_t width, std::uint32_t height,
                     std::uint32_t stride_bytes, std::uint32_t factor, LowResFrame& out) {
  out.width = 0;
  out.height = 0;
  if (yuyv == nullptr || factor < 2 || factor % 2 != 0 || width % 2 != 0 ||
      stride_bytes < 2 * width) {
    return false;
  }
  const std::uint32_t low_w = width / factor;
  const std::uint32_t low_h = height / factor;
  if (low_w == 0 || low_h == 0 || low_w > LowResFrame::kMaxWidth ||
      low_h > LowResFrame::kMaxHeight) {
    return false;
  }
  out.width = low_w;
  out.height = low_h;
  const float luma_scale = 1.0F / static_cast<float>(factor * factor);
  const std::uint32_t chroma_count = factor * factor / 2;
  const std::uint32_t block_bytes = 2 * factor;
  // Column sums of one output row, accumulated over the block's rows.
  std::array<std::uint32_t, LowResFrame::kMaxWidth> sum_y{};
  std::array<std::uint32_t, LowResFrame::kMaxWidth> sum_u{};
  std::array<std::uint32_t, LowResFrame::kMaxWidth> sum_v{};
  if (factor == 4) {
    // The thesis's case (640x480 → 160x120): first add the block's four rows bytewise
    // (a loop the compiler vectorises), then fold each 8-byte run Y U Y V Y U Y V.
    std::array<std::uint16_t, std::size_t{LowResFrame::kMaxWidth} * 8> rows{};
    const std::size_t row_bytes = std::size_t{low_w} * 8;
    for (std::uint32_t lv = 0; lv < low_h; ++lv) {
      const std::uint8_t* r0 = yuyv + std::size_t{lv} * 4 * stride_bytes;
      const std::uint8_t* r1 = r0 + stride_bytes;
      const std::uint8_t* r2 = r1 + stride_bytes;
      const std::uint8_t* r3 = r2 + stride_bytes;
      for (std::size_t i = 0; i < row_bytes; ++i) {
        rows[i] = static_cast<std::uint16_t>(r0[i] + r1[i] + r2[i] + r3[i]);
      }
      const std::size_t base = out.index(0, lv);
      for (std::uint32_t lu = 0; lu < low_w; ++lu) {
        const std::uint16_t* p = rows.data() + std::size_t{lu} * 8;
        const std::uint32_t y = std::uint32_t{p[0]} + p[2] + p[4] + p[6];
        const std::uint32_t u = std::uint32_t{p[1]} + p[5];
        const std::uint32_t v = std::uint32_t{p[3]} + p[7];
        out.luma[base + lu] = static_cast<float>(y) * (1.0F / 16.0F);
        out.chroma_u[base + lu] = static_cast<std::uint8_t>((u + 4) / 8);
        out.chroma_v[base + lu] = static_cast<std::uint8_t>((v + 4) / 8);
      }
    }
    return true;
  }
  for (std::uint32_t lv = 0; lv < low_h; ++lv) {
    sum_y.fill(0);
    sum_u.fill(0);
    sum_v.fill(0);
    for (std::uint32_t r = 0; r < factor; ++r) {
      const std::uint8_t* row = yuyv + std::size_t{lv * factor + r} * stride_bytes;
      for (std::uint32_t lu = 0; lu < low_w; ++lu) {
        const std::uint8_t* p = row + std::size_t{lu} * block_bytes;
        std::uint32_t y = 0;
        std::uint32_t u = 0;
        std::uint32_t v = 0;
        for (std::uint32_t k = 0; k < block_bytes; k += 4) {
          y += std::uint32_t{p[k]} + p[k + 2];
          u += p[k + 1];
          v += p[k + 3];
        }
        sum_y[lu] += y;
        sum_u[lu] += u;
        sum_v[lu] += v;
      }
    }
    for (std::uint32_t lu = 0; lu < low_w; ++lu) {
      const std::size_t i = out.index(lu, lv);
      out.luma[i] = static_cast<float>(sum_y[lu]) * luma_scale;
      out.chroma_u[i] = static_cast<std::uint8_t>((sum_u[lu] + chroma_count / 2) / chroma_count);
      out.chroma_v[i] = static_cast<std::uint8_t>((sum_v[lu] + chroma_count / 2) / chroma_count);
    }
  }
  return true;
}

}  // namespace boticelli::image
