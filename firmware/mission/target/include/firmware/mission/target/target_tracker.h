// TargetTracker: target sightings in the world frame; a goal only when views from two places
// agree, refined as it is seen again, revoked when it is missing where it should be seen.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>

#include <Eigen/Core>

#include "algo/core/geometry.h"

namespace boticelli::firmware::mission {

struct TargetTrackerParams {
  float agree_radius_m = 0.25F;  // two sightings this close (3-D) are the same target
  std::size_t min_views = 2;     // distinct views (look, pan, tilt row) that must agree
  // Once confirmed, the estimate is the weighted mean of every sighting within this of the
  // group's centre (re-centred twice): stereo fixes scatter along the line of sight, farther
  // than two of them need to agree.
  float refine_radius_m = 0.25F;
  // The agreeing views must have been seen from places at least this far apart [m] (0: any;
  // the mission asks for two positions, so the pans of one look never confirm on their own).
  float min_baseline_m = 0.0F;
  // A confirmed target missed this many times in a row (missed()) is revoked (0: never).
  std::size_t revoke_after_misses = 0;
};

// Keeps the last kMaxSightings sightings (world frame, odometry). The estimate is the mean of
// the largest group of sightings within agree_radius_m of their mean, from at least min_views
// distinct views seen from places min_baseline_m apart; a lone sighting (a false detection, a
// reflection) never becomes the goal. Once confirmed it stays the goal until it is revoked:
// revoke_after_misses views in a row that should have seen it (aimed at it, in range, the
// line of sight clear: the caller judges) and did not.
class TargetTracker {
 public:
  static constexpr std::size_t kMaxSightings = 64;

  void configure(const TargetTrackerParams& params) { params_ = params; }
  void clear() {
    count_ = next_ = support_ = 0;
    confirmed_ = false;
    misses_ = revocations_ = 0;
    estimate_ = candidate_ = Eigen::Vector3f::Zero();
    dismissed_count_ = dismissed_next_ = 0;
  }
  // A goal confirmed before a restart: confirmed at once, as if seen from two places.
  void restore(const Eigen::Vector3f& goal_world_m);
  // `view` identifies where it was seen from (e.g. cycle·64 + view index): two sightings of
  // the same view count once.
  // `range_error_m` is how far off the fix may be along its line of sight: δr of Eq 3.7 at
  // its range and its two frames' baseline (TargetFix::range_error_m), which grows with the
  // square of the range and shrinks with the baseline; a sighting's weight in the mean is
  // (0.1 + confidence) / max(δr, kMinRangeError_m)².
  // `from` is where the robot stood (world frame, the look's pose).
  static constexpr float kMinRangeError_m = 0.01F;
  void add(const Eigen::Vector3f& point_world_m, float confidence, std::uint32_t view,
           float range_error_m = 0.1F, core::Point2 from = {});
  // Whether `p` is the confirmed target (within agree_radius_m of the estimate).
  [[nodiscard]] bool is_target(const Eigen::Vector3f& p) const {
    return confirmed_ &&
           (p - estimate_).squaredNorm() <= params_.agree_radius_m * params_.agree_radius_m;
  }
  // A view that should have seen the confirmed target did not: true when this revoked it
  // (its sightings are forgotten; another group may be confirmed in its place). A sighting of
  // the target (add() near the estimate) resets the count.
  bool missed();
  [[nodiscard]] std::size_t misses() const { return misses_; }
  [[nodiscard]] std::size_t revocations() const { return revocations_; }

  [[nodiscard]] bool confirmed() const { return confirmed_; }
  [[nodiscard]] const Eigen::Vector3f& estimate_m() const { return estimate_; }
  [[nodiscard]] std::size_t sightings() const { return count_; }
  [[nodiscard]] std::size_t supporting_views() const { return support_; }
  // The largest group's mean even when too few views agree (valid when sightings() > 0): a
  // sighting to look at again from closer.
  [[nodiscard]] const Eigen::Vector3f& candidate_m() const { return candidate_; }
  // A candidate that min_views views agree on, all seen from one place (the pans of one
  // look), so not confirmed: worth going to, where a view from its stand-off (a second
  // place) confirms it. Never one within agree_radius_m of a dismissed candidate.
  [[nodiscard]] bool provisional() const;
  // The provisional candidate was not seen from its stand-off: its sightings are forgotten
  // and its place kept (the last kMaxDismissed), so sightings there are never provisional
  // again; they can still be confirmed from two places. False when there is none.
  bool dismiss_candidate();
  static constexpr std::size_t kMaxDismissed = 8;
  [[nodiscard]] std::size_t dismissed() const { return dismissed_count_; }

 private:
  struct Sighting {
    Eigen::Vector3f point = Eigen::Vector3f::Zero();
    float confidence = 0.0F;
    float weight = 0.0F;
    std::uint32_t view = 0;
    core::Point2 from{};
  };
  void update_estimate();
  // Whether the group within r2 of `centre` holds two sightings seen min_baseline_m apart.
  [[nodiscard]] bool has_baseline(const Eigen::Vector3f& centre, float r2) const;
  // Forgets the sightings within refine_radius_m of `centre`; the estimate starts afresh.
  void forget_near(Eigen::Vector3f centre);

  TargetTrackerParams params_{};
  std::array<Sighting, kMaxSightings> sightings_{};
  std::size_t count_ = 0;
  std::size_t next_ = 0;
  bool confirmed_ = false;
  std::size_t misses_ = 0;
  std::size_t revocations_ = 0;
  std::size_t support_ = 0;
  Eigen::Vector3f estimate_ = Eigen::Vector3f::Zero();
  Eigen::Vector3f candidate_ = Eigen::Vector3f::Zero();
  std::array<Eigen::Vector3f, kMaxDismissed> dismissed_{};
  std::size_t dismissed_count_ = 0;
  std::size_t dismissed_next_ = 0;
};

}  // namespace boticelli::firmware::mission
