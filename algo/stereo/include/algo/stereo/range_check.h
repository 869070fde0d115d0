// Calibration self-check: stereo ranges against the floor cue's ground-plane ranges at obstacle
// bases.
#pragma once

#include <array>
#include <cstddef>

#include "algo/stereo/floor_cue.h"
#include "algo/stereo/rig.h"
#include "algo/stereo/stereo_processor.h"

namespace boticelli::stereo {

// The stereo reads a range from the parallax left once the tilt step Φ is taken out with the
// configured focal length, so a focal length or lens a little off scales every stereo range
// (docs/benchmarks.md, "The realistic camera and rig"). The floor cue's ranges come from the
// ground plane instead: the camera's height and the ray's elevation. Where a walk of the floor
// cue ends at an obstacle's base, a stereo point low on that obstacle, in the walk's vertical
// plane, should be as far along the plane as the base: the ratio of the two distances is 1 for
// a calibrated camera. The median ratio over a look's pairs says whether the calibration fits
// what the camera sees.
struct RangeCheckParams {
  float min_height_m = 0.03F;    // stereo points this high above the floor ...
  float max_height_m = 0.5F;     // ... to this high are low on an obstacle [m]
  float lateral_m = 0.02F;       // off the walk's plane by at most this ...
  float lateral_per_m = 0.015F;  // ... plus this per metre along it (a column's width) [m/m]
  float min_base_m = 0.5F;       // bases nearer than this or ...
  float max_base_m = 3.0F;       // ... farther are not used [m]
  float min_ratio = 0.6F;        // a ratio outside [min, max] is another object's point
  float max_ratio = 1.6F;
};

// The stereo's self-calibration step (StereoParams::self_calibration): the inverse-range bias
// in use [1/m] plus a look's residual median (RangeCheck::inverse_bias, of points that had the
// bias in use removed) from `pairs` pairs, held to ±self_calibration_max_bias_per_m, and 0
// when that is within ±self_calibration_min_bias_per_m (the stereo's own); the bias in use
// unchanged when it is off or the look has fewer than self_calibration_min_pairs.
float updated_inverse_bias(float in_use_per_m, float residual_per_m, std::size_t pairs,
                           const StereoParams& params);

// The one rig error that alone leaves an inverse-range bias b [1/m] (1/r_read = 1/r + b): the
// stereo takes F·Φ of a pair's parallax as the tilt step's rotation and reads the range from
// the rest, F·L·Φ/r (lever L). A true focal length s·F leaves (s − 1)·F·Φ of it, so
// b = (s − 1)/L and s = 1 + b·L; a true tilt step Φ + δ leaves F·δ, so b = δ/(L·Φ) and
// δ = b·L·Φ. What an operator checks first: camera.focal_px, then ptu.tilt_step_rad.
float bias_as_focal_scale(float bias_per_m, const RigParams& rig);
float bias_as_tilt_step_error_rad(float bias_per_m, const RigParams& rig);

class RangeCheck {
 public:
  static constexpr std::size_t kCapacity = 2048;  // ratios kept per look

  explicit RangeCheck(const RigModel& rig, const RangeCheckParams& params = {})
      : rig_(rig), params_(params) {}
  [[nodiscard]] const RangeCheckParams& params() const { return params_; }

  void begin_look() { count_ = 0; }
  // One view: the floor cue's columns of the pair's first frame (seen at pan, tilt [rad]) and
  // the pair's stereo points. Adds one ratio for every point low on an obstacle that lies in
  // the plane of a walk ending at a base (the walk whose plane it is nearest); returns how
  // many. Allocation-free; ratios beyond kCapacity are dropped.
  std::size_t add_view(const FloorCue& cue, float pan_rad, float tilt_rad,
                       const StereoPoint* points, std::size_t point_count);
  // The look's median ratio (stereo distance / floor distance) and how many ratios it is of;
  // false when there are none.
  bool median(float& ratio, std::size_t& count);
  // The look's median inverse-range bias b [1/m]: the stereo's 1/r̂ less the floor's 1/r along
  // the same line of sight, (1 − ratio)/r̂ for each ratio (a point on the camera's ray at
  // ratio × the base's distance along the walk's plane is at ratio × its true range). A
  // focal length or tilt step a little off adds about the same b to every inverse range
  // (StereoProcessor::set_inverse_range_bias); false when there is no ratio.
  bool inverse_bias(float& bias_per_m, std::size_t& count);
  [[nodiscard]] std::size_t count() const { return count_; }

 private:
  // The walks that end at a base: their plane's direction and the base's distance along it.
  struct Plane {
    float ax = 0.0F;
    float ay = 0.0F;
    float s_base_m = 0.0F;
  };
  const RigModel& rig_;
  RangeCheckParams params_;
  std::array<Plane, FloorCue::kMaxColumns> planes_{};
  std::array<float, kCapacity> ratios_{};
  std::array<float, kCapacity> inverse_biases_{};  // (1 − ratio) / r̂ of the same pairs [1/m]
  std::size_t count_ = 0;
};

}  // namespace boticelli::stereo
