// Tests of the PoseKeeper: the mission frame anchored against the base's odometry.
#include <cmath>

#include "algo/core/angles.h"
#include "algo/core/geometry.h"
#include "firmware/mission/localize/pose_keeper.h"
#include "firmware_fakes.h"

#include "CppUTest/TestHarness.h"

using boticelli::core::kPi;
using boticelli::core::Pose2;
using boticelli::firmware::mission::PoseKeeper;
using boticelli::test::FakeBase;

namespace {

constexpr double kTol = 1e-5;

void set_odometry(FakeBase& base, double x_m, double y_m, double yaw_rad) {
  base.odometry_value.x_m = x_m;
  base.odometry_value.y_m = y_m;
  base.odometry_value.yaw_rad = yaw_rad;
}

void check_pose(const Pose2& expected, const Pose2& actual) {
  DOUBLES_EQUAL(expected.x_m, actual.x_m, kTol);
  DOUBLES_EQUAL(expected.y_m, actual.y_m, kTol);
  DOUBLES_EQUAL(expected.yaw_rad, actual.yaw_rad, kTol);
}

}  // namespace

TEST_GROUP(PoseKeeper) {
  FakeBase base;
  PoseKeeper keeper{base};
};

TEST(PoseKeeper, ANewMissionAnchoredAtTheOdometrysOriginReadsTheOdometryAsItIs) {
  keeper.anchor({});
  set_odometry(base, 1.5, -0.5, 0.7);
  check_pose({1.5F, -0.5F, 0.7F}, keeper.pose());
}

TEST(PoseKeeper, AnchoredAtASavedPoseThePoseFollowsTheOdometryComposedOntoIt) {
  keeper.anchor({1.0F, 2.0F, kPi<float> / 2.0F});
  // 1 m forward and 0.3 rad to the left in the odometry: 1 m along the saved heading (+y).
  set_odometry(base, 1.0, 0.0, 0.3);
  check_pose({1.0F, 3.0F, kPi<float> / 2.0F + 0.3F}, keeper.pose());
  // 1 m to the odometry's left: along −x in the mission frame.
  set_odometry(base, 0.0, 1.0, 0.0);
  check_pose({0.0F, 2.0F, kPi<float> / 2.0F}, keeper.pose());
}

TEST(PoseKeeper, AnchoringWhileTheOdometryIsAwayFromItsOriginPutsTheRobotAtTheAnchorNow) {
  // The base reports a pose already (it was ready before the mission started).
  set_odometry(base, 2.0, -1.0, 0.5);
  keeper.anchor({1.0F, 2.0F, kPi<float> / 2.0F});
  check_pose({1.0F, 2.0F, kPi<float> / 2.0F}, keeper.pose());
  // 1 m forward along the odometry's heading is 1 m forward along the anchor's; a turn in
  // place turns it by as much.
  set_odometry(base, 2.0 + std::cos(0.5), -1.0 + std::sin(0.5), 0.5 - 0.25);
  check_pose({1.0F, 3.0F, kPi<float> / 2.0F - 0.25F}, keeper.pose());
}

TEST(PoseKeeper, AResumedMissionCarriesOnInTheSavedFrameWhileTheOdometryRestartsAtZero) {
  // The first run: a new mission, the robot drives to where the state is saved.
  keeper.anchor({});
  set_odometry(base, 1.0, 1.0, kPi<double> / 4.0);
  const Pose2 saved = keeper.pose();
  // The second run: a fresh base whose odometry starts at zero, anchored at the saved pose.
  FakeBase restarted;
  PoseKeeper resumed{restarted};
  resumed.anchor(saved);
  check_pose(saved, resumed.pose());
  // Half a metre forward goes on along the saved heading, in the first run's frame.
  set_odometry(restarted, 0.5, 0.0, 0.0);
  const float d = 0.5F / std::sqrt(2.0F);
  check_pose({1.0F + d, 1.0F + d, kPi<float> / 4.0F}, resumed.pose());
}

TEST(PoseKeeper, TheMissionFramesOriginInTheWorldInvertsTheAnchor) {
  // The mission frame's origin lies 1 m behind the robot's start, turned by a quarter turn.
  keeper.anchor({1.0F, 0.0F, kPi<float> / 2.0F});
  // The odometry's origin stands at the world's origin: the frame's origin is the anchor's
  // inverse, (0, 1) and turned back by a quarter turn.
  check_pose({0.0F, 1.0F, -kPi<float> / 2.0F}, keeper.frame_origin_in_world({}));
  // Anywhere: the robot's world pose is its mission pose seen from the frame's origin, and
  // its odometry seen from the odometry's origin.
  set_odometry(base, 0.8, -0.4, 1.1);
  const Pose2 odometry_origin{3.0F, -2.0F, 0.6F};
  const Pose2 via_mission =
      boticelli::core::compose(keeper.frame_origin_in_world(odometry_origin), keeper.pose());
  const Pose2 via_odometry = boticelli::core::compose(odometry_origin, {0.8F, -0.4F, 1.1F});
  check_pose(via_odometry, via_mission);
}

namespace {

// A registration that constrains all three directions equally (eigenvalue `information`
// each) and found the look at `registered`.
boticelli::worldmap::Registration registration(const Pose2& initial, const Pose2& registered,
                                               float information, int constrained = 3) {
  boticelli::worldmap::Registration r;
  r.matched = true;
  r.initial = initial;
  r.refined = registered;
  r.pose = registered;
  r.residual_m = 0.03F;
  r.eigenvalues = Eigen::Vector3f::Constant(information);
  r.eigenvectors = Eigen::Matrix3f::Identity();
  r.constrained = constrained;
  return r;
}

}  // namespace

TEST(PoseKeeper, ARegistrationMovesThePoseByItsWeightAgainstTheOdometryAndTheOdometryCarriesOn) {
  keeper.anchor({});
  // 2 m driven and half a turn turned: the odometry is uncertain by centimetres and degrees.
  set_odometry(base, 2.0, 0.0, kPi<double> / 2.0);
  keeper.moved({0.0F, 0.0F, 0.0F}, {2.0F, 0.0F, kPi<float> / 2.0F});
  const Pose2 before = keeper.pose();
  const Pose2 found{2.1F, -0.05F, kPi<float> / 2.0F - 0.03F};
  const Pose2 after = keeper.correct(before, registration(before, found, 200.0F));
  // Most of the way to the registration (it is the surer), not all of it.
  CHECK(after.x_m > 2.07F && after.x_m < 2.1F);
  CHECK(after.y_m < -0.035F && after.y_m > -0.05F);
  CHECK(after.yaw_rad < kPi<float> / 2.0F - 0.02F);
  check_pose(after, keeper.pose());
  // The odometry then carries on from the corrected pose: 1 m straight on.
  set_odometry(base, 2.0, 1.0, kPi<double> / 2.0);
  const Pose2 on = boticelli::core::compose(after, {1.0F, 0.0F, 0.0F});
  check_pose(on, keeper.pose());
  // The raw odometry in the mission frame is untouched by the correction.
  check_pose({2.0F, 1.0F, kPi<float> / 2.0F}, keeper.odometry_pose());
  // The pose is surer after the registration than before it.
  CHECK(keeper.covariance()(0, 0) < 0.02F * 0.02F * 4.0F);
}

TEST(PoseKeeper, WithoutMotionOrAlongAnUnconstrainedDirectionTheOdometryStands) {
  keeper.anchor({});
  const Pose2 before = keeper.pose();
  // No motion since the anchor: the pose is known, a registration does not move it.
  const Pose2 still = keeper.correct(before, registration(before, {0.2F, 0.1F, 0.05F}, 200.0F));
  DOUBLES_EQUAL(before.x_m, still.x_m, 1e-4);
  DOUBLES_EQUAL(before.y_m, still.y_m, 1e-4);
  DOUBLES_EQUAL(before.yaw_rad, still.yaw_rad, 1e-4);
  // After a move, a registration that constrains only y and heading (a wall along x) moves
  // neither x nor anything when it is not matched.
  set_odometry(base, 3.0, 0.0, 0.0);
  keeper.moved({0.0F, 0.0F, 0.0F}, {3.0F, 0.0F, 0.0F});
  const Pose2 odo = keeper.pose();
  boticelli::worldmap::Registration wall = registration(odo, {3.2F, 0.1F, 0.0F}, 200.0F, 2);
  wall.eigenvalues = Eigen::Vector3f(0.05F, 200.0F, 200.0F);  // x (column 0) unconstrained
  const Pose2 after = keeper.correct(odo, wall);
  DOUBLES_EQUAL(3.0, after.x_m, 1e-4);
  CHECK(after.y_m > 0.05F);
  wall.matched = false;
  check_pose(keeper.pose(), keeper.correct(keeper.pose(), wall));
}

TEST(PoseKeeper, EachMoveAndEachMatchedRegistrationReachTheBaseCalibratorWithTheWheelCounters) {
  base.odometry_value.wheels_known = true;
  keeper.anchor({});
  const Pose2 start = keeper.pose();
  (void)keeper.correct(start, registration(start, start, 200.0F));  // the first interval begins
  // A left turn of 1 rad by a 0.4 m track, then 0.5 m straight.
  base.odometry_value.wheel_left_m = -0.2 + 0.5;
  base.odometry_value.wheel_right_m = 0.2 + 0.5;
  set_odometry(base, 0.5 * std::cos(1.0), 0.5 * std::sin(1.0), 1.0);
  keeper.moved(start, keeper.pose());
  LONGS_EQUAL(0, keeper.calibrator().estimate().intervals);
  const Pose2 before = keeper.pose();
  boticelli::worldmap::Registration r = registration(before, before, 200.0F);
  r.matched = false;
  (void)keeper.correct(before, r);  // not matched: the interval goes on
  LONGS_EQUAL(0, keeper.calibrator().estimate().intervals);
  (void)keeper.correct(before, registration(before, before, 200.0F));
  const boticelli::firmware::mission::BaseCalibration e = keeper.calibrator().estimate();
  LONGS_EQUAL(1, e.intervals);
  DOUBLES_EQUAL(1.0, e.turned_rad, 1e-4);
  DOUBLES_EQUAL(0.5, e.driven_m, 1e-4);
  // Anchored again (a resumed mission): the move before the next registration is not used.
  keeper.anchor(keeper.pose());
  base.odometry_value.wheel_left_m += 0.5;
  base.odometry_value.wheel_right_m += 0.5;
  keeper.moved(before, keeper.pose());
  (void)keeper.correct(keeper.pose(), registration(keeper.pose(), keeper.pose(), 200.0F));
  LONGS_EQUAL(1, keeper.calibrator().estimate().intervals);
}
