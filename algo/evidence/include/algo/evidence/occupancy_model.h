// The occupancy model's domain and the thesis's constraints on it (Eqs 4.27–4.28), in one place.
#pragma once

#include <limits>
#include <numbers>

#include "algo/evidence/ray_samples.h"
#include "algo/evidence/reading_limits.h"

namespace boticelli::evidence {

// How far the α = 0/2π seam copies reach beyond [0, 2π) (§4.9.1) [rad].
inline constexpr float kSeamMarginRad = 0.5F;

// Slope bounds of the occupancy model F(α, h, r) in SI units (the thesis gives them per dm;
// see algo/core/units.h): |∂F/∂α| < 1 per rad, |∂F/∂h| < 1 per dm = 10 per m (Eq 4.28),
// and ∂F/∂r > 0 (Eq 4.27: monotone in r, so the model can be inverted in r, §5.4.1) as a
// small positive lower bound with no upper bound.
inline constexpr float kMaxAlphaSlopePerRad = 1.0F;
inline constexpr float kMaxHeightSlopePerM = 10.0F;
inline constexpr float kMinRangeSlopePerM = 1e-4F;

// The bound on |∂F/∂α| [1/rad] for ray samples with δr / r = delta_r_fraction: the thesis's
// 1 per rad for its 0.1 (Eq 4.28), times 0.1 / delta_r_fraction. The bound keeps the m_safe
// surface from turning abruptly with pan: its tilt is dr/dα = −(∂F/∂α) / (∂F/∂r), and ∂F/∂r,
// the ramp's slope before a reading, grows as 1/δr. So a sharper sensor model keeps the
// thesis's limit on the tilt, where the thesis's bound would hold the surface at a fraction
// of it (a wall seen at 45° needs |dr/dα| = r).
[[nodiscard]] constexpr float alpha_slope_bound_per_rad(float delta_r_fraction) {
  return delta_r_fraction > 0.0F ? kMaxAlphaSlopePerRad * (0.1F / delta_r_fraction)
                                 : kMaxAlphaSlopePerRad;
}

// Sets the input box and the weight bounds of an occupancy ALN with inputs (α, h, r) and
// output occupancy in [0, 1]. `Model` is an aln::Aln<Scalar, 3, Pieces>. Heights are
// relative to the PTU centre [m]; `max_range_m` is the farthest r the model must cover;
// `max_alpha_slope_per_rad` bounds |∂F/∂α| (alpha_slope_bound_per_rad of the ray samples).
template <typename Model>
void configure_occupancy_model(Model& model, float lowest_h_m, float highest_h_m, float max_range_m,
                               float max_alpha_slope_per_rad = kMaxAlphaSlopePerRad) {
  constexpr float kTwoPi = 2.0F * std::numbers::pi_v<float>;
  model.set_input_range(0, -kSeamMarginRad, kTwoPi + kSeamMarginRad);
  model.set_input_range(1, lowest_h_m, highest_h_m);
  model.set_input_range(2, 0.0F, max_range_m);
  model.set_output_range(0.0F, 1.0F);
  model.set_weight_bounds(0, -max_alpha_slope_per_rad, max_alpha_slope_per_rad);
  model.set_weight_bounds(1, -kMaxHeightSlopePerM, kMaxHeightSlopePerM);
  model.set_weight_bounds(2, kMinRangeSlopePerM, std::numeric_limits<float>::infinity());
}

// The same from the reading limits the stereo output was filtered with: the input box is
// model_box(limits, ray_sample_reach(rays, bound)), which holds every ray sample of every
// reading within the limits, so the model, the pads (pad_region) and the readings agree.
template <typename Model>
void configure_occupancy_model(Model& model, const ReadingLimits& limits,
                               const RaySampleParams& rays = RaySampleParams{},
                               OccupancyBound bound = OccupancyBound::kPlausibility) {
  const ModelBox box = model_box(limits, ray_sample_reach(rays, bound));
  configure_occupancy_model(model, box.lowest_h_m, box.highest_h_m, box.max_range_m,
                            alpha_slope_bound_per_rad(rays.delta_r_fraction));
}

}  // namespace boticelli::evidence
