// Feature selection by vertical derivative with 3x3 non-maximum suppression (§3.4.1).
#include "algo/image/features.h"

#include <algorithm>
#include <cmath>
#include <cstddef>

namespace boticelli::image {

std::size_t FeatureSelector::select(const LowResFrame& frame, const BandGeometry& band,
                                    core::FixedVectorBase<Feature>& out) {
  out.clear();
  const auto w = static_cast<int>(frame.width);
  const auto h = static_cast<int>(frame.height);
  if (w < 7 || h < 7 || band.focal_px <= 0.0F) {
    return 0;
  }
  const float scale = band.focal_px / 150.0F;
  const float half_w = params_.band_half_width_at_f150_px * scale;
  const float half_h = params_.band_half_height_at_f150_px * scale;
  const float half_h_below =
      (params_.band_half_height_below_at_f150_px > 0.0F ? params_.band_half_height_below_at_f150_px
                                                        : params_.band_half_height_at_f150_px) *
      scale;
  // Band limits, kept 2 px from the border for the 5x5 window and 1 more for the 3x3 test.
  const int u0 = std::max(3, static_cast<int>(std::ceil(band.principal_x_px - half_w)));
  const int u1 = std::min(w - 4, static_cast<int>(std::floor(band.principal_x_px + half_w)));
  const int v0 = std::max(3, static_cast<int>(std::ceil(band.principal_y_px - half_h)));
  const int v1 = std::min(h - 4, static_cast<int>(std::floor(band.principal_y_px + half_h_below)));
  if (u0 > u1 || v0 > v1) {
    return 0;
  }
  const float* y = frame.luma.data();
  const auto at = [w](int u, int v) { return static_cast<std::size_t>(std::ptrdiff_t{v} * w + u); };
  // |∂Y/∂v| by central difference on the band grown by one pixel.
  for (int v = v0 - 1; v <= v1 + 1; ++v) {
    for (int u = u0 - 1; u <= u1 + 1; ++u) {
      gradient_[at(u, v)] = 0.5F * std::fabs(y[at(u, v + 1)] - y[at(u, v - 1)]);
    }
  }
  std::size_t count = 0;
  for (int v = v0; v <= v1; ++v) {
    for (int u = u0; u <= u1; ++u) {
      const float g = gradient_[at(u, v)];
      if (g < params_.min_strength) {
        continue;
      }
      // Strict maximum over earlier neighbours, ≥ over later ones: plateaus keep one pixel.
      bool is_max = true;
      for (int dv = -1; dv <= 1 && is_max; ++dv) {
        for (int du = -1; du <= 1; ++du) {
          if (du == 0 && dv == 0) {
            continue;
          }
          const float n = gradient_[at(u + du, v + dv)];
          const bool earlier = dv < 0 || (dv == 0 && du < 0);
          if (earlier ? n >= g : n > g) {
            is_max = false;
            break;
          }
        }
      }
      if (is_max && count < candidates_.size()) {
        candidates_[count++] = {g, static_cast<std::uint32_t>(at(u, v))};
      }
    }
  }
  const std::size_t wanted = std::min({params_.max_features, out.capacity(), count});
  const auto stronger = [](const Candidate& a, const Candidate& b) {
    return a.strength > b.strength || (a.strength == b.strength && a.index < b.index);
  };
  const auto first = candidates_.begin();
  const auto last = first + static_cast<std::ptrdiff_t>(count);
  const auto cut = first + static_cast<std::ptrdiff_t>(wanted);
  std::nth_element(first, cut, last, stronger);
  std::sort(first, cut, stronger);
  for (auto it = first; it != cut; ++it) {
    Feature f;
    f.u_px = static_cast<std::uint16_t>(it->index % frame.width);
    f.v_px = static_cast<std::uint16_t>(it->index / frame.width);
    f.strength = it->strength;
    (void)out.push_back(f);
  }
  return out.size();
}

}  // namespace boticelli::image
