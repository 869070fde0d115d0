// Tests of the BaseCalibrator: a base's effective track and wheel diameter ratio recovered from
// registrations of looks between moves.
#include <cmath>
#include <cstdint>
#include <numbers>

#include "algo/core/angles.h"
#include "firmware/mission/localize/base_calibrator.h"

#include "CppUTest/TestHarness.h"

using boticelli::firmware::mission::BaseCalibration;
using boticelli::firmware::mission::BaseCalibrator;

namespace {

constexpr double kPi = std::numbers::pi;

// A differential drive whose odometry assumes a track of 0.40 m and equal wheels, while the
// ground turns it by its true track and diameter ratio. Registrations see the true heading
// (plus `noise_rad` of a fixed pseudo-random sequence) and correct half of the error.
struct Base {
  double nominal_track_m = 0.40;
  double true_track_m = 0.40;
  double diameter_ratio = 1.0;  // right / left
  double noise_rad = 0.0;

  double left_m = 0.0;  // the counters (encoder travel at the nominal diameter)
  double right_m = 0.0;
  double true_yaw = 0.0;
  double odometry_yaw = 0.0;
  double estimate_yaw = 0.0;  // odometry composed on the last correction
  std::uint32_t rng = 12345;

  double noise() {
    rng = rng * 1664525U + 1013904223U;
    return noise_rad * (static_cast<double>(rng >> 8) / 8388608.0 - 1.0);  // uniform ±noise
  }
  // Counters by (u, s); the odometry and the truth follow.
  void wheels(double u, double s) {
    const double dl = s - 0.5 * u;
    const double dr = s + 0.5 * u;
    left_m += dl;
    right_m += dr;
    const double odo = (dr - dl) / nominal_track_m;
    const double kl = 2.0 / (1.0 + diameter_ratio);
    const double kr = 2.0 * diameter_ratio / (1.0 + diameter_ratio);
    true_yaw += (dr * kr - dl * kl) / true_track_m;
    odometry_yaw += odo;
    estimate_yaw += odo;
  }
  // A move: turn in place by `turn_rad` (by the odometry), then `d_m` straight.
  void move(BaseCalibrator& c, double turn_rad, double d_m) {
    const double before = estimate_yaw;
    wheels(turn_rad * nominal_track_m, 0.0);
    wheels(0.0, d_m);
    c.moved(static_cast<float>(std::remainder(estimate_yaw - before, 2.0 * kPi)), true, left_m,
            right_m);
  }
  void register_look(BaseCalibrator& c) {
    const double residual = std::remainder(true_yaw + noise() - estimate_yaw, 2.0 * kPi);
    const double correction = 0.5 * residual;
    c.registered(true, left_m, right_m, static_cast<float>(residual),
                 static_cast<float>(correction));
    estimate_yaw += correction;
  }
};

// Turns of varied size and side and steps forward and back, a registration after each move.
void drive_a_mission(Base& b, BaseCalibrator& c, int looks) {
  b.register_look(c);
  for (int i = 0; i < looks; ++i) {
    const double turn = (i % 3 == 0 ? 2.5 : 0.9) * (i % 2 == 0 ? 1.0 : -1.0);
    const double d = i % 4 == 3 ? -0.3 : 0.6 + 0.1 * (i % 3);
    b.move(c, turn, d);
    b.register_look(c);
  }
}

}  // namespace

TEST_GROUP(BaseCalibrator) {
  BaseCalibrator calibrator;
  Base base;

  // The estimate after `looks` moves of a base with this true track and diameter ratio.
  BaseCalibration estimate_of(double track_m, double ratio, int looks, double noise_rad = 0.0) {
    base.true_track_m = track_m;
    base.diameter_ratio = ratio;
    base.noise_rad = noise_rad;
    drive_a_mission(base, calibrator, looks);
    const BaseCalibration e = calibrator.estimate();
    CHECK_TRUE(e.valid);
    return e;
  }
};

TEST(BaseCalibrator, AnExactBaseIsEstimatedExactlyFromNoiselessRegistrations) {
  const BaseCalibration e = estimate_of(0.404, 1.005, 12);
  LONGS_EQUAL(12, e.intervals);
  DOUBLES_EQUAL(17.2, e.turned_rad, 1e-4);  // 4 × 2.5 + 8 × 0.9
  DOUBLES_EQUAL(7.2, e.driven_m, 1e-4);     // backward steps counted by their length
  DOUBLES_EQUAL(0.404, e.track_m, 1e-5);
  DOUBLES_EQUAL(1.005, e.diameter_ratio, 1e-5);
  DOUBLES_EQUAL(0.0, e.track_sd_m, 1e-4);
}

TEST(BaseCalibrator, ATrackTooShortAndWheelsTheOtherWayAreEstimatedToo) {
  const BaseCalibration e = estimate_of(0.392, 0.99, 10);
  DOUBLES_EQUAL(0.392, e.track_m, 1e-5);
  DOUBLES_EQUAL(0.99, e.diameter_ratio, 1e-5);
}

TEST(BaseCalibrator, NoisyRegistrationsGiveAnEstimateWithinItsStandardErrors) {
  const BaseCalibration e = estimate_of(0.404, 1.005, 40, 0.05);  // ±2.9°, as registrations err
  CHECK(e.track_sd_m > 0.0F && e.track_sd_m < 0.004F);
  CHECK(e.diameter_ratio_sd > 0.0F && e.diameter_ratio_sd < 0.02F);
  CHECK(std::fabs(e.track_m - 0.404F) < 3.0F * e.track_sd_m);
  CHECK(std::fabs(e.diameter_ratio - 1.005F) < 3.0F * e.diameter_ratio_sd);
}

TEST(BaseCalibrator, AHalfTurnWrappedToTheWrongSideIsTakenTheWayTheWheelsTurned) {
  base.true_track_m = 0.404;
  base.register_look(calibrator);
  for (int i = 0; i < 6; ++i) {
    // Exactly half a turn each way: the wrapped change reads −π for a left turn of π too.
    base.wheels(kPi * base.nominal_track_m, 0.0);
    base.wheels(0.0, 0.5);
    calibrator.moved(static_cast<float>(-kPi), true, base.left_m, base.right_m);
    base.register_look(calibrator);
  }
  // Add straight driving so the two unknowns are told apart.
  drive_a_mission(base, calibrator, 4);
  const BaseCalibration e = calibrator.estimate();
  CHECK_TRUE(e.valid);
  DOUBLES_EQUAL(0.404, e.track_m, 1e-4);
}

TEST(BaseCalibrator, NothingIsEstimatedBeforeEnoughTurningAndDriving) {
  base.true_track_m = 0.404;
  base.register_look(calibrator);
  for (int i = 0; i < 3; ++i) {
    base.move(calibrator, 1.0, 0.5);
    base.register_look(calibrator);
  }
  BaseCalibration e = calibrator.estimate();
  CHECK_FALSE(e.valid);
  LONGS_EQUAL(3, e.intervals);
  DOUBLES_EQUAL(3.0, e.turned_rad, 1e-3);
  DOUBLES_EQUAL(1.5, e.driven_m, 1e-3);
  // Four intervals, 4 rad: still short of a whole turn.
  base.move(calibrator, 1.0, 0.5);
  base.register_look(calibrator);
  CHECK_FALSE(calibrator.estimate().valid);
  base.move(calibrator, 2.5, 0.5);
  base.register_look(calibrator);
  e = calibrator.estimate();
  CHECK_TRUE(e.valid);
  DOUBLES_EQUAL(0.404, e.track_m, 1e-5);
}

TEST(BaseCalibrator, AnIntervalWhoseWheelsMovedWithoutAReportedMoveIsLeftOut) {
  base.true_track_m = 0.404;
  drive_a_mission(base, calibrator, 6);
  LONGS_EQUAL(6, calibrator.estimate().intervals);
  // A step cut short by a hold: the wheels turned, no move was reported.
  base.wheels(0.3, 0.2);
  base.register_look(calibrator);
  LONGS_EQUAL(6, calibrator.estimate().intervals);
  // The next interval counts again, and the estimate is still exact.
  base.move(calibrator, 1.0, 0.5);
  base.register_look(calibrator);
  const BaseCalibration e = calibrator.estimate();
  LONGS_EQUAL(7, e.intervals);
  DOUBLES_EQUAL(0.404, e.track_m, 1e-5);
}

TEST(BaseCalibrator, ARestartDropsTheIntervalUnderWayAndUnknownCountersDropTheirs) {
  base.true_track_m = 0.404;
  drive_a_mission(base, calibrator, 5);
  base.move(calibrator, 1.0, 0.5);
  calibrator.restart();  // a resumed mission: the interval under way is not used
  base.register_look(calibrator);
  LONGS_EQUAL(5, calibrator.estimate().intervals);
  base.move(calibrator, 1.0, 0.5);
  calibrator.registered(false, 0.0, 0.0, 0.0F, 0.0F);  // counters unknown
  base.register_look(calibrator);
  LONGS_EQUAL(5, calibrator.estimate().intervals);
  base.move(calibrator, 1.0, 0.5);
  base.register_look(calibrator);
  LONGS_EQUAL(6, calibrator.estimate().intervals);
  calibrator.clear();
  LONGS_EQUAL(0, calibrator.estimate().intervals);
}
