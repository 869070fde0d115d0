// Feature selection (§3.4.1): strongest vertical intensity derivatives in the central band.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>

#include "algo/core/fixed_vector.h"
#include "algo/image/low_res_frame.h"

namespace boticelli::image {

// A selected feature: a low-resolution pixel and its vertical derivative |∂Y/∂v|.
struct Feature {
  std::uint16_t u_px = 0;
  std::uint16_t v_px = 0;
  float strength = 0.0F;  // |Y(u, v+1) − Y(u, v−1)| / 2 [grey levels per px]
};

struct FeatureParams {
  std::size_t max_features = 500;  // cap on the features per frame (§3.4.1: about 500)
  // Central band |i| ≤ 53, |j| ≤ 40 at F = 150 px (§3.4.1); scaled by the actual F.
  float band_half_width_at_f150_px = 53.0F;
  float band_half_height_at_f150_px = 40.0F;  // above the principal point (and below, unless set)
  // Below the principal point, if > 0: a point low in the first frame is higher in the second,
  // tilted down by Φ, so the band may reach the image's bottom; the thesis's band stops at 40
  // rows, leaving a gap between two tilt rows 0.5 rad apart in which an overhang 0.3 m up at
  // 1 m falls (its rim is below the upper row's band and above the lower row's).
  float band_half_height_below_at_f150_px = 0.0F;
  float min_strength = 2.0F;  // weaker derivatives are not features [grey levels per px]
};

// Where the band is: principal point and focal length at the processing resolution.
struct BandGeometry {
  float principal_x_px = 79.375F;
  float principal_y_px = 59.375F;
  float focal_px = 150.0F;
};

// Selects features: local maxima of |∂Y/∂v| in a 3x3 neighbourhood (non-maximum
// suppression spreads them over the image), strongest first, up to the cap, inside the
// band and at least 2 px from the border (the 5x5 window of Eq 3.1 must fit).
class FeatureSelector {
 public:
  static constexpr std::size_t kMaxFeatures = 1024;
  explicit FeatureSelector(const FeatureParams& params = {}) : params_(params) {}
  [[nodiscard]] const FeatureParams& params() const { return params_; }

  // Returns the number selected; `out` is cleared first and keeps at most its capacity.
  std::size_t select(const LowResFrame& frame, const BandGeometry& band,
                     core::FixedVectorBase<Feature>& out);

 private:
  struct Candidate {
    float strength;
    std::uint32_t index;
  };
  FeatureParams params_;
  std::array<float, LowResFrame::kMaxPixels> gradient_{};
  std::array<Candidate, LowResFrame::kMaxPixels / 4> candidates_{};
};

}  // namespace boticelli::image
