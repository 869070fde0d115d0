// Tests of the LookScan against a mock PTU: move, settle, grab, hand over; a pair's two tilts;
// the aimed pair last; the PTU's and the camera's faults; a hold and its resume.
#include <array>
#include <cmath>
#include <cstdint>

#include "firmware/mission/look/look_scan.h"
#include "firmware/mission/params/mission_params.h"
#include "hal/camera.h"
#include "hal/pan_tilt.h"
#include "hal_mocks.h"

#include "CppUTest/TestHarness.h"
#include "CppUTestExt/MockSupport.h"

using namespace boticelli::firmware::mission;
namespace hal = boticelli::hal;
namespace mocks = boticelli::mocks;

TEST_GROUP(LookScan) {
  MissionParams params;
  mocks::MockPanTilt ptu;
  LookScan scan{params};
  std::uint64_t now = 0;
  std::array<std::uint8_t, 16 * 8 * 2> pixels{};  // 16 x 8 YUYV, mid grey
  hal::Frame frame;
  float phi = 0.0F;

  void setup() override {
    // One row of single frames at -0.2 rad; the PTU pans over ±1 rad.
    params.pan_positions = 1;
    params.row_count = 1;
    params.rows[0] = {-0.2F, false};
    phi = params.rig.tilt_step_rad;
    hal::PanTiltLimits limits;
    limits.pan_min_rad = -1.0F;
    limits.pan_max_rad = 1.0F;
    limits.tilt_min_rad = -0.6F;
    limits.tilt_max_rad = 0.5F;
    ptu.set_limits(limits);
    pixels.fill(128);
    frame.data = pixels.data();
    frame.width_px = 16;
    frame.height_px = 8;
    frame.stride_bytes = 32;
    mock().ignoreOtherCalls();  // state() and limits() return what was set
  }

  ScanEvent control() {
    return scan.control(now, ptu);
  }
  void expect_move(float pan_rad, float tilt_rad) {
    mock()
        .expectOneCall("PanTilt.move_to")
        .onObject(&ptu)
        .withParameter("pan_rad", static_cast<double>(pan_rad))
        .withParameter("tilt_rad", static_cast<double>(tilt_rad));
  }
  // The PTU reports the move done (or still under way) at these angles.
  void ptu_at(float pan_rad, float tilt_rad, bool moving = false) {
    hal::PanTiltState s;
    s.pan_rad = pan_rad;
    s.tilt_rad = tilt_rad;
    s.moving = moving;
    ptu.set_state(s);
  }
  void deliver(std::uint64_t timestamp_us) {
    frame.timestamp_us = timestamp_us;
    scan.on_frame(frame);
  }
  // The move to (pan, tilt), the PTU there, its settling, and a frame after it.
  void move_settle_grab(float pan_rad, float tilt_rad) {
    expect_move(pan_rad, tilt_rad);
    CHECK(control() == ScanEvent::kBusy);
    mock().checkExpectations();
    ptu_at(pan_rad, tilt_rad);
    now += 1000;
    CHECK(control() == ScanEvent::kBusy);  // at rest: the settle time starts
    now += params.settle_us;
    CHECK(control() == ScanEvent::kBusy);  // settled: frames wanted
    CHECK_TRUE(scan.wants_frames());
    deliver(now);
    now += 1000;
    CHECK(control() == ScanEvent::kBusy);  // the frame kept
    CHECK_FALSE(scan.wants_frames());
  }
  // A pair's first tilt reached from below: the move above it, the PTU there at rest.
  void approach(float pan_rad, float above_rad) {
    expect_move(pan_rad, above_rad);
    CHECK(control() == ScanEvent::kBusy);
    mock().checkExpectations();
    ptu_at(pan_rad, above_rad, true);
    now += 1000;
    CHECK(control() == ScanEvent::kBusy);  // still moving
    ptu_at(pan_rad, above_rad);
    now += 1000;
    CHECK(control() == ScanEvent::kBusy);  // there: on to the view's tilt
    CHECK_FALSE(scan.wants_frames());
  }
  // The background is done with the view; the scan goes on to the next one.
  void next_view() {
    scan.view_processed();
    CHECK(control() == ScanEvent::kBusy);
  }
};

TEST(LookScan, AViewIsMovedToSettledAndGrabbedWithAFrameFromAfterTheSettleTime) {
  scan.begin(now, {});
  CHECK_EQUAL(1U, scan.view_count());
  expect_move(0.0F, -0.2F);  // one pan position: the middle of the pan range
  CHECK(control() == ScanEvent::kBusy);
  mock().checkExpectations();
  CHECK_FALSE(scan.wants_frames());
  ptu_at(0.0F, -0.2F);
  now = 1000;
  CHECK(control() == ScanEvent::kBusy);  // at rest: settles until 1000 + settle_us
  now = 1000 + params.settle_us / 2;
  CHECK(control() == ScanEvent::kBusy);
  CHECK_FALSE(scan.wants_frames());
  now = 1000 + params.settle_us;
  CHECK(control() == ScanEvent::kBusy);
  CHECK_TRUE(scan.wants_frames());
  // A frame exposed while the camera still swung is not kept.
  deliver(1000 + params.settle_us - 1);
  now += 1000;
  CHECK(control() == ScanEvent::kBusy);
  CHECK_FALSE(scan.view_ready());
  CHECK_TRUE(scan.wants_frames());
  deliver(1000 + params.settle_us + 500);
  now += 1000;
  CHECK(control() == ScanEvent::kBusy);
  CHECK_TRUE(scan.view_ready());
  CHECK_FALSE(scan.wants_frames());
  const GrabbedView v = scan.view();
  CHECK_FALSE(v.pair);
  CHECK_FALSE(v.aimed);
  CHECK_EQUAL(0U, v.index);
  DOUBLES_EQUAL(0.0, v.pose.pan_rad, 1e-6);
  DOUBLES_EQUAL(-0.2, v.pose.first_tilt_rad, 1e-6);
  CHECK_EQUAL(16U / params.rig.downsample_factor, v.first.width);
  // The view waits for the background; then the look ends with the camera parked level.
  now += 1000;
  CHECK(control() == ScanEvent::kBusy);
  CHECK_TRUE(scan.view_ready());
  scan.view_processed();
  expect_move(0.0F, 0.0F);
  CHECK(control() == ScanEvent::kDone);
}

TEST(LookScan, APairGrabsItsFirstFrameAtTheRowsTiltAndItsSecondAtTheTiltLessPhi) {
  params.rows[0] = {-0.2F, true};
  scan.begin(now, {});
  move_settle_grab(0.0F, -0.2F);
  CHECK_FALSE(scan.view_ready());  // the second frame is still to come
  move_settle_grab(0.0F, -0.2F - phi);
  CHECK_TRUE(scan.view_ready());
  const GrabbedView v = scan.view();
  CHECK_TRUE(v.pair);
  DOUBLES_EQUAL(-0.2, v.pose.first_tilt_rad, 1e-6);
  DOUBLES_EQUAL(-0.2 - static_cast<double>(phi), v.pose.second_tilt_rad, 1e-6);
  CHECK_EQUAL(4U, v.second.width);
}

TEST(LookScan, TheScansViewsComeInTurnAndTheAimedPairComesLast) {
  params.pan_positions = 2;
  AimedPair aimed;
  aimed.aimed = true;
  aimed.pan_rad = 0.4F;
  aimed.tilt_rad = 0.1F;
  scan.begin(now, aimed);
  CHECK_EQUAL(2U, scan.scan_views());
  CHECK_EQUAL(3U, scan.view_count());
  move_settle_grab(-1.0F, -0.2F);
  CHECK_TRUE(scan.view_ready());
  CHECK_EQUAL(0U, scan.view().index);
  CHECK_FALSE(scan.view().aimed);
  next_view();
  move_settle_grab(1.0F, -0.2F);
  CHECK_TRUE(scan.view_ready());
  CHECK_EQUAL(1U, scan.view().index);
  CHECK_FALSE(scan.view().aimed);
  next_view();
  // The aimed view is a pair, at the aimed angles, its first tilt reached from above.
  approach(0.4F, 0.1F + params.ptu_approach_rad);
  move_settle_grab(0.4F, 0.1F);
  CHECK_FALSE(scan.view_ready());
  move_settle_grab(0.4F, 0.1F - phi);
  CHECK_TRUE(scan.view_ready());
  const GrabbedView v = scan.view();
  CHECK_EQUAL(2U, v.index);
  CHECK_TRUE(v.aimed);
  CHECK_TRUE(v.pair);
  DOUBLES_EQUAL(0.4, v.pose.pan_rad, 1e-6);
  scan.view_processed();
  expect_move(0.0F, 0.0F);
  CHECK(control() == ScanEvent::kDone);
}

TEST(LookScan, AGlanceIsTheAimedPairAloneAndWithoutOneAWholeLook) {
  params.pan_positions = 2;
  AimedPair aimed;
  aimed.aimed = true;
  aimed.pan_rad = -0.3F;
  aimed.tilt_rad = 0.05F;
  scan.begin(now, aimed, true);
  approach(-0.3F, 0.05F + params.ptu_approach_rad);  // from level, up to the pair
  move_settle_grab(-0.3F, 0.05F);
  move_settle_grab(-0.3F, 0.05F - phi);
  CHECK_TRUE(scan.view_ready());
  CHECK_TRUE(scan.view().aimed);
  CHECK_EQUAL(2U, scan.view().index);
  scan.view_processed();
  expect_move(0.0F, 0.0F);
  CHECK(control() == ScanEvent::kDone);
  mock().checkExpectations();
  // Nothing to aim at: the glance is a whole look, from its first view.
  scan.begin(now, AimedPair{}, true);
  move_settle_grab(-1.0F, -0.2F);
  CHECK_EQUAL(0U, scan.view().index);
}

TEST(LookScan, AMoveThatNeverCompletesIsAPtuTimeout) {
  scan.begin(now, {});
  expect_move(0.0F, -0.2F);
  CHECK(control() == ScanEvent::kBusy);
  ptu_at(0.3F, -0.1F, true);  // under way, and staying so
  now = params.ptu_timeout_us;
  CHECK(control() == ScanEvent::kBusy);
  now = params.ptu_timeout_us + 1;
  CHECK(control() == ScanEvent::kPtuTimeout);
}

TEST(LookScan, NoFrameWithinTheFrameTimeoutIsNoFrame) {
  scan.begin(now, {});
  expect_move(0.0F, -0.2F);
  CHECK(control() == ScanEvent::kBusy);
  ptu_at(0.0F, -0.2F);
  CHECK(control() == ScanEvent::kBusy);
  now = params.settle_us;
  CHECK(control() == ScanEvent::kBusy);
  CHECK_TRUE(scan.wants_frames());
  now += params.frame_timeout_us;
  CHECK(control() == ScanEvent::kBusy);
  now += 1;
  CHECK(control() == ScanEvent::kNoFrame);
}

TEST(LookScan, ARefusedMoveAndAFaultedPtuAreReportedAsSuch) {
  scan.begin(now, {});
  mock()
      .expectOneCall("PanTilt.move_to")
      .onObject(&ptu)
      .withParameter("pan_rad", 0.0)
      .withParameter("tilt_rad", -0.2)
      .andReturnValue(false);
  CHECK(control() == ScanEvent::kPtuRefused);
  hal::PanTiltState s;
  s.fault = true;
  ptu.set_state(s);
  CHECK(control() == ScanEvent::kPtuFault);
}

TEST(LookScan, ResumeAfterAHoldIssuesTheInterruptedMoveAgainAndWaitsForIt) {
  scan.begin(now, {});
  expect_move(0.0F, -0.2F);
  CHECK(control() == ScanEvent::kBusy);
  ptu_at(0.0F, -0.1F, true);
  now += 1000;
  CHECK(control() == ScanEvent::kBusy);
  // A hold: the PTU was halted on the way. Carrying on, the move is issued once more.
  scan.stop_frames();
  scan.resume();
  expect_move(0.0F, -0.2F);
  now += 1000;
  CHECK(control() == ScanEvent::kBusy);
  mock().checkExpectations();
  ptu_at(0.0F, -0.2F);
  now += 1000;
  CHECK(control() == ScanEvent::kBusy);
  now += params.settle_us;
  CHECK(control() == ScanEvent::kBusy);
  CHECK_TRUE(scan.wants_frames());
  // A hold while frames are wanted: none is kept until the camera is settled again.
  scan.stop_frames();
  CHECK_FALSE(scan.wants_frames());
  deliver(now);
  scan.resume();
  move_settle_grab(0.0F, -0.2F);
  CHECK_TRUE(scan.view_ready());
}

TEST(LookScan, ResumeWhileTheBackgroundHasTheViewMovesNothing) {
  scan.begin(now, {});
  move_settle_grab(0.0F, -0.2F);
  CHECK_TRUE(scan.view_ready());
  scan.stop_frames();
  scan.resume();
  now += 1000;
  CHECK(control() == ScanEvent::kBusy);  // no move: CppUMock fails on an unexpected one
  CHECK_TRUE(scan.view_ready());
  scan.view_processed();
  expect_move(0.0F, 0.0F);
  CHECK(control() == ScanEvent::kDone);
}

// Gear play: both frames of a pair must take up the PTU's backlash on the same side, so a
// pair's first tilt is reached moving down, as its second is. From below (or from the same
// tilt) the PTU goes above it first; from above it goes straight there; a single frame needs
// neither.
TEST(LookScan, APairsFirstTiltIsReachedMovingDownAsItsSecondIs) {
  params.pan_positions = 2;
  params.rows[0] = {-0.2F, true};
  ptu_at(0.0F, -0.5F);  // below the row
  scan.begin(now, {});
  approach(-1.0F, -0.2F + params.ptu_approach_rad);
  move_settle_grab(-1.0F, -0.2F);
  move_settle_grab(-1.0F, -0.2F - phi);
  next_view();
  // The second view's first tilt is above where the first view's second frame left the PTU.
  approach(1.0F, -0.2F + params.ptu_approach_rad);
  move_settle_grab(1.0F, -0.2F);
  move_settle_grab(1.0F, -0.2F - phi);
  scan.view_processed();
  expect_move(0.0F, 0.0F);
  CHECK(control() == ScanEvent::kDone);
  mock().checkExpectations();
  // From above: straight to the pair.
  ptu_at(0.0F, 0.3F);
  scan.begin(now, {});
  move_settle_grab(-1.0F, -0.2F);
  // A single frame: straight to it from below.
  params.rows[0] = {-0.2F, false};
  ptu_at(0.0F, -0.5F);
  scan.begin(now, {});
  move_settle_grab(-1.0F, -0.2F);
  // Without an approach: straight to the pair from below.
  params.rows[0] = {-0.2F, true};
  params.ptu_approach_rad = 0.0F;
  ptu_at(0.0F, -0.5F);
  scan.begin(now, {});
  move_settle_grab(-1.0F, -0.2F);
}

TEST(LookScan, TheApproachGoesAboveThePairWithinTheTiltLimitOrStraightThereFromAbove) {
  DOUBLES_EQUAL(-0.19, tilt_approach_rad(-0.5F, -0.2F, 0.01F, 0.5F), 1e-6);
  DOUBLES_EQUAL(-0.19, tilt_approach_rad(-0.2F, -0.2F, 0.01F, 0.5F), 1e-6);  // same tilt
  DOUBLES_EQUAL(-0.2, tilt_approach_rad(-0.1F, -0.2F, 0.01F, 0.5F), 1e-6);   // from above
  DOUBLES_EQUAL(0.5, tilt_approach_rad(0.0F, 0.495F, 0.01F, 0.5F), 1e-6);    // at the limit
  DOUBLES_EQUAL(0.5, tilt_approach_rad(0.0F, 0.5F, 0.01F, 0.5F), 1e-6);
  DOUBLES_EQUAL(-0.2, tilt_approach_rad(-0.5F, -0.2F, 0.0F, 0.5F), 1e-6);  // none asked
}

// The aimed pair holds the target midway between its two tilts; a target below the tilt range
// (low and near) is aimed at the lowest first tilt whose second frame is still in range, one
// above it at the highest tilt; nothing is aimed beyond the range or outside the pan range.
TEST(LookScan, APairAimedAtATargetHoldsItMidwayBetweenItsTiltsWithinThePtusRange) {
  boticelli::hal::PanTiltLimits lim;
  lim.pan_min_rad = -2.0F;
  lim.pan_max_rad = 2.0F;
  lim.tilt_min_rad = -0.5F;
  lim.tilt_max_rad = 0.4F;
  const float step = 0.134F;
  const float h = 0.9F;  // the PTU's height
  AimedPair a =
      aim_pair_at({2.0F, 2.0F, h + 2.0F * std::sqrt(2.0F) * std::tan(0.1F)}, h, step, 5.0F, lim);
  CHECK(a.aimed);
  DOUBLES_EQUAL(std::atan2(2.0, 2.0), a.pan_rad, 1e-6);
  DOUBLES_EQUAL(0.1 + 0.5 * static_cast<double>(step), a.tilt_rad,
                1e-5);                                      // the target at 0.1 rad of elevation
  a = aim_pair_at({0.4F, 0.0F, 0.1F}, h, step, 5.0F, lim);  // 63° below: under the range
  CHECK(a.aimed);
  DOUBLES_EQUAL(lim.tilt_min_rad + step, a.tilt_rad, 1e-6);
  a = aim_pair_at({0.5F, 0.0F, h + 2.0F}, h, step, 5.0F, lim);  // far above
  DOUBLES_EQUAL(lim.tilt_max_rad, a.tilt_rad, 1e-6);
  CHECK_FALSE(aim_pair_at({5.5F, 0.0F, h}, h, step, 5.0F, lim).aimed);   // beyond the range
  CHECK_FALSE(aim_pair_at({-2.0F, 0.1F, h}, h, step, 5.0F, lim).aimed);  // behind: pan 3.09
  CHECK_FALSE(aim_pair_at({-2.0F, -0.1F, h}, h, step, 5.0F, lim).aimed);
}
