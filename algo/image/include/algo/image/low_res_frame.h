// Low-resolution frame: camera YUYV averaged in 4x4 blocks to luma and chroma planes.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>

namespace boticelli::image {

// Fixed-capacity planes at the processing resolution (thesis §3.4: 640x480 averaged to
// 160x120). Capacity allows camera frames up to 1280x960. Pixel (u, v) is column u, row v.
struct LowResFrame {
  static constexpr std::uint32_t kMaxWidth = 320;
  static constexpr std::uint32_t kMaxHeight = 240;
  static constexpr std::size_t kMaxPixels = std::size_t{kMaxWidth} * kMaxHeight;

  std::uint32_t width = 0;                          // [px]
  std::uint32_t height = 0;                         // [px]
  std::array<float, kMaxPixels> luma{};             // Y averaged over the block, grey levels 0..255
  std::array<std::uint8_t, kMaxPixels> chroma_u{};  // U (Cb) averaged, 128 = neutral
  std::array<std::uint8_t, kMaxPixels> chroma_v{};  // V (Cr) averaged, 128 = neutral

  [[nodiscard]] std::size_t index(std::uint32_t u, std::uint32_t v) const {
    return std::size_t{v} * width + u;
  }
  [[nodiscard]] float y(std::uint32_t u, std::uint32_t v) const { return luma[index(u, v)]; }
  // Chroma as signed offsets from neutral grey.
  [[nodiscard]] int cb(std::uint32_t u, std::uint32_t v) const {
    return int{chroma_u[index(u, v)]} - 128;
  }
  [[nodiscard]] int cr(std::uint32_t u, std::uint32_t v) const {
    return int{chroma_v[index(u, v)]} - 128;
  }
};

// Averages a packed YUYV frame (Y0 U Y1 V per pixel pair) in factor x factor blocks.
// width must be even; rows may be padded (stride_bytes ≥ 2·width). Pixels beyond a whole
// block at the right and bottom edges are dropped. factor must be even (U and V are shared
// by pixel pairs). Returns false, leaving `out` empty, if the result would not fit.
bool downsample_yuyv(const std::uint8_t* yuyv, std::uint32_t width, std::uint32_t height,
                     std::uint32_t stride_bytes, std::uint32_t factor, LowResFrame& out);

}  // namespace boticelli::image
