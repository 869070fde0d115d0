// TargetTracker: grouping of target sightings (see target_tracker.h).
#include "firmware/mission/target/target_tracker.h"

#include <algorithm>
#include <cmath>

namespace boticelli::firmware::mission {

void TargetTracker::restore(const Eigen::Vector3f& goal_world_m) {
  clear();
  sightings_[0] = {goal_world_m, 1.0F, 1.0F, 0xFFFFFFF0U, {}};
  count_ = next_ = 1;
  confirmed_ = true;
  support_ = params_.min_views;
  estimate_ = candidate_ = goal_world_m;
}

bool TargetTracker::missed() {
  if (!confirmed_ || params_.revoke_after_misses == 0) return false;
  if (++misses_ < params_.revoke_after_misses) return false;
  // Forget the target's sightings (those its estimate was refined from) and look again.
  forget_near(estimate_);
  ++revocations_;
  return true;
}

bool TargetTracker::provisional() const {
  if (confirmed_ || count_ == 0 || support_ < params_.min_views) return false;
  const float r2 = params_.agree_radius_m * params_.agree_radius_m;
  for (std::size_t i = 0; i < dismissed_count_; ++i) {
    if ((dismissed_[i] - candidate_).squaredNorm() <= r2) return false;
  }
  return true;
}

bool TargetTracker::dismiss_candidate() {
  if (!provisional()) return false;
  dismissed_[dismissed_next_] = candidate_;
  dismissed_next_ = (dismissed_next_ + 1) % kMaxDismissed;
  if (dismissed_count_ < kMaxDismissed) ++dismissed_count_;
  forget_near(candidate_);
  return true;
}

void TargetTracker::forget_near(Eigen::Vector3f centre) {
  const float q2 = params_.refine_radius_m * params_.refine_radius_m;
  std::size_t kept = 0;
  for (std::size_t i = 0; i < count_; ++i) {
    if ((sightings_[i].point - centre).squaredNorm() > q2) sightings_[kept++] = sightings_[i];
  }
  count_ = kept;
  next_ = kept % kMaxSightings;
  confirmed_ = false;
  misses_ = 0;
  estimate_ = candidate_ = Eigen::Vector3f::Zero();
  support_ = 0;
  if (count_ > 0) update_estimate();
}

bool TargetTracker::has_baseline(const Eigen::Vector3f& centre, float r2) const {
  if (params_.min_baseline_m <= 0.0F) return true;
  for (std::size_t j = 0; j < count_; ++j) {
    if ((sightings_[j].point - centre).squaredNorm() > r2) continue;
    for (std::size_t k = 0; k < j; ++k) {
      if ((sightings_[k].point - centre).squaredNorm() <= r2 &&
          core::distance_m(sightings_[j].from, sightings_[k].from) >= params_.min_baseline_m) {
        return true;
      }
    }
  }
  return false;
}

void TargetTracker::add(const Eigen::Vector3f& point_world_m, float confidence, std::uint32_t view,
                        float range_error_m, core::Point2 from) {
  // A non-finite confidence would make the group's weighted mean NaN, and a NaN centre
  // counts every sighting as within the radius.
  if (!point_world_m.allFinite() || !std::isfinite(confidence) || !std::isfinite(range_error_m)) {
    return;
  }
  const float e = std::max(range_error_m, kMinRangeError_m);
  if (is_target(point_world_m)) misses_ = 0;
  sightings_[next_] = {point_world_m, confidence, (0.1F + confidence) / (e * e), view, from};
  next_ = (next_ + 1) % kMaxSightings;
  if (count_ < kMaxSightings) ++count_;
  update_estimate();
}

void TargetTracker::update_estimate() {
  const float r2 = params_.agree_radius_m * params_.agree_radius_m;
  std::size_t best_views = 0;
  Eigen::Vector3f best = Eigen::Vector3f::Zero();
  for (std::size_t i = 0; i < count_; ++i) {
    // The group around sighting i, re-centred once on its mean (two passes).
    Eigen::Vector3f centre = sightings_[i].point;
    for (int pass = 0; pass < 2; ++pass) {
      Eigen::Vector3f sum = Eigen::Vector3f::Zero();
      float weight = 0.0F;
      for (std::size_t j = 0; j < count_; ++j) {
        if ((sightings_[j].point - centre).squaredNorm() <= r2) {
          const float w = sightings_[j].weight;
          sum += w * sightings_[j].point;
          weight += w;
        }
      }
      centre = sum / weight;
    }
    // Distinct views in the group.
    std::size_t views = 0;
    for (std::size_t j = 0; j < count_; ++j) {
      if ((sightings_[j].point - centre).squaredNorm() > r2) continue;
      bool seen_before = false;
      for (std::size_t k = 0; k < j && !seen_before; ++k) {
        seen_before = sightings_[k].view == sightings_[j].view &&
                      (sightings_[k].point - centre).squaredNorm() <= r2;
      }
      if (!seen_before) ++views;
    }
    if (views > best_views) {
      best_views = views;
      best = centre;
    }
  }
  support_ = best_views;
  candidate_ = best;
  if (best_views >= params_.min_views && has_baseline(best, r2)) {
    confirmed_ = true;
    const float q2 = params_.refine_radius_m * params_.refine_radius_m;
    Eigen::Vector3f centre = best;
    for (int pass = 0; pass < 2; ++pass) {
      Eigen::Vector3f sum = Eigen::Vector3f::Zero();
      float weight = 0.0F;
      for (std::size_t j = 0; j < count_; ++j) {
        if ((sightings_[j].point - centre).squaredNorm() <= q2) {
          sum += sightings_[j].weight * sightings_[j].point;
          weight += sightings_[j].weight;
        }
      }
      if (weight > 0.0F) centre = sum / weight;
    }
    estimate_ = centre;
  }
}

}  // namespace boticelli::firmware::mission
