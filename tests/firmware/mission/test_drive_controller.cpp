// Tests of the DriveController on a simulated differential-drive base (ramped speeds, wheel
// errors).
#include <algorithm>
#include <cmath>
#include <cstdint>

#include "algo/core/angles.h"
#include "algo/core/geometry.h"
#include "firmware/mission/drive/drive_controller.h"

#include "CppUTest/TestHarness.h"

using boticelli::core::distance_m;
using boticelli::core::Point2;
using boticelli::core::Pose2;
using boticelli::core::wrap_pi;
using namespace boticelli::firmware::mission;

namespace {

constexpr float kDt_s = 0.01F;
constexpr std::uint64_t kDt_us = 10000;

// A differential-drive base: the setpoint is followed with a speed ramp (1 m/s², 3 rad/s²)
// and a yaw rate limit (0.8 rad/s); each wheel then turns by its own scale error (slip, a
// worn tyre), and the odometry integrates what the wheels did. `stuck` holds it in place
// (blocked wheels: the odometry reads no motion).
struct SimBase {
  Pose2 pose{};
  float v_cmd_m_s = 0.0F;  // ramped setpoint
  float w_cmd_rad_s = 0.0F;
  float v_m_s = 0.0F;  // measured (from the wheels)
  float w_rad_s = 0.0F;
  float left_scale = 1.0F;
  float right_scale = 1.0F;
  float track_m = 0.4F;
  float w_accel_rad_s2 = 3.0F;  // how fast the yaw rate follows its setpoint
  bool stuck = false;

  void step(const DriveCommand& c) {
    if (stuck) {
      v_m_s = w_rad_s = 0.0F;
      return;
    }
    v_cmd_m_s += std::clamp(c.v_m_s - v_cmd_m_s, -1.0F * kDt_s, 1.0F * kDt_s);
    w_cmd_rad_s +=
        std::clamp(c.omega_rad_s - w_cmd_rad_s, -w_accel_rad_s2 * kDt_s, w_accel_rad_s2 * kDt_s);
    w_cmd_rad_s = std::clamp(w_cmd_rad_s, -0.8F, 0.8F);
    const float left = (v_cmd_m_s - 0.5F * w_cmd_rad_s * track_m) * left_scale;
    const float right = (v_cmd_m_s + 0.5F * w_cmd_rad_s * track_m) * right_scale;
    v_m_s = 0.5F * (left + right);
    w_rad_s = (right - left) / track_m;
    const float mid_yaw = pose.yaw_rad + 0.5F * w_rad_s * kDt_s;
    pose.x_m += v_m_s * std::cos(mid_yaw) * kDt_s;
    pose.y_m += v_m_s * std::sin(mid_yaw) * kDt_s;
    pose.yaw_rad = wrap_pi(pose.yaw_rad + w_rad_s * kDt_s);
  }
};

// What one drive did, seen from outside.
struct DriveLog {
  std::uint64_t periods = 0;
  float max_v_m_s = 0.0F;    // largest |commanded v|
  float min_v_m_s = 0.0F;    // most negative commanded v
  float max_w_rad_s = 0.0F;  // largest |commanded ω|
  // Heading error (to the start→end direction) when v was first commanded non-zero; and how
  // far the base had moved from its start by then.
  float heading_error_at_first_v_rad = -1.0F;
  bool drove = false;
};

class Drive {
 public:
  DriveController controller;
  SimBase base;
  std::uint64_t now_us = 1000000;
  DriveLog log;

  void start(Point2 end) {
    line_heading_ = std::atan2(end.y_m - base.pose.y_m, end.x_m - base.pose.x_m);
    controller.start(base.pose, end, now_us);
    log = DriveLog{};
  }
  DriveCommand period() {
    const DriveCommand c = controller.update(base.pose, base.v_m_s, base.w_rad_s, now_us);
    log.max_v_m_s = std::max(log.max_v_m_s, std::fabs(c.v_m_s));
    log.min_v_m_s = std::min(log.min_v_m_s, c.v_m_s);
    log.max_w_rad_s = std::max(log.max_w_rad_s, std::fabs(c.omega_rad_s));
    if (c.v_m_s != 0.0F && !log.drove) {
      log.drove = true;
      log.heading_error_at_first_v_rad = std::fabs(wrap_pi(line_heading_ - base.pose.yaw_rad));
    }
    base.step(c);
    now_us += kDt_us;
    ++log.periods;
    return c;
  }
  // Runs until the controller is no longer busy (or `max_s` of simulated time).
  void run(float max_s = 60.0F) {
    const auto max_periods = static_cast<std::uint64_t>(max_s / kDt_s);
    while (controller.busy() && log.periods < max_periods) {
      period();
    }
  }

 private:
  float line_heading_ = 0.0F;
};

void check_ended_at_rest_at(const Drive& d, Point2 end) {
  CHECK(d.controller.status() == DriveStatus::kDone);
  const float tol = d.controller.params().position_tolerance_m;
  // Within the tolerance plus the stopping distance after it (v ≈ √(2·a·tol), ramp 1 m/s²).
  CHECK_TEXT(distance_m({d.base.pose.x_m, d.base.pose.y_m}, end) <= 2.0F * tol,
             "stopped too far from the end");
  CHECK(std::fabs(d.base.v_m_s) <= d.controller.params().settle_speed_m_s);
  CHECK(std::fabs(d.base.w_rad_s) <= d.controller.params().settle_rate_rad_s);
}

void check_within_limits(const Drive& d) {
  CHECK(d.log.max_v_m_s <= d.controller.params().max_speed_m_s);
  CHECK(d.log.max_w_rad_s <= d.controller.params().max_turn_rate_rad_s);
  CHECK(d.log.min_v_m_s >= 0.0F);  // never backs up
}

}  // namespace

TEST_GROUP(DriveController) {
  Drive d;
  void setup() override {
    d.controller.configure(DriveParams{});
  }
};

TEST(DriveController, ReachesTheEndOfAStepAndEndsAtRest) {
  d.base.pose = {0.2F, -0.1F, 0.3F};
  const Point2 end{1.4F, 0.7F};
  d.start(end);
  CHECK(d.controller.status() == DriveStatus::kTurning);
  d.run();
  check_ended_at_rest_at(d, end);
  check_within_limits(d);
  // A 1.44 m leg at 0.3 m/s needs at least 4.8 s: it did drive at full speed.
  DOUBLES_EQUAL(d.controller.params().max_speed_m_s, d.log.max_v_m_s, 1e-4);
}

TEST(DriveController, TurnsInPlaceBeforeItDrivesForward) {
  d.base.pose = {0.0F, 0.0F, 0.0F};
  const Point2 end{0.0F, 1.0F};  // 90° to the left
  d.start(end);
  // Some periods into the turn: turning, not moving forward.
  for (int i = 0; i < 50; ++i) {
    const DriveCommand c = d.period();
    DOUBLES_EQUAL(0.0, c.v_m_s, 0.0);
    CHECK(c.omega_rad_s > 0.0F);  // the short way round
  }
  CHECK(d.controller.status() == DriveStatus::kTurning);
  d.run();
  CHECK(d.log.drove);
  CHECK(d.log.heading_error_at_first_v_rad <= d.controller.params().heading_tolerance_rad);
  check_ended_at_rest_at(d, end);
}

TEST(DriveController, NeverCommandsMoreThanTheSpeedLimits) {
  DriveParams p;
  p.max_speed_m_s = 0.2F;
  p.max_turn_rate_rad_s = 0.5F;
  d.controller.configure(p);
  d.base.pose = {0.0F, 0.0F, 2.5F};
  const Point2 end{2.5F, -1.0F};
  d.start(end);
  d.run();
  check_within_limits(d);
  DOUBLES_EQUAL(0.2, d.log.max_v_m_s, 1e-4);
  DOUBLES_EQUAL(0.5, d.log.max_w_rad_s, 1e-4);
  check_ended_at_rest_at(d, end);
}

TEST(DriveController, CorrectsItsHeadingWhenTheWheelsSlipUnequally) {
  d.base.left_scale = 1.02F;
  d.base.right_scale = 0.98F;  // drifts right when driving straight
  d.base.pose = {0.0F, 0.0F, 0.0F};
  const Point2 end{2.0F, 0.0F};
  d.start(end);
  float worst_cross_m = 0.0F;
  while (d.controller.busy() && d.log.periods < 6000) {
    d.period();
    worst_cross_m = std::max(worst_cross_m, std::fabs(d.base.pose.y_m));
  }
  check_ended_at_rest_at(d, end);
  check_within_limits(d);
  CHECK(worst_cross_m < d.controller.params().max_cross_track_m);
}

TEST(DriveController, TurnsAroundForAStepBehindTheRobot) {
  d.base.pose = {1.0F, 1.0F, 0.0F};
  const Point2 end{0.0F, 1.0F};  // straight behind: 180°
  d.start(end);
  d.run();
  CHECK(d.log.heading_error_at_first_v_rad <= d.controller.params().heading_tolerance_rad);
  check_ended_at_rest_at(d, end);
  check_within_limits(d);
}

TEST(DriveController, TurnsTheShortWayAcrossTheHeadingSeam) {
  // Facing 3.0 rad, the end lies at −3.0 rad: 0.28 rad to the left across ±π, not 6 to the right.
  d.base.pose = {0.0F, 0.0F, 3.0F};
  const Point2 end{std::cos(-3.0F), std::sin(-3.0F)};
  d.start(end);
  CHECK(d.period().omega_rad_s > 0.0F);
  while (d.controller.status() == DriveStatus::kTurning && d.log.periods < 1000) d.period();
  CHECK(static_cast<float>(d.log.periods) * kDt_s < 1.5F);
  d.run();
  check_ended_at_rest_at(d, end);
}

TEST(DriveController, ATinyStepIsDoneAtOnce) {
  d.base.pose = {1.0F, 1.0F, 0.5F};
  d.start({1.005F, 1.005F});
  CHECK(d.controller.status() == DriveStatus::kDone);
  CHECK_FALSE(d.controller.busy());
  const DriveCommand c = d.period();
  DOUBLES_EQUAL(0.0, c.v_m_s, 0.0);
  DOUBLES_EQUAL(0.0, c.omega_rad_s, 0.0);
}

TEST(DriveController, AbortStopsAndFailsWithTheReasonOnceTheBaseHasSettled) {
  d.base.pose = {0.0F, 0.0F, 0.0F};
  d.start({2.0F, 0.0F});
  for (int i = 0; i < 300 && d.controller.status() != DriveStatus::kDriving; ++i) d.period();
  for (int i = 0; i < 200; ++i) d.period();  // 2 s into the leg: at full speed
  CHECK(d.controller.status() == DriveStatus::kDriving);
  CHECK(d.base.v_m_s > 0.2F);
  d.controller.abort("obstacle ahead");
  CHECK(d.controller.status() == DriveStatus::kStopping);
  CHECK(d.controller.busy());
  const DriveCommand c = d.period();
  DOUBLES_EQUAL(0.0, c.v_m_s, 0.0);
  DOUBLES_EQUAL(0.0, c.omega_rad_s, 0.0);
  // Still rolling: not yet failed.
  CHECK(d.controller.status() == DriveStatus::kStopping);
  d.run();
  CHECK(d.controller.status() == DriveStatus::kFailed);
  STRCMP_EQUAL("obstacle ahead", d.controller.failure());
  CHECK(std::fabs(d.base.v_m_s) <= d.controller.params().settle_speed_m_s);
  CHECK(d.log.max_v_m_s <= d.controller.params().max_speed_m_s);
}

TEST(DriveController, AbortWhenIdleOrDoneChangesNothing) {
  d.controller.abort("nothing to stop");
  CHECK(d.controller.status() == DriveStatus::kIdle);
  d.start({1.0F, 0.0F});
  d.run();
  CHECK(d.controller.status() == DriveStatus::kDone);
  d.controller.abort("too late");
  CHECK(d.controller.status() == DriveStatus::kDone);
  STRCMP_EQUAL("", d.controller.failure());
}

TEST(DriveController, ABaseThatDoesNotMoveTimesOut) {
  d.base.stuck = true;
  d.base.pose = {0.0F, 0.0F, 0.0F};
  const Point2 end{0.0F, 1.0F};
  d.start(end);
  // Nominal: the 90° turn at 0.8 rad/s, 1 m at 0.3 m/s, the ramps (2·0.3/0.4 s), 1 s; ×3.
  const DriveParams& p = d.controller.params();
  const float nominal_s = 1.5708F / p.max_turn_rate_rad_s + 1.0F / p.max_speed_m_s +
                          2.0F * p.max_speed_m_s / p.accel_m_s2 + 1.0F;
  d.run(120.0F);
  CHECK(d.controller.status() == DriveStatus::kFailed);
  STRCMP_EQUAL("step timed out", d.controller.failure());
  const float took_s = static_cast<float>(d.log.periods) * kDt_s;
  CHECK(took_s >= nominal_s * p.timeout_factor - 0.05F);
  CHECK(took_s <= nominal_s * p.timeout_factor + 0.05F);
}

TEST(DriveController, ASidePushBeyondTheLimitToEitherSideAbortsTheStep) {
  for (const float push_m : {0.1F, -0.1F}) {  // left, then right; max_cross_track_m is 0.06 m
    Drive drive;
    drive.controller.configure(DriveParams{});
    drive.base.pose = {0.0F, 0.0F, 0.0F};
    drive.start({2.0F, 0.0F});
    while (drive.controller.status() != DriveStatus::kDriving && drive.log.periods < 1000) {
      drive.period();
    }
    for (int i = 0; i < 150; ++i) drive.period();
    drive.base.pose.y_m += push_m;  // knocked sideways
    drive.period();
    CHECK(drive.controller.status() == DriveStatus::kStopping);
    drive.run();
    CHECK(drive.controller.status() == DriveStatus::kFailed);
    STRCMP_EQUAL("left the step's line", drive.controller.failure());
    CHECK(drive.base.pose.x_m < 1.5F);  // it stopped there, it did not go on
  }
}

TEST(DriveController, NeverGoesFasterThanItCanStopInWhatIsLeftOfTheStep) {
  d.base.pose = {0.0F, 0.0F, 0.0F};
  const Point2 end{1.2F, 0.0F};
  d.start(end);
  const float a = d.controller.params().accel_m_s2;
  std::uint64_t checked = 0;
  while (d.controller.busy() && d.log.periods < 6000) {
    const float left_m = end.x_m - d.base.pose.x_m;  // along the line (it is the x axis)
    const DriveCommand c = d.period();
    if (c.v_m_s > 0.0F) {
      CHECK(c.v_m_s <= std::sqrt(2.0F * a * std::max(left_m, 0.0F)) + 1e-4F);
      ++checked;
    }
  }
  CHECK(checked > 100);
  check_ended_at_rest_at(d, end);
}

TEST(DriveController, AHeavyBaseStopsTurningBeforeItDrivesOff) {
  d.base.w_accel_rad_s2 = 0.4F;  // the yaw rate lags its setpoint: it overshoots the heading
  d.base.pose = {0.0F, 0.0F, 0.0F};
  const Point2 end{0.0F, 1.5F};  // 90° to the left
  d.start(end);
  float w_at_first_v = -1.0F;
  while (d.controller.busy() && d.log.periods < 6000) {
    const float w = d.base.w_rad_s;
    const DriveCommand c = d.period();
    if (c.v_m_s > 0.0F && w_at_first_v < 0.0F) w_at_first_v = std::fabs(w);
  }
  CHECK(w_at_first_v >= 0.0F);
  CHECK(w_at_first_v <= 10.0F * d.controller.params().settle_rate_rad_s);
  check_ended_at_rest_at(d, end);
}

TEST(DriveController, AnAbortDuringATurnFailsOnlyOnceTheBaseHasStoppedTurning) {
  d.base.pose = {0.0F, 0.0F, 0.0F};
  d.start({-1.0F, 0.1F});  // nearly behind: a long turn
  for (int i = 0; i < 100; ++i) d.period();
  CHECK(d.controller.status() == DriveStatus::kTurning);
  CHECK(std::fabs(d.base.w_rad_s) > 0.5F);
  d.controller.abort("obstacle ahead");
  while (d.controller.status() == DriveStatus::kStopping && d.log.periods < 1000) d.period();
  CHECK(d.controller.status() == DriveStatus::kFailed);
  CHECK(std::fabs(d.base.w_rad_s) <= d.controller.params().settle_rate_rad_s);
}

TEST(DriveController, ASmallSidePushIsCorrected) {
  d.base.pose = {0.0F, 0.0F, 0.0F};
  const Point2 end{2.0F, 0.0F};
  d.start(end);
  while (d.controller.status() != DriveStatus::kDriving && d.log.periods < 1000) d.period();
  for (int i = 0; i < 150; ++i) d.period();
  d.base.pose.y_m += 0.04F;  // within max_cross_track_m
  d.run();
  check_ended_at_rest_at(d, end);
}

TEST(DriveController, ATurnInPlaceFacesTheHeadingAndEndsAtRestWhereItStarted) {
  d.base.pose = {1.0F, 1.0F, 0.4F};
  d.controller.start_turn(d.base.pose, 0.4F - 3.0F, d.now_us);
  CHECK(d.controller.status() == DriveStatus::kTurning);
  d.run();
  CHECK(d.controller.status() == DriveStatus::kDone);
  CHECK(std::fabs(wrap_pi(d.base.pose.yaw_rad - (0.4F - 3.0F))) <=
        d.controller.params().heading_tolerance_rad + 0.01F);
  DOUBLES_EQUAL(0.0, d.log.max_v_m_s, 0.0);  // never drove
  CHECK(distance_m({d.base.pose.x_m, d.base.pose.y_m}, {1.0F, 1.0F}) < 1e-4F);
  CHECK(std::fabs(d.base.w_rad_s) <= d.controller.params().settle_rate_rad_s);
}

TEST(DriveController, ABasePushedPastTheEndOfItsStepIsStoppedNotDrivenOn) {
  for (const float past_m : {0.02F, 0.3F, 2.0F}) {  // beyond the end along the step's line
    DriveController controller;
    controller.configure(DriveParams{});
    controller.start({0.0F, 0.0F, 0.0F}, {1.0F, 0.0F}, 0);
    (void)controller.update({0.0F, 0.0F, 0.0F}, 0.0F, 0.0F, kDt_us);  // facing it already
    CHECK(controller.status() == DriveStatus::kDriving);
    const DriveCommand c = controller.update({1.0F + past_m, 0.0F, 0.0F}, 0.3F, 0.0F, 2 * kDt_us);
    CHECK(controller.status() == DriveStatus::kStopping);
    DOUBLES_EQUAL(0.0, static_cast<double>(c.v_m_s), 0.0);
    DOUBLES_EQUAL(0.0, static_cast<double>(c.omega_rad_s), 0.0);
  }
}

TEST(DriveController, ABaseThatDoesNotMoveTimesOutAfterTheTurnFromItsOwnHeading) {
  d.base.stuck = true;
  d.base.pose = {0.0F, 0.0F, 1.0F};  // facing 1 rad; the end is a quarter turn to its left
  const float heading = 1.0F + 1.5708F;
  d.start({std::cos(heading), std::sin(heading)});
  const DriveParams& p = d.controller.params();
  const float nominal_s = 1.5708F / p.max_turn_rate_rad_s + 1.0F / p.max_speed_m_s +
                          2.0F * p.max_speed_m_s / p.accel_m_s2 + 1.0F;
  d.run(120.0F);
  STRCMP_EQUAL("step timed out", d.controller.failure());
  const float took_s = static_cast<float>(d.log.periods) * kDt_s;
  CHECK(took_s >= nominal_s * p.timeout_factor - 0.05F);
  CHECK(took_s <= nominal_s * p.timeout_factor + 0.05F);
}

TEST(DriveController, ATurnInPlaceOnABaseThatDoesNotMoveTimesOutAfterItsNominalTimeTimesTheFactor) {
  d.base.stuck = true;
  d.base.pose = {0.0F, 0.0F, 0.5F};
  d.controller.start_turn(d.base.pose, 0.5F + 1.5708F, d.now_us);
  const DriveParams& p = d.controller.params();
  const float nominal_s = 1.5708F / p.max_turn_rate_rad_s + 1.0F;  // the turn, then 1 s
  d.run(120.0F);
  CHECK(d.controller.status() == DriveStatus::kFailed);
  STRCMP_EQUAL("step timed out", d.controller.failure());
  const float took_s = static_cast<float>(d.log.periods) * kDt_s;
  CHECK(took_s >= nominal_s * p.timeout_factor - 0.05F);
  CHECK(took_s <= nominal_s * p.timeout_factor + 0.05F);
}

TEST(DriveController, ATurnEndsFacingTheHeadingWhileStillTurningSlowerThanTenTimesTheSettleRate) {
  const DriveParams p{};
  const float limit = 10.0F * p.settle_rate_rad_s;  // 0.2 rad/s
  for (const float omega : {0.75F * limit, 1.5F * limit}) {
    DriveController controller;
    controller.configure(p);
    controller.start({0.0F, 0.0F, 0.0F}, {1.0F, 0.0F}, 0);
    (void)controller.update({0.0F, 0.0F, 0.0F}, 0.0F, omega, kDt_us);  // facing, still turning
    CHECK(controller.status() == (omega <= limit ? DriveStatus::kDriving : DriveStatus::kTurning));
  }
}

TEST(DriveController, WithinFiveCentimetresOfTheEndItSteersToTheStepsHeadingNotToTheEndPoint) {
  // 1 cm left of the line, facing along it: far from the end it turns towards the end point,
  // within 5 cm it holds the heading (turning there would swing the base round the point).
  for (const float left_m : {0.04F, 0.07F}) {
    DriveController controller;
    controller.configure(DriveParams{});
    controller.start({0.0F, 0.0F, 0.0F}, {1.0F, 0.0F}, 0);
    (void)controller.update({0.0F, 0.0F, 0.0F}, 0.0F, 0.0F, kDt_us);
    CHECK(controller.status() == DriveStatus::kDriving);
    const DriveCommand c = controller.update({1.0F - left_m, 0.01F, 0.0F}, 0.1F, 0.0F, 2 * kDt_us);
    CHECK(c.v_m_s > 0.0F);
    if (left_m < 0.05F) {
      DOUBLES_EQUAL(0.0, static_cast<double>(c.omega_rad_s), 0.0);
    } else {
      CHECK(c.omega_rad_s < -0.1F);  // right, towards the end point
    }
  }
}

TEST(DriveController, AtExactlyThePositionToleranceFromTheEndTheStepIsDone) {
  DriveParams p{};
  p.position_tolerance_m = 0.25F;  // exact in binary, as are the positions below
  DriveController controller;
  controller.configure(p);
  controller.start({0.0F, 0.0F, 0.0F}, {1.0F, 0.0F}, 0);
  (void)controller.update({0.0F, 0.0F, 0.0F}, 0.0F, 0.0F, kDt_us);
  (void)controller.update({0.5F, 0.0F, 0.0F}, 0.2F, 0.0F, 2 * kDt_us);
  CHECK(controller.status() == DriveStatus::kDriving);  // 0.5 m to go
  const DriveCommand c = controller.update({0.75F, 0.0F, 0.0F}, 0.2F, 0.0F, 3 * kDt_us);
  CHECK(controller.status() == DriveStatus::kStopping);
  DOUBLES_EQUAL(0.0, static_cast<double>(c.v_m_s), 0.0);
}

TEST(DriveController, AStepOfExactlyThePositionToleranceIsDoneAtOnceAndALongerOneTurnsFirst) {
  DriveParams p{};
  p.position_tolerance_m = 0.25F;  // exact in binary, as are the ends below
  for (const float length_m : {0.25F, 0.25F + 1.0F / 1024.0F}) {
    DriveController controller;
    controller.configure(p);
    controller.start({0.0F, 0.0F, 1.0F}, {length_m, 0.0F}, 0);
    CHECK(controller.status() == (length_m <= 0.25F ? DriveStatus::kDone : DriveStatus::kTurning));
  }
}

TEST(DriveController, ATurnEndsAtExactlyTheHeadingToleranceAndNotBeyondIt) {
  DriveParams p{};
  p.heading_tolerance_rad = 0.0625F;  // exact in binary, as are the yaws below
  for (const float off_rad : {0.0625F, 0.0625F + 1.0F / 1024.0F}) {
    for (const float side : {-1.0F, 1.0F}) {
      DriveController controller;
      controller.configure(p);
      controller.start({0.0F, 0.0F, side * off_rad}, {1.0F, 0.0F}, 0);
      (void)controller.update({0.0F, 0.0F, side * off_rad}, 0.0F, 0.0F, kDt_us);
      CHECK(controller.status() ==
            (off_rad <= 0.0625F ? DriveStatus::kDriving : DriveStatus::kTurning));
    }
  }
}

TEST(DriveController, ThePeriodThatEndsTheTurnCommandsRestSoTheLegStartsFromIt) {
  DriveController controller;
  controller.configure(DriveParams{});
  controller.start({0.0F, 0.0F, 0.0F}, {1.0F, 0.0F}, 0);
  const DriveCommand c = controller.update({0.0F, 0.0F, 0.01F}, 0.0F, 0.0F, kDt_us);
  CHECK(controller.status() == DriveStatus::kDriving);
  DOUBLES_EQUAL(0.0, static_cast<double>(c.v_m_s), 0.0);
  DOUBLES_EQUAL(0.0, static_cast<double>(c.omega_rad_s), 0.0);
}

TEST(DriveController, ThePeriodThatFindsTheBaseOffTheStepsLineCommandsAStop) {
  DriveController controller;
  controller.configure(DriveParams{});
  controller.start({0.0F, 0.0F, 0.0F}, {2.0F, 0.0F}, 0);
  (void)controller.update({0.0F, 0.0F, 0.0F}, 0.0F, 0.0F, kDt_us);
  const DriveCommand c = controller.update({1.0F, 0.1F, 0.0F}, 0.3F, 0.0F, 2 * kDt_us);
  CHECK(controller.status() == DriveStatus::kStopping);
  DOUBLES_EQUAL(0.0, static_cast<double>(c.v_m_s), 0.0);
  DOUBLES_EQUAL(0.0, static_cast<double>(c.omega_rad_s), 0.0);
}

TEST(DriveController, ANewTurnForgetsTheFailureOfTheStepBeforeIt) {
  DriveController controller;
  controller.configure(DriveParams{});
  controller.start({0.0F, 0.0F, 0.0F}, {1.0F, 0.0F}, 0);
  controller.abort("operator");
  (void)controller.update({0.0F, 0.0F, 0.0F}, 0.0F, 0.0F, kDt_us);
  CHECK(controller.status() == DriveStatus::kFailed);
  controller.start_turn({0.0F, 0.0F, 0.0F}, 1.0F, 2 * kDt_us);
  STRCMP_EQUAL("", controller.failure());
  controller.start({0.0F, 0.0F, 0.0F}, {1.0F, 0.0F}, 3 * kDt_us);
  controller.abort("operator");
  controller.start({0.0F, 0.0F, 0.0F}, {1.0F, 0.0F}, 4 * kDt_us);
  STRCMP_EQUAL("", controller.failure());
}
