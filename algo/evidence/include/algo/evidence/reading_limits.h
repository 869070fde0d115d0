// ReadingLimits: the one box of ranges and heights that stereo output, pads and the model share.
#pragma once

#include <cmath>
#include <cstddef>
#include <numbers>

#include "algo/core/fixed_vector.h"
#include "algo/evidence/ray_samples.h"
#include "algo/evidence/reading.h"

namespace boticelli::evidence {

// Which readings are believed, in the quasi-cylindrical coordinates of a Reading (§4.5.2).
// Heights are relative to the PTU centre [m]; ranges are distances from it [m]. The stereo
// output is filtered with it, the pads (§4.9.1) are drawn in it (pad_region) and the
// occupancy model's input box covers the ray samples of every reading in it (model_box), so
// the three cannot disagree.
struct ReadingLimits {
  float min_range_m = 0.0F;  // a reading must be farther than this (r = 0 is never one) [m]
  float max_range_m = 4.5F;  // and at most this far (thesis §3.4: visibility) [m]
  float min_h_m = -1.0F;     // lowest believed height, e.g. a little below the floor [m]
  float max_h_m = 1.0F;      // highest, e.g. the ceiling [m]
  // The floor test (floor_readings): the floor plane's height [m] (below the PTU centre, so
  // negative) and the range error, as a fraction of the range, within which a reading that
  // meets the plane is the floor. 0 (the default): no floor test, the thesis's readings.
  float floor_h_m = 0.0F;
  float floor_range_fraction = 0.0F;

  // min_range < r ≤ max_range and min_h ≤ h ≤ max_h; false for NaN.
  [[nodiscard]] bool within(const Reading& reading) const {
    return reading.r_m > min_range_m && reading.r_m <= max_range_m && reading.h_m >= min_h_m &&
           reading.h_m <= max_h_m;
  }
};

// The limits of a robot whose PTU centre is ptu_height_m above the floor [m], in a room whose
// ceiling is ceiling_height_m above the floor [m]: heights from floor_tolerance_m below the
// floor (a reading deeper than that is a mismatch: nothing is seen through the floor) to the
// ceiling, ranges up to max_range_m (§3.4: beyond about 4.5 m the 3 cm baseline's range error
// makes readings useless). min_range_m is 0; set it if the rig has a near limit.
[[nodiscard]] inline ReadingLimits make_reading_limits(float ptu_height_m,
                                                       float ceiling_height_m = 2.5F,
                                                       float max_range_m = 4.5F,
                                                       float floor_tolerance_m = 0.1F) {
  ReadingLimits limits;
  limits.min_range_m = 0.0F;
  limits.max_range_m = max_range_m;
  limits.min_h_m = -ptu_height_m - floor_tolerance_m;
  limits.max_h_m = ceiling_height_m - ptu_height_m;
  return limits;
}

// Removes in place the readings outside `limits`, keeping the order of the rest; returns how
// many were removed.
inline std::size_t filter_readings(core::FixedVectorBase<Reading>& readings,
                                   const ReadingLimits& limits) {
  std::size_t kept = 0;
  for (std::size_t i = 0; i < readings.size(); ++i) {
    if (limits.within(readings[i])) {
      readings[kept++] = readings[i];
    }
  }
  const std::size_t removed = readings.size() - kept;
  readings.resize(kept);
  return removed;
}

// What floor_readings did.
struct FloorReadings {
  std::size_t floor = 0;  // readings of the floor itself, now free (m = 0)
  std::size_t below = 0;  // readings below the floor beyond their range error, removed
};

// Stereo readings of the floor itself. The stereo (§3.4) sees strong intensity changes, and a
// textured floor (a rug, wood grain, tile joints) is full of them: fitted as occupancy, they
// fill the robot's height band with the floor. A reading's range is measured along its line
// of sight from the camera (view_*; the PTU centre if unset), and that line meets the floor
// plane at t = (floor_h − z_view)/(h − z_view) times the reading's distance from the camera.
// When t is within the range error, 1 − f ≤ t ≤ 1 + f, the reading is the floor: the camera
// saw the floor there, so its line of sight and the point are free, and its evidence becomes
// 0 (the ray samples then make it free space, ray_samples.h). t < 1 − f is a reading deeper
// than the floor by more than its error, a mismatch (nothing is seen through the floor): it
// is removed, the order of the rest kept. A plain box's bottom edge is also at the floor and
// also becomes free floor; the box itself stands above it. Nothing happens unless
// limits.floor_range_fraction is in (0, 1) and limits.floor_h_m < 0.
inline FloorReadings floor_readings(core::FixedVectorBase<Reading>& readings,
                                    const ReadingLimits& limits) {
  FloorReadings out;
  const float f = limits.floor_range_fraction;
  if (!(f > 0.0F && f < 1.0F && limits.floor_h_m < 0.0F)) return out;
  std::size_t kept = 0;
  for (std::size_t i = 0; i < readings.size(); ++i) {
    Reading reading = readings[i];
    const float drop = reading.view_z_m - reading.h_m;  // how far the line of sight falls [m]
    if (drop > 0.0F) {
      const float t = (reading.view_z_m - limits.floor_h_m) / drop;
      if (t < 1.0F - f) {
        ++out.below;
        continue;
      }
      if (t <= 1.0F + f) {
        reading.m = 0.0F;
        ++out.floor;
      }
    }
    readings[kept++] = reading;
  }
  readings.resize(kept);
  return out;
}

// The region the pads are drawn from (§4.9.1): all pan angles and exactly the limits' box,
// so no pad claims "empty" where no reading could have been believed.
[[nodiscard]] inline PadRegion pad_region(const ReadingLimits& limits) {
  PadRegion region;
  region.alpha_min_rad = 0.0F;
  region.alpha_max_rad = 2.0F * std::numbers::pi_v<float>;
  region.h_min_m = limits.min_h_m;
  region.h_max_m = limits.max_h_m;
  region.r_min_m = limits.min_range_m;
  region.r_max_m = limits.max_range_m;
  return region;
}

// How far beyond its reading a ray sample reaches, as a fraction of r: the plausibility
// samples' far plateau sample lies at r + δr (δr = delta_r_fraction · r); the belief samples'
// last zero at r + (1 + ramp_length_delta_r · (k + 1) / k) · δr, k = samples_per_reading − 3
// (ray_samples.h). Samples lie on the ray of view, so their height scales by the same factor.
[[nodiscard]] inline float ray_sample_reach(const RaySampleParams& params,
                                            OccupancyBound bound = OccupancyBound::kPlausibility) {
  if (bound == OccupancyBound::kPlausibility || params.samples_per_reading < 4) {
    return params.delta_r_fraction;
  }
  const auto k = static_cast<float>(params.samples_per_reading - 3);
  return (1.0F + params.ramp_length_delta_r * (k + 1.0F) / k) * params.delta_r_fraction;
}

// The occupancy model's input box (configure_occupancy_model): heights relative to the PTU
// centre [m] and the farthest range [m].
struct ModelBox {
  float lowest_h_m = 0.0F;
  float highest_h_m = 0.0F;
  float max_range_m = 0.0F;
};

// The smallest box that holds every ray sample of every reading within `limits`: a sample at
// distance s on the ray to (h, r) has height h·s/r with 0 ≤ s ≤ (1 + reach)·r, so heights run
// from (1 + reach)·min(min_h, 0) to (1 + reach)·max(max_h, 0), ranges to (1 + reach)·max_range.
// It is 10⁻⁵ (relative) larger, because the samples' float arithmetic (r + 4·δr, then h·s/r)
// rounds a few ulps past the exact product.
[[nodiscard]] inline ModelBox model_box(const ReadingLimits& limits, float reach) {
  constexpr float kRoundingSlack = 1e-5F;
  const float scale = (1.0F + std::fmax(reach, 0.0F)) * (1.0F + kRoundingSlack);
  return {scale * std::fmin(limits.min_h_m, 0.0F), scale * std::fmax(limits.max_h_m, 0.0F),
          scale * limits.max_range_m};
}

}  // namespace boticelli::evidence
