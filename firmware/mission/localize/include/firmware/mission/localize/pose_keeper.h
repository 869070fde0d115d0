// PoseKeeper: the robot's pose in the mission's frame, the one place the mission reads it:
// wheel odometry composed onto the last look's registered pose (or the pose a mission, or a
// resumed one, started at), with the uncertainty that decides how much a registration moves it.
#pragma once

#include <Eigen/Core>

#include "algo/core/geometry.h"
#include "algo/worldmap/scan_matcher.h"
#include "firmware/mission/localize/base_calibrator.h"
#include "hal/base.h"

namespace boticelli::firmware::mission {

// How far the firmware expects an uncalibrated base's odometry to stray (standard deviations;
// Borenstein & Feng 1996: unequal wheels and a wrong track dominate).
struct OdometryErrorModel {
  float position_per_m = 0.02F;   // position, per metre driven [m/m]
  float heading_per_rad = 0.03F;  // heading, per radian turned [rad/rad]
  float heading_per_m = 0.015F;   // heading, per metre driven (unequal wheels) [rad/m]
  // A registration's points are not independent (neighbouring rays see the same surface and
  // share the look's range error): its information is divided by this many [1].
  float registration_inflation = 20.0F;
  float min_residual_m = 0.025F;  // a registration's residual is at least this (half a cell) [m]
};

class PoseKeeper {
 public:
  explicit PoseKeeper(const hal::Base& base) : base_(base) {}
  PoseKeeper(const PoseKeeper&) = delete;
  PoseKeeper& operator=(const PoseKeeper&) = delete;

  void configure(const OdometryErrorModel& model) { model_ = model; }
  // Fixes the mission frame against the odometry so that the robot stands at `mission_pose`
  // now: identity for a new mission at the odometry's origin; a resumed one continues in the
  // frame its lists and goal were saved in, while the odometry restarts at zero. The pose is
  // taken as known.
  void anchor(const core::Pose2& mission_pose);
  // The robot drove from `from` to `to` (a turn, then straight; mission frame): the pose's
  // uncertainty grows by the odometry's error over that move (first-order propagation).
  void moved(const core::Pose2& from, const core::Pose2& to);
  // A look's registration: the robot thought itself at `before` (mission frame) when the look
  // was taken. The registered pose is weighed against the odometry by their uncertainties
  // (information form: the registration's H over its residual², only along the directions it
  // constrains), and from now on the odometry is composed onto the result, which is returned.
  core::Pose2 correct(const core::Pose2& before, const worldmap::Registration& registration);
  // The robot's pose in the mission's frame [m, rad]: the firmware's estimate.
  [[nodiscard]] core::Pose2 pose() const;
  // Its covariance (x, y [m], yaw [rad]).
  [[nodiscard]] const Eigen::Matrix3f& covariance() const { return covariance_; }
  // Wheel odometry alone in the mission's frame (as anchored, no correction) [m, rad].
  [[nodiscard]] core::Pose2 odometry_pose() const;
  // The world pose of the mission frame's origin, given the world pose of the odometry
  // frame's origin (sim ground truth only).
  [[nodiscard]] core::Pose2 frame_origin_in_world(const core::Pose2& odometry_origin) const;
  // The base's systematic errors as the registrations so far show them (moves and
  // registrations are fed to it here).
  [[nodiscard]] const BaseCalibrator& calibrator() const { return calibrator_; }

 private:
  [[nodiscard]] core::Pose2 odometry() const;

  const hal::Base& base_;
  OdometryErrorModel model_{};
  core::Pose2 frame_from_odometry_{};     // mission frame from odometry frame, corrected
  core::Pose2 anchored_from_odometry_{};  // ... as anchored (the frame itself)
  Eigen::Matrix3f covariance_ = Eigen::Matrix3f::Zero();
  BaseCalibrator calibrator_;
};

}  // namespace boticelli::firmware::mission
