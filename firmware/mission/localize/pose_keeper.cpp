// PoseKeeper: the mission frame against the odometry, and its corrections (see pose_keeper.h).
#include "firmware/mission/localize/pose_keeper.h"

#include <Eigen/LU>
#include <cmath>

#include "algo/core/angles.h"

namespace boticelli::firmware::mission {

core::Pose2 PoseKeeper::odometry() const {
  const hal::Odometry o = base_.odometry();
  return {static_cast<float>(o.x_m), static_cast<float>(o.y_m), static_cast<float>(o.yaw_rad)};
}

void PoseKeeper::anchor(const core::Pose2& mission_pose) {
  frame_from_odometry_ = core::compose(mission_pose, core::inverse(odometry()));
  anchored_from_odometry_ = frame_from_odometry_;
  covariance_.setZero();
  calibrator_.restart();
}

void PoseKeeper::moved(const core::Pose2& from, const core::Pose2& to) {
  const float dx = to.x_m - from.x_m;
  const float dy = to.y_m - from.y_m;
  const float d = std::hypot(dx, dy);
  const float turned = std::fabs(core::wrap_pi(to.yaw_rad - from.yaw_rad));
  // A heading error before the move displaces its end across the way driven.
  Eigen::Matrix3f f = Eigen::Matrix3f::Identity();
  f(0, 2) = -dy;
  f(1, 2) = dx;
  const float sp = model_.position_per_m * d;
  const float sh = model_.heading_per_rad * turned + model_.heading_per_m * d;
  Eigen::Matrix3f q = Eigen::Matrix3f::Zero();
  q(0, 0) = q(1, 1) = sp * sp;
  q(2, 2) = sh * sh;
  covariance_ = f * covariance_ * f.transpose() + q;
  const hal::Odometry o = base_.odometry();
  calibrator_.moved(core::wrap_pi(to.yaw_rad - from.yaw_rad), o.wheels_known, o.wheel_left_m,
                    o.wheel_right_m);
}

core::Pose2 PoseKeeper::correct(const core::Pose2& before,
                                const worldmap::Registration& registration) {
  const worldmap::Registration& r = registration;
  if (!r.matched) return before;
  // The registration's information along the directions it constrains [1/m², 1/rad²].
  const float residual = std::max(r.residual_m, model_.min_residual_m);
  const float scale = 1.0F / (residual * residual * model_.registration_inflation);
  Eigen::Matrix3f info = Eigen::Matrix3f::Zero();
  for (int k = 0; k < 3; ++k) {
    if (k < 3 - r.constrained) continue;  // eigenvalues ascend: the weak ones come first
    const Eigen::Vector3f e = r.eigenvectors.col(k);
    info.noalias() += (r.eigenvalues(k) * scale) * e * e.transpose();
  }
  const Eigen::Vector3f delta(r.refined.x_m - before.x_m, r.refined.y_m - before.y_m,
                              core::wrap_pi(r.refined.yaw_rad - before.yaw_rad));
  // Posterior information = the odometry's + the registration's; the correction is the
  // registration's pull weighed by both.
  const Eigen::Matrix3f prior = (covariance_ + 1e-8F * Eigen::Matrix3f::Identity()).inverse();
  const Eigen::Matrix3f posterior = (prior + info).inverse();
  const Eigen::Vector3f c = posterior * (info * delta);
  if (!c.allFinite()) {
    calibrator_.restart();
    return before;
  }
  covariance_ = posterior;
  const hal::Odometry o = base_.odometry();
  calibrator_.registered(o.wheels_known, o.wheel_left_m, o.wheel_right_m, delta.z(), c.z());
  const core::Pose2 after{before.x_m + c.x(), before.y_m + c.y(),
                          core::wrap_pi(before.yaw_rad + c.z())};
  frame_from_odometry_ =
      core::compose(after, core::compose(core::inverse(before), frame_from_odometry_));
  return after;
}

core::Pose2 PoseKeeper::pose() const {
  return core::compose(frame_from_odometry_, odometry());
}

core::Pose2 PoseKeeper::odometry_pose() const {
  return core::compose(anchored_from_odometry_, odometry());
}

core::Pose2 PoseKeeper::frame_origin_in_world(const core::Pose2& odometry_origin) const {
  // The mission frame is where the odometry was anchored; corrections move the robot in it.
  return core::compose(odometry_origin, core::inverse(anchored_from_odometry_));
}

}  // namespace boticelli::firmware::mission
