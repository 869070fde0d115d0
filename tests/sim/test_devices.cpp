// Tests of the simulated devices: PTU and base kinematics in simulated time, collisions,
// GPIO, lockstep clock, camera timing, watchdog, determinism.
#include <ctime>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <string>
#include <vector>

#include "algo/core/angles.h"
#include "algo/stereo/rig.h"
#include "hal/sim/base_sim.h"
#include "hal/sim/camera_sim.h"
#include "hal/sim/clock_sim.h"
#include "hal/sim/gpio_sim.h"
#include "hal/sim/pan_tilt_sim.h"
#include "hal/sim/renderer.h"
#include "hal/sim/sim_world.h"
#include "hal/sim/textures.h"
#include "hal/sim/watchdog_sim.h"
#include "sim_test_worlds.h"

#include "alloc_guard.h"
#include "CppUTest/TestHarness.h"

using namespace boticelli::hal::sim;
using boticelli::hal::BaseHealth;
using boticelli::hal::sim::test::world_path;

namespace {

World g_world;
TextureBank g_bank;
SimWorld g_sim;
char g_error[256];
const boticelli::stereo::RigModel g_rig;

void start(const char* name, const SimParams& params = {}) {
  const std::string path = world_path(name);
  CHECK_TEXT(load_world(path.c_str(), g_world, g_error, sizeof g_error), g_error);
  CHECK_TEXT(g_sim.init(g_world, g_rig, params, g_error, sizeof g_error), g_error);
}

// Runs frames of `frame_us` until `until` is true or `max_s` of simulated time passed;
// returns the simulated time [s] at which `until` became true (or −1).
template <typename Until>
double run_until(ClockSim& clock, Until until, double max_s, std::uint64_t frame_us = 10000) {
  const std::uint64_t t0 = clock.now_us();
  while (clock.now_us() - t0 < static_cast<std::uint64_t>(max_s * 1e6)) {
    clock.sleep_until_us(clock.now_us() + frame_us);
    if (until()) return static_cast<double>(clock.now_us() - t0) * 1e-6;
  }
  return -1.0;
}

void make_ready(BaseSim& base, ClockSim& clock) {
  CHECK(base.init());
  CHECK(base.health() == BaseHealth::kStarting);
  clock.sleep_until_us(clock.now_us() + 60000);
  base.update();
  CHECK(base.health() == BaseHealth::kReady);
}

}  // namespace

TEST_GROUP(SimDevices){void setup() override{g_error[0] = '\0';
}
}
;

TEST(SimDevices, ThePtuReachesAQuantisedTargetInTheTrapezoidalMoveTime) {
  start("rectangular_room");
  PanTiltSim ptu(g_sim);
  ClockSim clock(g_sim);
  CHECK(ptu.init());
  CHECK_FALSE(ptu.move_to(0.5F, 0.0F));  // not ready before update()
  ptu.update();
  CHECK(ptu.set_speed(1.0F, 0.5F));
  CHECK(ptu.move_to(1.0F, -0.2F));
  CHECK(ptu.state().moving);
  const double t = run_until(
      clock, [&] { return !ptu.state().moving; }, 5.0, 1000);
  const double res = ptu.limits().pan_resolution_rad;
  const double pan = std::round(1.0 / res) * res;
  const double tilt = std::round(-0.2 / res) * res;
  // Trapezoid: d/v + v/a for each axis; the slower one decides (pan 1.25 s, tilt 0.525 s).
  DOUBLES_EQUAL(pan / 1.0 + 1.0 / 4.0, t, 0.005);
  DOUBLES_EQUAL(pan, ptu.state().pan_rad, 1e-6);
  DOUBLES_EQUAL(tilt, ptu.state().tilt_rad, 1e-6);
  // Halfway through a move it is halfway there (symmetric profile).
  CHECK(ptu.move_to(0.0F, -0.2F));
  clock.sleep_until_us(clock.now_us() + 625000);
  DOUBLES_EQUAL(pan / 2.0, g_sim.pan().position_rad, 0.01);
}

TEST(SimDevices, ThePtuRefusesOutOfLimitCommandsAndStaysPut) {
  start("rectangular_room");
  PanTiltSim ptu(g_sim);
  ptu.init();
  ptu.update();
  const auto l = ptu.limits();
  CHECK_FALSE(ptu.move_to(l.pan_max_rad + 0.01F, 0.0F));
  CHECK(std::strstr(ptu.error(), "pan") != nullptr);
  CHECK_FALSE(ptu.move_to(0.0F, l.tilt_min_rad - 0.01F));
  CHECK(std::strstr(ptu.error(), "tilt") != nullptr);
  CHECK_FALSE(ptu.move_to(std::nanf(""), 0.0F));
  CHECK_FALSE(ptu.state().moving);
  CHECK_FALSE(ptu.set_speed(100.0F, 1.0F));
  CHECK_FALSE(ptu.set_speed(0.0F, 1.0F));
  CHECK(ptu.move_to(l.pan_max_rad, l.tilt_max_rad));  // the limits themselves are allowed
  STRCMP_EQUAL("", ptu.error());
}

TEST(SimDevices, HaltingThePtuBrakesToAStopShortOfTheTarget) {
  start("rectangular_room");
  PanTiltSim ptu(g_sim);
  ClockSim clock(g_sim);
  ptu.init();
  ptu.update();
  CHECK(ptu.move_to(2.0F, 0.0F));
  clock.sleep_until_us(500000);
  ptu.halt();
  CHECK(run_until(
            clock, [&] { return !ptu.state().moving; }, 2.0) > 0.0);
  CHECK(ptu.state().pan_rad > 0.3F);
  CHECK(ptu.state().pan_rad < 1.0F);
}

TEST(SimDevices, TheBaseDrivesStraightAndTurnsByTheCommandedAmountInSimulatedTime) {
  start("rectangular_room");
  BaseSim base(g_sim);
  ClockSim clock(g_sim);
  base.set_velocity(0.2F, 0.0F);  // ignored while starting
  make_ready(base, clock);
  base.set_velocity(0.2F, 0.0F);
  clock.sleep_until_us(clock.now_us() + 3000000);
  // 3 s at 0.2 m/s minus the ramp (v² / 2a = 0.02 m at 1 m/s²).
  DOUBLES_EQUAL(0.58, g_sim.true_pose().x_m, 1e-3);
  DOUBLES_EQUAL(0.0, g_sim.true_pose().y_m, 1e-6);
  DOUBLES_EQUAL(0.58, base.odometry().x_m, 1e-3);
  DOUBLES_EQUAL(0.2, base.odometry().v_m_s, 1e-6);
  base.set_velocity(0.0F, 0.5F);
  clock.sleep_until_us(clock.now_us() + 2000000);
  // Wheels ramp from 0.2 m/s to ∓0.1 m/s at 1 m/s²: the right one in 0.1 s, the left in
  // 0.3 s, so ∫(v_r − v_l) dt = 0.02 + 0.2 · 1.7 = 0.36 m over a 0.4 m track: 0.9 rad.
  const double yaw = g_sim.true_pose().yaw_rad;
  DOUBLES_EQUAL(0.9, yaw, 2e-3);
  DOUBLES_EQUAL(yaw, base.odometry().yaw_rad, 1e-6);
  // Commands beyond the limits are clamped.
  base.set_velocity(5.0F, 0.0F);
  clock.sleep_until_us(clock.now_us() + 1000000);
  DOUBLES_EQUAL(0.3, base.odometry().v_m_s, 1e-6);
  CHECK_EQUAL(0U, g_sim.collisions());
}

TEST(SimDevices, AStopBrakesTheWheelsToRestWithinTheBrakingDistanceAndThenIdlesTheAxes) {
  start("rectangular_room");
  BaseSim base(g_sim);
  ClockSim clock(g_sim);
  make_ready(base, clock);
  base.set_velocity(0.3F, 0.0F);
  clock.sleep_until_us(clock.now_us() + 1000000);
  const double x0 = static_cast<double>(g_sim.true_pose().x_m);
  base.stop();
  CHECK(base.health() == BaseHealth::kStopped);  // commands nothing from now on
  CHECK_TRUE(g_sim.base_braking());
  const double t = run_until(
      clock, [&] { return g_sim.wheel_speed_m_s() == 0.0F; }, 2.0, 1000);
  // 0.3 m/s at the 1 m/s² brake: 0.3 s and v²/2a = 0.045 m.
  DOUBLES_EQUAL(0.3, t, 0.002);
  DOUBLES_EQUAL(0.045, static_cast<double>(g_sim.true_pose().x_m) - x0, 0.001);
  clock.sleep_until_us(clock.now_us() + 1000);
  CHECK_FALSE(g_sim.base_braking());
  CHECK_TRUE(g_sim.base_axes_idle());
  CHECK(base.resume());
  CHECK_FALSE(g_sim.base_axes_idle());
}

TEST(SimDevices, AnAxisFaultIdlesTheAxesAndTheWheelsCoastFartherThanABrakedStop) {
  start("rectangular_room");
  BaseSim base(g_sim);
  ClockSim clock(g_sim);
  make_ready(base, clock);
  base.set_velocity(0.3F, 0.0F);
  clock.sleep_until_us(clock.now_us() + 1000000);
  const double x0 = static_cast<double>(g_sim.true_pose().x_m);
  CHECK(g_sim.faults().inject(FaultDevice::kAxisLeft, FaultType::kOff, clock.now_us(), 0));
  base.update();
  CHECK(base.health() == BaseHealth::kStopped);
  CHECK_FALSE(g_sim.base_braking());
  CHECK_TRUE(g_sim.base_axes_idle());
  const double t = run_until(
      clock, [&] { return g_sim.wheel_speed_m_s() == 0.0F; }, 3.0, 1000);
  // Coasting on rolling friction (0.2 m/s²): 1.5 s and v²/2a = 0.225 m.
  DOUBLES_EQUAL(1.5, t, 0.002);
  DOUBLES_EQUAL(0.225, static_cast<double>(g_sim.true_pose().x_m) - x0, 0.001);
}

TEST(SimDevices, TheOdrivesWatchdogIdlesTheAxesAndTheWheelsCoast) {
  SimParams params;
  params.base.command_timeout_us = 200000;
  start("rectangular_room", params);
  BaseSim base(g_sim);
  ClockSim clock(g_sim);
  make_ready(base, clock);
  base.set_velocity(0.3F, 0.0F);
  for (int i = 0; i < 100; ++i) {
    clock.sleep_until_us(clock.now_us() + 10000);
    base.update();
  }
  const double x0 = static_cast<double>(g_sim.true_pose().x_m);
  // No setpoint from now on: 0.2 s at 0.3 m/s, then 0.225 m coasting.
  CHECK(run_until(
            clock, [&] { return g_sim.wheel_speed_m_s() == 0.0F; }, 3.0, 1000) > 0.0);
  STRCMP_CONTAINS("0x00000800", base.error());
  DOUBLES_EQUAL(0.06 + 0.225, static_cast<double>(g_sim.true_pose().x_m) - x0, 0.002);
}

TEST(SimDevices, ADelayedCanBusDeliversSetpointsAndEstimatesFiftyMillisecondsLate) {
  start("rectangular_room");
  BaseSim base(g_sim);
  ClockSim clock(g_sim);
  make_ready(base, clock);
  clock.sleep_until_us(clock.now_us() + 200000);
  const std::uint64_t before = base.odometry().timestamp_us;
  CHECK(g_sim.faults().inject(FaultDevice::kCan, FaultType::kDelayed, clock.now_us(), 0));
  CHECK(base.odometry().timestamp_us >= before);  // a late estimate does not go back in time
  base.set_velocity(0.2F, 0.0F);
  clock.sleep_until_us(clock.now_us() + 45000);
  CHECK_EQUAL(0.0F, g_sim.wheel_speed_m_s());  // the setpoint is still on the bus
  clock.sleep_until_us(clock.now_us() + 10000);
  CHECK(g_sim.wheel_speed_m_s() > 0.0F);
  clock.sleep_until_us(clock.now_us() + 1000000);
  const std::uint64_t now = clock.now_us();
  CHECK(base.odometry().timestamp_us <= now - 50000U);
  CHECK(base.odometry().timestamp_us >= now - 51000U);
  DOUBLES_EQUAL(0.2, base.odometry().v_m_s, 1e-6);
  CHECK(base.health() == BaseHealth::kReady);
}

TEST(SimDevices, DrivingIntoThePartitionStopsTheBaseCountsOneCollisionAndClosesTheBumper) {
  start("thesis_room");
  BaseSim base(g_sim);
  ClockSim clock(g_sim);
  BumperInputSim bumper(g_sim);
  make_ready(base, clock);
  CHECK_FALSE(bumper.read());
  CHECK_FALSE(bumper.activated_since_last_poll());
  base.set_velocity(0.3F, 0.0F);  // start faces +y, the partition's face is at y = 0.55
  CHECK(run_until(
            clock, [&] { return g_sim.collisions() > 0; }, 12.0) > 0.0);
  UNSIGNED_LONGS_EQUAL(1, g_sim.collisions());
  CHECK(base.health() == BaseHealth::kStopped);
  STRCMP_CONTAINS("partition", base.error());
  DOUBLES_EQUAL(0.55 - 0.25, g_sim.true_pose().y_m, 2e-3);
  CHECK(bumper.read());
  CHECK(bumper.activated_since_last_poll());
  CHECK_FALSE(bumper.activated_since_last_poll());
  // Stopped means stopped: commands are ignored until resume().
  base.set_velocity(0.3F, 0.0F);
  clock.sleep_until_us(clock.now_us() + 500000);
  UNSIGNED_LONGS_EQUAL(1, g_sim.collisions());
  // Resume and back off: the bumper opens; drive in again: a second collision.
  CHECK(base.resume());
  base.set_velocity(-0.1F, 0.0F);
  clock.sleep_until_us(clock.now_us() + 1000000);
  CHECK_FALSE(bumper.read());
  base.set_velocity(0.2F, 0.0F);
  CHECK(run_until(
            clock, [&] { return g_sim.collisions() > 1; }, 5.0) > 0.0);
  UNSIGNED_LONGS_EQUAL(2, g_sim.collisions());
}

TEST(SimDevices, ARotatedBoxIsHitAtItsTrueOutline) {
  start("thesis_room");
  BaseSim base(g_sim);
  ClockSim clock(g_sim);
  // box_b: 0.4 x 0.4 m at (−0.2, −0.6), turned by −0.2 rad. Approach along x at y = −0.6.
  CHECK(g_sim.teleport({-1.4F, -0.6F, 0.0F}));
  make_ready(base, clock);
  base.set_velocity(0.2F, 0.0F);
  CHECK(run_until(
            clock, [&] { return g_sim.collisions() > 0; }, 10.0) > 0.0);
  STRCMP_EQUAL("box_b", g_sim.last_collision_model());
  // The −x face of the turned box crosses y = −0.6 at x = −0.2 − 0.2 / cos(0.2).
  const double face_x = -0.2 - 0.2 / std::cos(0.2);
  // Moving along x onto a face turned by 0.2 rad, the centre stops r / cos(0.2) short of it.
  const double gap = face_x - static_cast<double>(g_sim.true_pose().x_m);
  DOUBLES_EQUAL(0.25 / std::cos(0.2), gap, 2e-3);
  CHECK(g_sim.clearance_m(g_sim.true_pose().x_m, g_sim.true_pose().y_m) >= 0.0F);
}

TEST(SimDevices, CirclingInFreeSpaceNeverCollides) {
  start("rectangular_room");
  BaseSim base(g_sim);
  ClockSim clock(g_sim);
  BumperInputSim bumper(g_sim);
  make_ready(base, clock);
  base.set_velocity(0.25F, 0.4F);  // a 0.625 m circle about (0, 0.625) in the 5 x 5 m room
  bool touched = false;
  run_until(
      clock,
      [&] {
        touched = touched || bumper.read();
        return false;
      },
      60.0);
  UNSIGNED_LONGS_EQUAL(0, g_sim.collisions());
  CHECK_FALSE(touched);
  CHECK(base.health() == BaseHealth::kReady);
  // Odometry without noise is the true motion expressed from the start pose.
  const auto truth = g_sim.true_pose();
  DOUBLES_EQUAL(truth.x_m - g_world.start.x_m, base.odometry().x_m, 1e-4);
  DOUBLES_EQUAL(truth.y_m - g_world.start.y_m, base.odometry().y_m, 1e-4);
}

TEST(SimDevices, ObstaclesAboveTheRobotOrFlatOnTheFloorAreNotHit) {
  start("two_rooms_doorway");
  // The lintel over the doorway is at 1.8–2.0 m, above the 0.8 m robot.
  CHECK(g_sim.teleport({0.0F, 0.0F, 0.0F}));
  CHECK(g_sim.clearance_m(0.0, 0.0) > 0.1F);
  start("cluttered_room");
  // A cable 1 cm high lies around (0, −2): driven over.
  CHECK(g_sim.clearance_m(0.0, -2.0) > 0.0F);
}

TEST(SimDevices, ALowBoxAndAPillarAreHitAtTheirOutlines) {
  start("cluttered_room");
  const double r = static_cast<double>(SimParams{}.base.robot_radius_m);
  // box_3: 0.4 x 0.6 m, 0.3 m high (below the camera, above the floor clearance), at
  // (1.9, 1.6): its −x face is at x = 1.7.
  DOUBLES_EQUAL(0.2 - r, g_sim.clearance_m(1.5, 1.6), 1e-4);
  CHECK_FALSE(g_sim.teleport({1.5F, 1.6F, 0.0F}));  // the robot would stand in it
  CHECK(g_sim.teleport({1.4F, 1.6F, 0.0F}));
  // The pillar: a cylinder of radius 0.2 m at (−0.5, 1).
  DOUBLES_EQUAL(0.5 - 0.2 - r, g_sim.clearance_m(0.0, 1.0), 1e-4);
}

TEST(SimDevices, TheBumperClosesWithinItsMarginBeforeTheBodyHits) {
  start("thesis_room");
  BaseSim base(g_sim);
  ClockSim clock(g_sim);
  BumperInputSim bumper(g_sim);
  make_ready(base, clock);
  base.set_velocity(0.1F, 0.0F);  // slowly towards the partition (its face at y = 0.55)
  std::size_t collisions_at_contact = 99;
  CHECK(run_until(
            clock,
            [&] {
              if (!bumper.read()) return false;
              collisions_at_contact = g_sim.collisions();
              return true;
            },
            40.0, 1000) > 0.0);
  UNSIGNED_LONGS_EQUAL(0, collisions_at_contact);
  const float gap = g_sim.clearance_m(g_sim.true_pose().x_m, g_sim.true_pose().y_m);
  CHECK(gap >= 0.0F);
  CHECK(gap <= SimParams{}.base.contact_margin_m);
}

TEST(SimDevices, AScriptedEstopPressIsSeenOnceAndReleased) {
  start("rectangular_room");
  ClockSim clock(g_sim);
  EstopInputSim estop(g_sim);
  g_sim.schedule_estop(500000, 200000);
  clock.sleep_until_us(400000);
  CHECK_FALSE(estop.read());
  CHECK_FALSE(estop.activated_since_last_poll());
  clock.sleep_until_us(550000);
  CHECK(estop.read());
  CHECK(estop.activated_since_last_poll());
  CHECK_FALSE(estop.activated_since_last_poll());
  clock.sleep_until_us(800000);
  CHECK_FALSE(estop.read());
  // A press shorter than a frame between two polls is still reported.
  g_sim.schedule_estop(900000, 1000);
  clock.sleep_until_us(1000000);
  CHECK_FALSE(estop.read());
  CHECK(estop.activated_since_last_poll());
}

TEST(SimDevices, TheLedAndTheWatchdogStandInRecordWhatTheFirmwareDoes) {
  start("rectangular_room");
  ClockSim clock(g_sim);
  LedOutputSim led(g_sim);
  WatchdogSim dog(g_sim);
  led.write(true);
  led.write(true);
  led.write(false);
  UNSIGNED_LONGS_EQUAL(2, g_sim.led_changes());
  CHECK_FALSE(g_sim.led());
  CHECK(dog.start(100));
  clock.sleep_until_us(90000);
  dog.kick();
  clock.sleep_until_us(180000);
  UNSIGNED_LONGS_EQUAL(0, g_sim.watchdog_expirations());
  clock.sleep_until_us(400000);
  CHECK(g_sim.watchdog_expirations() >= 1);
  dog.stop();
  const auto n = g_sim.watchdog_expirations();
  clock.sleep_until_us(2000000);
  UNSIGNED_LONGS_EQUAL(n, g_sim.watchdog_expirations());
}

TEST(SimDevices, AWatchdogFaultRefusesKeepAlivesOrTheStartAsTheKernelWould) {
  start("rectangular_room");
  ClockSim clock(g_sim);
  WatchdogSim dog(g_sim);
  // Busy: another process holds the device while the fault lasts.
  CHECK(g_sim.faults().inject(FaultDevice::kWatchdog, FaultType::kStuck, 0, 100000));
  CHECK_FALSE(dog.start(100));
  STRCMP_CONTAINS("busy", dog.error());
  clock.sleep_until_us(150000);
  CHECK(dog.start(100));
  STRCMP_EQUAL("", dog.error());
  clock.sleep_until_us(200000);
  CHECK(dog.kick());
  // Keep-alives refused: they do not reach the stand-in, which expires as the board would
  // reset; once they are taken again it counts no more.
  CHECK(g_sim.faults().inject(FaultDevice::kWatchdog, FaultType::kOff, 200000, 300000));
  for (std::uint64_t t = 210000; t < 500000; t += 10000) {
    clock.sleep_until_us(t);
    CHECK_FALSE(dog.kick());
  }
  STRCMP_CONTAINS("keep-alive refused", dog.error());
  CHECK(g_sim.watchdog_expirations() >= 1);
  const auto n = g_sim.watchdog_expirations();
  for (std::uint64_t t = 500000; t < 900000; t += 10000) {
    clock.sleep_until_us(t);
    CHECK(dog.kick());
  }
  UNSIGNED_LONGS_EQUAL(n, g_sim.watchdog_expirations());
}

TEST(SimDevices, TheClockAdvancesOnlyWhenSleptAndExactlyToTheDeadline) {
  start("rectangular_room");
  ClockSim clock(g_sim);
  UNSIGNED_LONGS_EQUAL(0, clock.now_us());
  UNSIGNED_LONGS_EQUAL(0, clock.now_us());
  clock.sleep_until_us(12345);
  UNSIGNED_LONGS_EQUAL(12345, clock.now_us());
  clock.sleep_until_us(100);  // in the past: returns at once
  UNSIGNED_LONGS_EQUAL(12345, clock.now_us());
  CHECK_NO_ALLOCATION(clock.sleep_until_us(1000000));
}

TEST(SimDevices, TheCameraDeliversFramesAtItsRateFromTheCurrentPose) {
  start("thesis_room");
  CHECK_TEXT(g_bank.build(g_world, g_error, sizeof g_error), g_error);
  boticelli::stereo::CameraIntrinsics small;
  small.width_px = 160;
  small.height_px = 120;
  small.focal_px = 150.0F;
  small.principal_x_px = 79.5F;
  small.principal_y_px = 59.5F;
  Renderer renderer;
  RenderSettings settings;
  settings.noise_sigma_grey = 0.0F;  // so only the pose changes the image
  CHECK_TEXT(renderer.init(g_world, g_bank, small, settings, g_error, sizeof g_error), g_error);
  CameraSim camera(g_sim, renderer);
  ClockSim clock(g_sim);
  PanTiltSim ptu(g_sim);
  ptu.init();
  ptu.update();
  boticelli::hal::Frame frame;
  CHECK(camera.poll(frame) == boticelli::hal::CameraPoll::kFault);  // not set up
  CHECK(camera.setup(30.0F, g_error, sizeof g_error));
  CHECK(camera.init());
  camera.set_depth_enabled(true);
  UNSIGNED_LONGS_EQUAL(160, camera.width_px());
  // Rendering is the simulator's work: its CPU time is booked (the board's host clock leaves it
  // out of the firmware's figures); a poll without a new frame renders nothing.
  std::uint64_t booked_ns = g_sim.simulator_cpu_ns();
  const std::uint64_t booked_wall_ns = g_sim.simulator_wall_ns();
  CHECK(camera.poll(frame) == boticelli::hal::CameraPoll::kFrame);
  CHECK(g_sim.simulator_cpu_ns() > booked_ns);
  CHECK(g_sim.simulator_wall_ns() > booked_wall_ns);
  UNSIGNED_LONGS_EQUAL(0, frame.sequence);
  UNSIGNED_LONGS_EQUAL(320, frame.stride_bytes);
  std::vector<std::uint8_t> first(frame.data, frame.data + 320 * 120);
  camera.release();
  booked_ns = g_sim.simulator_cpu_ns();
  const std::uint64_t wall_before_ns = g_sim.simulator_wall_ns();
  CHECK(camera.poll(frame) == boticelli::hal::CameraPoll::kNoFrame);
  CHECK_EQUAL(booked_ns, g_sim.simulator_cpu_ns());
  CHECK_EQUAL(wall_before_ns, g_sim.simulator_wall_ns());
  clock.sleep_until_us(20000);
  CHECK(camera.poll(frame) == boticelli::hal::CameraPoll::kNoFrame);
  clock.sleep_until_us(33333);
  CHECK(camera.poll(frame) == boticelli::hal::CameraPoll::kFrame);
  UNSIGNED_LONGS_EQUAL(1, frame.sequence);
  UNSIGNED_LONGS_EQUAL(33333, frame.timestamp_us);
  // Pan away: the next frame sees another part of the room, and its depth is ground truth.
  CHECK(ptu.move_to(1.0F, 0.0F));
  clock.sleep_until_us(2000000);
  CHECK(camera.poll(frame) == boticelli::hal::CameraPoll::kFrame);
  UNSIGNED_LONGS_EQUAL(2, frame.sequence);  // frames in between were dropped
  std::size_t differing = 0;
  for (std::size_t i = 0; i < first.size(); i += 2)
    differing += first[i] != frame.data[i] ? 1U : 0U;
  CHECK(differing > first.size() / 4);
  std::size_t surface = 0;
  float d = 0.0F;
  CHECK(renderer.trace_pixel(camera.last_pose(), 40, 90, surface, d));
  DOUBLES_EQUAL(d, camera.depth_m()[90 * 160 + 40], 1e-5);
  clock.sleep_until_us(2040000);
  CHECK_NO_ALLOCATION(camera.poll(frame));
  // A new run sets the camera up again: the sequence (it picks each frame's noise) starts over,
  // so the same seed gives the same frames in the same process.
  CHECK(camera.setup(30.0F, g_error, sizeof g_error));
  CHECK(camera.init());
  CHECK(camera.poll(frame) == boticelli::hal::CameraPoll::kFrame);
  UNSIGNED_LONGS_EQUAL(0, frame.sequence);
}

TEST(SimDevices, AMissionLikeRunIsBitForBitRepeatableForASeed) {
  auto run = [](std::uint64_t seed, float noise) {
    SimParams params;
    params.seed = seed;
    params.base.odometry_noise = noise;
    start("cluttered_room", params);
    BaseSim base(g_sim);
    ClockSim clock(g_sim);
    PanTiltSim ptu(g_sim);
    ptu.init();
    ptu.update();
    make_ready(base, clock);
    for (int leg = 0; leg < 6; ++leg) {
      CHECK(ptu.move_to(0.4F * static_cast<float>(leg) - 1.0F, -0.1F));
      base.set_velocity(0.25F, leg % 2 == 0 ? 0.3F : -0.4F);
      clock.sleep_until_us(clock.now_us() + 1500000);
      if (base.health() == BaseHealth::kStopped) base.resume();
    }
    struct Result {
      boticelli::core::Pose2 truth;
      boticelli::hal::Odometry odo;
      float pan;
      std::uint32_t collisions;
    };
    return Result{g_sim.true_pose(), base.odometry(), g_sim.pan().position_rad, g_sim.collisions()};
  };
  const auto a = run(7, 0.02F);
  const auto b = run(7, 0.02F);
  const auto c = run(8, 0.02F);
  CHECK(std::memcmp(&a.truth, &b.truth, sizeof a.truth) == 0);
  CHECK(a.odo.x_m == b.odo.x_m && a.odo.y_m == b.odo.y_m && a.odo.yaw_rad == b.odo.yaw_rad);
  CHECK(a.pan == b.pan && a.collisions == b.collisions);
  CHECK(a.odo.x_m != c.odo.x_m);  // the odometry noise follows the seed
  CHECK(std::memcmp(&a.truth, &c.truth, sizeof a.truth) == 0);  // the truth does not
}

TEST(SimDevices, TheClockKeepsPaceWithWallTimeAtTheSpeedAskedAndRacesWithoutOne) {
  start("rectangular_room");
  ClockSim clock(g_sim);
  const auto wall_s = [] {
    timespec ts{};
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return static_cast<double>(ts.tv_sec) + static_cast<double>(ts.tv_nsec) * 1e-9;
  };
  // Default: 2 s of simulated time in 10 ms frames take a small fraction of that.
  double t0 = wall_s();
  std::uint64_t sim_us = clock.now_us();
  for (int i = 0; i < 200; ++i) clock.sleep_until_us(sim_us += 10000);
  CHECK(wall_s() - t0 < 1.0);
  // Speed 4: 0.8 s simulated take 0.2 s of wall time (the first frame sets the anchor).
  clock.set_speed(4.0);
  clock.sleep_until_us(sim_us += 10000);
  t0 = wall_s();
  for (int i = 0; i < 80; ++i) clock.sleep_until_us(sim_us += 10000);
  const double took_s = wall_s() - t0;
  DOUBLES_EQUAL(0.2, took_s, 0.05);
  CHECK_EQUAL(sim_us, clock.now_us());
}

TEST(SimDevices, TheClockReportsHowLateItWokeOnlyWhenItWaitedForTheWallClock) {
  start("rectangular_room");
  ClockSim clock(g_sim);
  CHECK_EQUAL(-1, clock.last_wake_latency_ns());
  std::uint64_t sim_us = clock.now_us();
  clock.sleep_until_us(sim_us += 10000);
  CHECK_EQUAL(-1, clock.last_wake_latency_ns());  // lockstep: no wall clock waited on
  clock.set_speed(10.0);
  clock.sleep_until_us(sim_us += 10000);
  CHECK_EQUAL(-1, clock.last_wake_latency_ns());  // the first paced sleep only anchors
  for (int i = 0; i < 5; ++i) {
    clock.sleep_until_us(sim_us += 10000);  // 1 ms of wall time each
    CHECK(clock.last_wake_latency_ns() >= 0);
  }
  clock.set_speed(0.0);
  clock.sleep_until_us(sim_us += 10000);
  CHECK_EQUAL(-1, clock.last_wake_latency_ns());
}

namespace {
// Commands (v, ω) for `us` of simulated time.
void drive_for(BaseSim& base, ClockSim& clock, float v_m_s, float omega_rad_s, std::uint64_t us) {
  base.set_velocity(v_m_s, omega_rad_s);
  clock.sleep_until_us(clock.now_us() + us);
}
// Stops the base and waits a second for the wheels to come to rest.
void stop_and_settle(BaseSim& base, ClockSim& clock) {
  drive_for(base, clock, 0.0F, 0.0F, 1000000);
}
}  // namespace

TEST(SimDevices, AWiderTrueTrackMakesTurnsShortAndUnequalWheelsBendAStraightDrive) {
  // Only the track 1 % wider than the odometry assumes: the base truly turns 1 % less.
  SimParams params;
  params.base.track_scale = 1.01F;
  start("rectangular_room", params);
  BaseSim base(g_sim);
  ClockSim clock(g_sim);
  make_ready(base, clock);
  const float yaw0 = g_sim.true_pose().yaw_rad;
  drive_for(base, clock, 0.0F, 0.5F, 2000000);
  stop_and_settle(base, clock);
  const double odo_turn = base.odometry().yaw_rad;
  const double true_turn = boticelli::core::wrap_pi(g_sim.true_pose().yaw_rad - yaw0);
  CHECK(odo_turn > 0.8);
  DOUBLES_EQUAL(odo_turn / 1.01, true_turn, 1e-4);
  // Only the wheels 0.5 % apart: a straight drive on the odometry bends the true path by
  // (right − left) / track per metre (−0.0125 rad/m here), the odometry's heading stays put.
  SimParams wheels;
  wheels.base.wheel_scale_left = 1.0025F;
  wheels.base.wheel_scale_right = 0.9975F;
  start("rectangular_room", wheels);
  BaseSim base2(g_sim);
  ClockSim clock2(g_sim);
  make_ready(base2, clock2);
  const float start_yaw = g_sim.true_pose().yaw_rad;
  drive_for(base2, clock2, 0.2F, 0.0F, 4000000);
  stop_and_settle(base2, clock2);
  const double driven_m = base2.odometry().x_m;
  DOUBLES_EQUAL(0.0, base2.odometry().yaw_rad, 1e-9);
  DOUBLES_EQUAL(-0.0125 * driven_m, boticelli::core::wrap_pi(g_sim.true_pose().yaw_rad - start_yaw),
                2e-4);
}

// The same errors with the odometry calibrated for them (E_b = 1.01, E_d = 0.9975/1.0025):
// a turn and a straight drive are where the odometry says, and the base turns at the rate
// commanded.
TEST(SimDevices, ACalibratedOdometryFollowsABaseWithAWiderTrackAndUnequalWheels) {
  SimParams params;
  params.base.track_scale = 1.01F;
  params.base.wheel_scale_left = 1.0025F;
  params.base.wheel_scale_right = 0.9975F;
  params.base.odometry_track_scale = 1.01F;
  params.base.odometry_left_scale = 1.0025F;
  params.base.odometry_right_scale = 0.9975F;
  start("rectangular_room", params);
  BaseSim base(g_sim);
  ClockSim clock(g_sim);
  make_ready(base, clock);
  const boticelli::core::Pose2 start_pose = g_sim.true_pose();
  drive_for(base, clock, 0.0F, 0.5F, 2000000);
  DOUBLES_EQUAL(0.5, base.odometry().omega_rad_s, 1e-4);
  drive_for(base, clock, 0.2F, 0.0F, 4000000);
  stop_and_settle(base, clock);
  const boticelli::hal::Odometry o = base.odometry();
  const boticelli::core::Pose2 moved =
      boticelli::core::compose(boticelli::core::inverse(start_pose), g_sim.true_pose());
  CHECK(o.yaw_rad > 0.9);
  CHECK(o.x_m * o.x_m + o.y_m * o.y_m > 0.5);
  DOUBLES_EQUAL(o.yaw_rad, moved.yaw_rad, 1e-4);
  DOUBLES_EQUAL(o.x_m, moved.x_m, 1e-3);
  DOUBLES_EQUAL(o.y_m, moved.y_m, 1e-3);
}

// Gear play: the camera trails the PTU's position by half the backlash, on the side each axis
// last moved from; the position the PTU reports stays the commanded one.
TEST(SimDevices, WithBacklashTheCameraTrailsEachAxisByHalfOfItOnTheSideItCameFrom) {
  SimParams params;
  params.ptu.backlash_rad = 0.002F;
  start("rectangular_room", params);
  PanTiltSim ptu(g_sim);
  ClockSim clock(g_sim);
  CHECK(ptu.init());
  ptu.update();
  const auto camera_at = [&](float pan, float tilt) {
    return g_sim.camera_pose(g_sim.true_pose(), pan, tilt);
  };
  const auto same = [](const RigidTransform& a, const RigidTransform& b) {
    return (a.rotation - b.rotation).norm() < 1e-6F &&
           (a.translation_m - b.translation_m).norm() < 1e-6F;
  };
  // Before any move: no play taken up either way.
  CHECK(same(camera_at(0.0F, 0.0F), g_sim.camera_pose()));
  const auto settle = [&](float pan, float tilt) {
    CHECK(ptu.move_to(pan, tilt));
    CHECK(run_until(
              clock, [&] { return !ptu.state().moving; }, 5.0, 1000) > 0.0);
  };
  settle(0.5F, -0.2F);  // pan up, tilt down
  const float pan = g_sim.pan().position_rad;
  const float tilt = g_sim.tilt().position_rad;
  CHECK(same(camera_at(pan - 0.001F, tilt + 0.001F), g_sim.camera_pose()));
  CHECK_FALSE(same(camera_at(pan, tilt), g_sim.camera_pose()));
  settle(0.2F, 0.1F);  // pan down, tilt up
  CHECK(same(camera_at(g_sim.pan().position_rad + 0.001F, g_sim.tilt().position_rad - 0.001F),
             g_sim.camera_pose()));
  // Without backlash the camera is where the axes are.
  start("rectangular_room");
  PanTiltSim plain(g_sim);
  CHECK(plain.init());
  plain.update();
  CHECK(plain.move_to(0.5F, -0.2F));
  CHECK(run_until(
            clock, [&] { return !plain.state().moving; }, 5.0, 1000) > 0.0);
  CHECK(same(camera_at(g_sim.pan().position_rad, g_sim.tilt().position_rad), g_sim.camera_pose()));
}
