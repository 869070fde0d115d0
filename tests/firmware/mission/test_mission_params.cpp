// Tests of the mission's parameters from the board: the look's rows and its scan views.
#include "firmware/mission/params/mission_params.h"

#include "CppUTest/TestHarness.h"

using namespace boticelli::firmware;
using namespace boticelli::firmware::mission;

TEST_GROUP(MissionParams) {
  BoardConfig config;
  boticelli::hal::PanTiltLimits limits{};
  void setup() override {
    config.look_pan_positions = 5;
    config.look_tilt_rows = 3;
    config.look_tilt_rad = {0.0F, -0.5F, -0.9F, 0.0F};
    config.look_tilt_is_pair = {true, true, false, false};
    limits.pan_min_rad = -2.0F;
    limits.pan_max_rad = 2.0F;
    limits.tilt_min_rad = -0.8F;
    limits.tilt_max_rad = 0.5F;
  }
};

TEST(MissionParams, TheLookRowsComeLowestTiltFirst) {
  const MissionParams p = make_mission_params(config);
  CHECK_EQUAL(3U, p.row_count);
  DOUBLES_EQUAL(-0.9, p.rows[0].tilt_rad, 1e-6);
  CHECK_FALSE(p.rows[0].pair);
  DOUBLES_EQUAL(-0.5, p.rows[1].tilt_rad, 1e-6);
  DOUBLES_EQUAL(0.0, p.rows[2].tilt_rad, 1e-6);
}

TEST(MissionParams, ScanViewsSweepThePanRangeAndBackOnEveryOtherRow) {
  const MissionParams p = make_mission_params(config);
  // Row 0 (a single frame at -0.9, clamped to the limit), left to right.
  LookView v = scan_view(p, limits, 0);
  DOUBLES_EQUAL(-2.0, v.pan_rad, 1e-6);
  DOUBLES_EQUAL(-0.8, v.tilt_rad, 1e-6);
  CHECK_FALSE(v.pair);
  DOUBLES_EQUAL(2.0, scan_view(p, limits, 4).pan_rad, 1e-6);
  // Row 1 (the pair at -0.5) comes back right to left.
  v = scan_view(p, limits, 5);
  DOUBLES_EQUAL(2.0, v.pan_rad, 1e-6);
  DOUBLES_EQUAL(-0.5, v.tilt_rad, 1e-6);
  CHECK_TRUE(v.pair);
  DOUBLES_EQUAL(0.0, scan_view(p, limits, 7).pan_rad, 1e-6);
  DOUBLES_EQUAL(-2.0, scan_view(p, limits, 9).pan_rad, 1e-6);
  // Row 2 left to right again.
  DOUBLES_EQUAL(-2.0, scan_view(p, limits, 10).pan_rad, 1e-6);
}

TEST(MissionParams, APairLowerThanTheTiltLimitAllowsLeavesRoomForItsSecondFrame) {
  config.look_tilt_is_pair = {true, true, true, false};
  const MissionParams p = make_mission_params(config);
  const LookView v = scan_view(p, limits, 0);
  CHECK_TRUE(v.pair);
  DOUBLES_EQUAL(-0.8 + static_cast<double>(p.rig.tilt_step_rad), v.tilt_rad, 1e-6);
}
