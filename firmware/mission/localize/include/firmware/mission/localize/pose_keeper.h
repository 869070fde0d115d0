// PoseKeeper: the robot's pose in the mission's frame, the one place the mission reads it.
// Today wheel odometry carried on from the pose a mission (or a resumed one) started at; a
// look's registration correction will be applied here.
#pragma once

#include "algo/core/geometry.h"
#include "hal/base.h"

namespace boticelli::firmware::mission {

class PoseKeeper {
 public:
  explicit PoseKeeper(const hal::Base& base) : base_(base) {}
  PoseKeeper(const PoseKeeper&) = delete;
  PoseKeeper& operator=(const PoseKeeper&) = delete;

  // Fixes the mission frame against the odometry so that the robot stands at `mission_pose`
  // now: identity for a new mission at the odometry's origin; a resumed one continues in the
  // frame its lists and goal were saved in, while the odometry restarts at zero.
  void anchor(const core::Pose2& mission_pose);
  // The robot's pose in the mission's frame [m, rad].
  [[nodiscard]] core::Pose2 pose() const;
  // The world pose of the mission frame's origin, given the world pose of the odometry
  // frame's origin (sim ground truth only).
  [[nodiscard]] core::Pose2 frame_origin_in_world(const core::Pose2& odometry_origin) const;

 private:
  [[nodiscard]] core::Pose2 odometry() const;

  const hal::Base& base_;
  core::Pose2 frame_from_odometry_{};  // mission frame from odometry frame
};

}  // namespace boticelli::firmware::mission
