// PoseKeeper: the mission frame against the odometry (see pose_keeper.h).
#include "firmware/mission/localize/pose_keeper.h"

namespace boticelli::firmware::mission {

core::Pose2 PoseKeeper::odometry() const {
  const hal::Odometry o = base_.odometry();
  return {static_cast<float>(o.x_m), static_cast<float>(o.y_m), static_cast<float>(o.yaw_rad)};
}

void PoseKeeper::anchor(const core::Pose2& mission_pose) {
  frame_from_odometry_ = core::compose(mission_pose, core::inverse(odometry()));
}

core::Pose2 PoseKeeper::pose() const {
  return core::compose(frame_from_odometry_, odometry());
}

core::Pose2 PoseKeeper::frame_origin_in_world(const core::Pose2& odometry_origin) const {
  return core::compose(odometry_origin, core::inverse(frame_from_odometry_));
}

}  // namespace boticelli::firmware::mission
