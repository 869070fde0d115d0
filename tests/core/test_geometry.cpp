// Tests of the plane geometry helpers: frames, composition and inverse of poses.
#include "algo/core/geometry.h"
#include "CppUTest/TestHarness.h"

using namespace boticelli::core;

TEST_GROUP(Geometry){};

TEST(Geometry, ToRobotUndoesToWorld) {
  const Pose2 pose{1.5F, -2.0F, 2.5F};
  const Point2 w = to_world(pose, {0.3F, 0.7F});
  const Point2 r = to_robot(pose, w);
  DOUBLES_EQUAL(0.3, r.x_m, 1e-6);
  DOUBLES_EQUAL(0.7, r.y_m, 1e-6);
}

TEST(Geometry, ComposingPlacesTheSecondPoseInTheFirstPosesFrame) {
  // A robot 1 m ahead of a frame turned by 90°, itself turned by 90°: at (1, 2) facing −x.
  const Pose2 c = compose({1.0F, 1.0F, kPi<float> / 2.0F}, {1.0F, 0.0F, kPi<float> / 2.0F});
  DOUBLES_EQUAL(1.0, c.x_m, 1e-6);
  DOUBLES_EQUAL(2.0, c.y_m, 1e-6);
  DOUBLES_EQUAL(kPi<double>, std::fabs(c.yaw_rad), 1e-6);
}

TEST(Geometry, APoseComposedWithItsInverseIsTheIdentityEitherWay) {
  const Pose2 a{-0.8F, 3.1F, -2.2F};
  for (const Pose2& i : {compose(a, inverse(a)), compose(inverse(a), a)}) {
    DOUBLES_EQUAL(0.0, i.x_m, 1e-6);
    DOUBLES_EQUAL(0.0, i.y_m, 1e-6);
    DOUBLES_EQUAL(0.0, i.yaw_rad, 1e-6);
  }
}
