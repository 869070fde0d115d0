// Breadcrumbs: where each of the robot's straight steps began, so it can back off the way it came.
#pragma once

#include <cstddef>

#include "algo/core/fixed_vector.h"
#include "algo/core/geometry.h"

namespace boticelli::firmware::mission {

// The start of every straight step driven, newest last, at most kCapacity (the oldest goes).
// The segment from the newest crumb to where the step ended was swept by the robot's disc,
// so driving it back needs no map: the way out when a look leaves no room to move.
class Breadcrumbs {
 public:
  static constexpr std::size_t kCapacity = 64;

  void clear() { crumbs_.clear(); }
  [[nodiscard]] std::size_t size() const { return crumbs_.size(); }

  // A straight step begins at `from` (mission frame [m]).
  void step_started(core::Point2 from) {
    if (crumbs_.size() == crumbs_.capacity()) {
      for (std::size_t i = 1; i < crumbs_.size(); ++i) crumbs_[i - 1] = crumbs_[i];
      crumbs_.resize(crumbs_.size() - 1);
    }
    (void)crumbs_.push_back(from);
  }

  // Where to back off to from `here`: the newest crumb at least `min_step_m` away (nearer
  // ones are dropped: the robot is there already). False when none is left.
  bool back_target(core::Point2 here, float min_step_m, core::Point2& out) {
    while (!crumbs_.empty() && core::distance_m(here, crumbs_.back()) < min_step_m) {
      crumbs_.resize(crumbs_.size() - 1);
    }
    if (crumbs_.empty()) return false;
    out = crumbs_.back();
    return true;
  }

  // The robot arrived at the newest crumb: the next back-off goes one step further back.
  void reached() {
    if (!crumbs_.empty()) crumbs_.resize(crumbs_.size() - 1);
  }

 private:
  core::FixedVector<core::Point2, kCapacity> crumbs_;
};

}  // namespace boticelli::firmware::mission
