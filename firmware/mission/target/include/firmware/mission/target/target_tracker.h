// TargetTracker: target sightings in the world frame; a goal only when two views agree, refined
// as it is seen again.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>

#include <Eigen/Core>

namespace boticelli::firmware::mission {

struct TargetTrackerParams {
  float agree_radius_m = 0.25F;  // two sightings this close (3-D) are the same target
  std::size_t min_views = 2;     // distinct views (look, pan, tilt row) that must agree
  // Once confirmed, the estimate is the weighted mean of every sighting within this of the
  // group's centre (re-centred twice): stereo fixes scatter along the line of sight, farther
  // than two of them need to agree.
  float refine_radius_m = 0.25F;
};

// Keeps the last kMaxSightings sightings (world frame, odometry). The estimate is the mean of
// the largest group of sightings within agree_radius_m of their mean, from at least min_views
// distinct views; a lone sighting (a false detection, a reflection) never becomes the goal.
class TargetTracker {
 public:
  static constexpr std::size_t kMaxSightings = 64;

  void configure(const TargetTrackerParams& params) { params_ = params; }
  void clear() {
    count_ = next_ = support_ = 0;
    confirmed_ = false;
    estimate_ = candidate_ = Eigen::Vector3f::Zero();
  }
  // `view` identifies where it was seen from (e.g. cycle·64 + view index): two sightings of
  // the same view count once.
  // `range_error_m` is how far off the fix may be along its line of sight: δr of Eq 3.7 at
  // its range and its two frames' baseline (TargetFix::range_error_m), which grows with the
  // square of the range and shrinks with the baseline; a sighting's weight in the mean is
  // (0.1 + confidence) / max(δr, kMinRangeError_m)².
  static constexpr float kMinRangeError_m = 0.01F;
  void add(const Eigen::Vector3f& point_world_m, float confidence, std::uint32_t view,
           float range_error_m = 0.1F);

  [[nodiscard]] bool confirmed() const { return confirmed_; }
  [[nodiscard]] const Eigen::Vector3f& estimate_m() const { return estimate_; }
  [[nodiscard]] std::size_t sightings() const { return count_; }
  [[nodiscard]] std::size_t supporting_views() const { return support_; }
  // The largest group's mean even when too few views agree (valid when sightings() > 0): a
  // sighting to look at again from closer.
  [[nodiscard]] const Eigen::Vector3f& candidate_m() const { return candidate_; }

 private:
  struct Sighting {
    Eigen::Vector3f point = Eigen::Vector3f::Zero();
    float confidence = 0.0F;
    float weight = 0.0F;
    std::uint32_t view = 0;
  };
  void update_estimate();

  TargetTrackerParams params_{};
  std::array<Sighting, kMaxSightings> sightings_{};
  std::size_t count_ = 0;
  std::size_t next_ = 0;
  bool confirmed_ = false;
  std::size_t support_ = 0;
  Eigen::Vector3f estimate_ = Eigen::Vector3f::Zero();
  Eigen::Vector3f candidate_ = Eigen::Vector3f::Zero();
};

}  // namespace boticelli::firmware::mission
