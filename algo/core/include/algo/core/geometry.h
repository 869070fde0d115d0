// Small plane geometry shared by mapping, planning and persistence: points and poses in the world
// frame.
#pragma once

#include <cmath>

#include "algo/core/angles.h"

namespace boticelli::core {

// A point on the floor plane [m] (world or robot frame, as the owner says).
struct Point2 {
  float x_m = 0.0F;
  float y_m = 0.0F;
};

// The robot's pose on the floor: position [m] and heading [rad], counter-clockwise from +x.
struct Pose2 {
  float x_m = 0.0F;
  float y_m = 0.0F;
  float yaw_rad = 0.0F;
};

inline float distance_m(Point2 a, Point2 b) {
  return std::hypot(a.x_m - b.x_m, a.y_m - b.y_m);
}

// Robot frame → world frame.
inline Point2 to_world(const Pose2& pose, Point2 p) {
  const float c = std::cos(pose.yaw_rad);
  const float s = std::sin(pose.yaw_rad);
  return {pose.x_m + c * p.x_m - s * p.y_m, pose.y_m + s * p.x_m + c * p.y_m};
}

// World frame → robot frame.
inline Point2 to_robot(const Pose2& pose, Point2 p) {
  const float c = std::cos(pose.yaw_rad);
  const float s = std::sin(pose.yaw_rad);
  const float dx = p.x_m - pose.x_m;
  const float dy = p.y_m - pose.y_m;
  return {c * dx + s * dy, -s * dx + c * dy};
}

// The pose `b`, given in the frame of pose `a`, in the frame `a` is given in (a ∘ b); both
// headings in (−π, π].
inline Pose2 compose(const Pose2& a, const Pose2& b) {
  const Point2 p = to_world(a, {b.x_m, b.y_m});
  // Into (−π, π] by one turn at most: exact when the sum is already in range.
  float yaw = a.yaw_rad + b.yaw_rad;
  if (yaw > kPi<float>) {
    yaw -= kTwoPi<float>;
  } else if (yaw <= -kPi<float>) {
    yaw += kTwoPi<float>;
  }
  return {p.x_m, p.y_m, yaw};
}

// The frame's own origin seen from the pose (a⁻¹): compose(a, inverse(a)) is the identity.
inline Pose2 inverse(const Pose2& a) {
  const Point2 p = to_robot(a, {0.0F, 0.0F});
  return {p.x_m, p.y_m, -a.yaw_rad};
}

// A differential drive's motion when its wheels travelled `left_m` and `right_m` on a track
// `track_m` wide, as one arc of constant curvature (exact for a straight line, a turn on the
// spot and any one arc), in the frame of the pose it started from. Heading wrapped to (−π, π].
inline Pose2 arc_motion(double left_m, double right_m, double track_m) {
  const double ds = 0.5 * (left_m + right_m);
  const double dyaw = (right_m - left_m) / track_m;
  const double half = 0.5 * dyaw;
  const double chord = std::fabs(half) > 1e-9 ? ds * std::sin(half) / half : ds;
  const double yaw = std::remainder(dyaw, 2.0 * kPi<double>);
  return {static_cast<float>(chord * std::cos(half)), static_cast<float>(chord * std::sin(half)),
          static_cast<float>(yaw <= -kPi<double> ? yaw + 2.0 * kPi<double> : yaw)};
}

}  // namespace boticelli::core
