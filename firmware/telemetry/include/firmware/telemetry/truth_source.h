// TruthSource: the ground truth a simulated board reports (trace, target error, pictures).
#pragma once

#include <span>

#include <Eigen/Core>

#include "algo/core/geometry.h"
#include "firmware/telemetry/snapshot.h"

namespace boticelli::firmware {

// Ground truth a simulated board can report (never used to decide anything): the trace and
// the MISSION line's target error. Hardware boards have none.
class TruthSource {
 public:
  virtual ~TruthSource() = default;
  virtual core::Pose2 robot_pose() const = 0;       // true pose in the world [m, rad]
  virtual core::Pose2 odometry_origin() const = 0;  // world pose of the odometry frame's origin
  virtual Eigen::Vector3f target_m() const = 0;     // the true target point in the world [m]
  // The obstacles seen from above, for pictures: convex outlines and circles (world frame).
  virtual std::span<const std::span<const core::Point2>> outlines() const { return {}; }
  virtual std::span<const SnapshotCircle> circles() const { return {}; }

 protected:
  TruthSource() = default;
  TruthSource(const TruthSource&) = default;
  TruthSource& operator=(const TruthSource&) = default;
};

}  // namespace boticelli::firmware
