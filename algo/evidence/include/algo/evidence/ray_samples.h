// Ray samples of the visual sensor model (Fig 3.8b, 4.2b): a Reading becomes a few samples.
#pragma once

#include <cstddef>
#include <cstdint>
#include <span>

#include "algo/core/fixed_vector.h"
#include "algo/evidence/reading.h"

namespace boticelli::evidence {

// One regression sample of the occupancy function F(α, h, r) (thesis §4.5, Eq 4.22):
// a point in quasi-cylindrical coordinates about the PTU centre and the occupancy value
// the fit should reach there.
struct RaySample {
  float alpha_rad = 0.0F;  // pan angle [rad]; seam copies lie outside [0, 2π)
  float h_m = 0.0F;        // height relative to the PTU centre [m]
  float r_m = 0.0F;        // distance from the PTU centre [m]
  float occupancy = 0.0F;  // target value in [0, 1]
};

using RaySampleBuffer = core::FixedVectorBase<RaySample>;

// Where the samples of one reading go (docs/evidence.md has the picture). With δr =
// delta_r_fraction · r (§3.7.3) and k = samples_per_reading − 3 "lower" samples:
//   two plateau samples with evidence m at r − δr and r + δr (the range error, Eq 3.7);
//   k lower samples towards the camera, the j-th (j = 1..k) at
//     r − (1 + j·ramp_length_delta_r / k)·δr with evidence m·(1 − j/(k+1)),
//   so occupancy falls linearly from m at r − δr to zero at about
//   r − (1 + ramp_length_delta_r·(k+1)/k)·δr (the gradual slope of Fig 3.8b);
//   one sample at the robot centre (α, 0, 0) with occupancy 0;
//   line_of_sight_samples more with occupancy 0 on the line of sight, evenly between where it
//   starts (the reading's view, the camera's optical centre; the PTU centre if unset) and
//   the ramp's foot on it, reach·δr short of the point (the j-th of n at j/(n+1) of the way):
//   the camera saw the point through that space, so it is evidence of free, not only the
//   centre (the thesis's model has none).
// Samples between the camera and the point lie on the ray of view: a sample at distance s
// has height h·s/r (r is the 3-D distance, h the height, so the ray is straight).
struct RaySampleParams {
  std::size_t samples_per_reading = 5;    // ≥ 3 and ≤ kMaxSamplesPerReading
  float delta_r_fraction = 0.1F;          // δr / r, the thesis's sensor model (§3.7.3)
  float ramp_length_delta_r = 2.0F;       // spread of the lower samples, in units of δr
  std::size_t line_of_sight_samples = 0;  // ≤ kMaxSamplesPerReading; 0 = the thesis's model
};

inline constexpr std::size_t kMaxSamplesPerReading = 16;

// δr / r sized from the stereo's measured accuracy instead of the thesis's 0.1: the 90th
// percentile of |r − r_true| / r_true is 0.029-0.045 over 0.3-3 m (0.076 at 3-4.5 m) in the
// stereo suite's frames (docs/benchmarks.md "stereo"), so at most one reading in ten lies
// outside r ± δr nearer than 3 m.
inline constexpr float kStereoDeltaRFraction = 0.05F;

// The sensor model sized from the stereo's accuracy, with the line of sight as evidence of
// free (two samples on it besides the robot centre's).
[[nodiscard]] constexpr RaySampleParams stereo_ray_sample_params() {
  RaySampleParams p;
  p.delta_r_fraction = kStereoDeltaRFraction;
  p.line_of_sight_samples = 2;
  return p;
}

// Samples per reading of the plausibility model: samples_per_reading + line_of_sight_samples.
[[nodiscard]] constexpr std::size_t plausibility_samples_per_reading(
    const RaySampleParams& params) {
  return params.samples_per_reading + params.line_of_sight_samples;
}

// Plausibility samples (the thesis's default): the fit is monotone in r (Eq 4.24), so
// nothing is said behind the point; the constraint carries m on to larger r.
// Returns the number of samples appended: plausibility_samples_per_reading(), or 0 (and
// nothing appended) if the buffer lacks room or the parameters are invalid.
std::size_t append_plausibility_samples(const Reading& reading, const RaySampleParams& params,
                                        RaySampleBuffer& out);

// Belief samples (evidence before and behind the point, no monotone constraint, §4.3
// Eq 4.16–4.18 Bel ≤ Pl): the same samples as the plausibility model, then the ramp
// mirrored behind the point (the j-th at r + (1 + j·ramp/k)·δr with m·(1 − j/(k+1)))
// and one closing sample with occupancy 0 at r + (1 + ramp·(k+1)/k)·δr, because the
// evidence behind the observed point is zero (§3.7.3). Count: belief_samples_per_reading().
std::size_t append_belief_samples(const Reading& reading, const RaySampleParams& params,
                                  RaySampleBuffer& out);

[[nodiscard]] constexpr std::size_t belief_samples_per_reading(const RaySampleParams& params) {
  return params.samples_per_reading < 3
             ? 0
             : 2 * params.samples_per_reading - 2 + params.line_of_sight_samples;
}

enum class OccupancyBound : std::uint8_t { kPlausibility, kBelief };

// All readings, all or nothing per reading; returns the number of readings that fitted.
// Plausibility (monotone in r) is the thesis's model and the default.
std::size_t append_ray_samples(std::span<const Reading> readings, const RaySampleParams& params,
                               RaySampleBuffer& out,
                               OccupancyBound bound = OccupancyBound::kPlausibility);

// §4.9.1 discontinuity at α = 0/2π: every sample among the first `count` of `samples`
// with α < margin gets a copy at α + 2π, every one with α > 2π − margin a copy at α − 2π.
// margin = 2π copies everything to both sides. Returns the copies made (stops when full).
std::size_t append_seam_copies(RaySampleBuffer& samples, float margin_rad);

// Deterministic generator for the pads (xorshift32); the caller keeps the state.
struct PadRandom {
  std::uint32_t state = 0x9E3779B9U;
  // Uniform in [0, 1).
  float uniform();
};

// The region pads are drawn from, in quasi-cylindrical coordinates.
struct PadRegion {
  float alpha_min_rad = 0.0F;
  float alpha_max_rad = 6.2831853F;
  float h_min_m = -1.0F;
  float h_max_m = 1.0F;
  float r_min_m = 0.0F;
  float r_max_m = 4.5F;
};

// §4.9.1 lack of features: `count` samples with occupancy 0 uniformly over the region
// (the thesis used about 1000 over the whole space). Returns the pads appended.
std::size_t append_zero_pads(const PadRegion& region, std::size_t count, PadRandom& random,
                             RaySampleBuffer& out);

// Pads only where there is nothing to say (§4.9.1 "lack of features"): the directions of
// view, pan α in [alpha_min, alpha_max) x elevation asin(h/r) in [elevation_min,
// elevation_max), are cut into alpha_bins x elevation_bins cells; each cell that holds no
// reading gets pads_per_empty_cell zero samples on rays of that cell, at distances uniform
// in [r_min, r_max] but never beyond the height range [h_min, h_max] of the region (e.g.
// the floor). A featureless direction is taken as empty, which is what the thesis's pads
// do; cells with readings keep their ray samples only, so pads never contradict a feature.
struct FeaturelessPadParams {
  std::size_t alpha_bins = 32;      // ≤ kMaxPadBins
  std::size_t elevation_bins = 16;  // ≤ kMaxPadBins
  float elevation_min_rad = -1.2F;
  float elevation_max_rad = 1.2F;
  std::size_t pads_per_empty_cell = 4;
};
inline constexpr std::size_t kMaxPadBins = 64;
std::size_t append_featureless_pads(std::span<const Reading> readings, const PadRegion& region,
                                    const FeaturelessPadParams& params, PadRandom& random,
                                    RaySampleBuffer& out);

}  // namespace boticelli::evidence
