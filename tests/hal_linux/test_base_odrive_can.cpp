// Tests of BaseOdriveCan against two emulated ODrive axes on a fake CAN bus (socketpair).
#include <linux/can.h>
#include <unistd.h>

#include <cmath>
#include <cstdint>
#include <functional>
#include <memory>
#include <numbers>
#include <string>
#include <vector>

#include "fake_clock.h"
#include "hal/linux/base_odrive_can.h"
#include "odrive_can_emulator.h"

#include "CppUTest/TestHarness.h"
#include "alloc_guard.h"

using boticelli::fakes::FakeClock;
using boticelli::fakes::OdriveCanEmulator;
using boticelli::fakes::OdriveCanEmulatorConfig;
using boticelli::hal::BaseHealth;
using boticelli::hal_linux::BaseOdriveCan;
using boticelli::hal_linux::BaseOdriveCanConfig;
namespace od = boticelli::codec::odrive;

namespace {

constexpr int kLeft = 0;
constexpr int kRight = 1;

// One cycle = driver update, emulator service, 10 ms of fake time (a 100 Hz executive).
// The socketpair delivers at once, so the whole rig is deterministic.
struct Rig {
  explicit Rig(const OdriveCanEmulatorConfig& ec = {}, BaseOdriveCanConfig bc = config())
      : emu(ec), clock(5000000) {
    CHECK_TRUE(emu.open());
    bc.socket_fd = emu.driver_fd();
    base = std::make_unique<BaseOdriveCan>(bc, clock);
  }
  static BaseOdriveCanConfig config() {
    BaseOdriveCanConfig c;
    c.left_node_id = 3;
    c.right_node_id = 4;
    c.geometry = {0.1F, 0.5F, 1.0F, -1.0F};
    c.heartbeat_timeout_ms = 300;
    c.startup_timeout_ms = 1000;
    return c;
  }
  static OdriveCanEmulatorConfig emu_config() {
    OdriveCanEmulatorConfig c;
    c.node_ids[0] = 3;
    c.node_ids[1] = 4;
    return c;
  }
  void cycle() {
    base->update();
    emu.service(clock.peek_us());
    clock.advance_us(10000);
  }
  bool run_until(const std::function<bool()>& done, int max_cycles = 1000) {
    for (int i = 0; i < max_cycles; ++i) {
      if (done()) return true;
      cycle();
    }
    return done();
  }
  bool start() {
    emu.service(clock.peek_us());
    if (!base->init()) return false;
    return run_until([&] { return base->health() == BaseHealth::kReady; });
  }
  OdriveCanEmulator emu;
  FakeClock clock;
  std::unique_ptr<BaseOdriveCan> base;
};

}  // namespace

TEST_GROUP(BaseOdriveCan){};

TEST(BaseOdriveCan, StartUpPutsBothAxesInClosedLoopVelocityControl) {
  Rig rig(Rig::emu_config());
  CHECK_TRUE(rig.base->init());
  CHECK(rig.base->health() == BaseHealth::kStarting);
  CHECK_TRUE_TEXT(rig.run_until([&] { return rig.base->health() == BaseHealth::kReady; }),
                  rig.base->error());
  for (int axis : {kLeft, kRight}) {
    CHECK_EQUAL(8, rig.emu.axis_state(axis));
    CHECK_EQUAL(2U, rig.emu.control_mode(axis));
    CHECK_EQUAL(1U, rig.emu.input_mode(axis));
    CHECK(rig.emu.count(axis, od::Command::kClearErrors) >= 1U);
  }
  STRCMP_EQUAL("", rig.base->error());
}

TEST(BaseOdriveCan, VelocityCommandsBecomeWheelTurnsPerSecond) {
  Rig rig(Rig::emu_config());
  CHECK_TRUE(rig.start());
  rig.base->set_velocity(0.5F, 0.4F);
  rig.cycle();
  rig.cycle();
  // v_l = 0.5 − 0.4·0.25 = 0.4 m/s, v_r = 0.6 m/s; r = 0.1 m; right motor mirrored.
  const double per_turn = 2.0 * std::numbers::pi * 0.1;
  DOUBLES_EQUAL(0.4 / per_turn, rig.emu.vel_setpoint(kLeft), 1e-5);
  DOUBLES_EQUAL(-0.6 / per_turn, rig.emu.vel_setpoint(kRight), 1e-5);
}

TEST(BaseOdriveCan, SetpointsAreClampedKeepingTheCurvature) {
  BaseOdriveCanConfig bc = Rig::config();
  bc.max_wheel_turns_s = 1.0F;
  Rig rig(Rig::emu_config(), bc);
  CHECK_TRUE(rig.start());
  rig.base->set_velocity(10.0F, 10.0F);  // far beyond 1 turn/s
  rig.cycle();
  rig.cycle();
  const float l = rig.emu.vel_setpoint(kLeft);
  const float r = rig.emu.vel_setpoint(kRight);
  DOUBLES_EQUAL(1.0, std::max(std::fabs(l), std::fabs(r)), 1e-5);
  // v_l : v_r = (10 − 2.5) : (10 + 2.5)
  DOUBLES_EQUAL(7.5 / 12.5, std::fabs(l / r), 1e-4);
}

TEST(BaseOdriveCan, TheSetpointIsResentEveryCycleSoTheOdriveWatchdogStaysFed) {
  OdriveCanEmulatorConfig ec = Rig::emu_config();
  ec.watchdog_timeout_us = 50000;  // 5 cycles without a setpoint trips it
  Rig rig(ec);
  CHECK_TRUE(rig.start());
  rig.base->set_velocity(0.2F, 0.0F);
  const std::uint32_t before = rig.emu.count(kLeft, od::Command::kSetInputVel);
  for (int i = 0; i < 300; ++i) rig.cycle();  // 3 s
  CHECK_EQUAL(before + 300U, rig.emu.count(kLeft, od::Command::kSetInputVel));
  CHECK_EQUAL(0U, rig.emu.axis_error(kLeft));
  CHECK(rig.base->health() == BaseHealth::kReady);
}

TEST(BaseOdriveCan, OdometryFollowsTheEncoderEstimates) {
  Rig rig(Rig::emu_config());
  CHECK_TRUE(rig.start());
  rig.base->set_velocity(0.5F, 0.0F);
  for (int i = 0; i < 200; ++i) rig.cycle();  // 2 s at 0.5 m/s
  const auto odo = rig.base->odometry();
  DOUBLES_EQUAL(1.0, odo.x_m, 0.02);  // one cycle of latency at most
  DOUBLES_EQUAL(0.0, odo.y_m, 1e-6);
  DOUBLES_EQUAL(0.5, odo.v_m_s, 1e-4);
  DOUBLES_EQUAL(0.0, odo.omega_rad_s, 1e-4);
  CHECK(odo.timestamp_us > 5000000U);
  rig.base->set_velocity(0.0F, 0.5F);  // a quarter turn in place: π s
  for (int i = 0; i < 314; ++i) rig.cycle();
  DOUBLES_EQUAL(std::numbers::pi / 2, rig.base->odometry().yaw_rad, 0.02);
  DOUBLES_EQUAL(1.0, rig.base->odometry().x_m, 0.03);
}

TEST(BaseOdriveCan, EncoderRequestsAreSentWhenConfigured) {
  OdriveCanEmulatorConfig ec = Rig::emu_config();
  ec.encoder_period_us = 0;  // the ODrives only answer requests
  BaseOdriveCanConfig bc = Rig::config();
  bc.request_encoder = true;
  Rig rig(ec, bc);
  CHECK_TRUE(rig.start());
  rig.base->set_velocity(0.5F, 0.0F);
  for (int i = 0; i < 100; ++i) rig.cycle();
  CHECK(rig.emu.count(kRight, od::Command::kGetEncoderEstimates) >= 99U);
  DOUBLES_EQUAL(0.5, rig.base->odometry().x_m, 0.02);
}

TEST(BaseOdriveCan, ALostHeartbeatStopsTheBaseAndSaysWhich) {
  Rig rig(Rig::emu_config());
  CHECK_TRUE(rig.start());
  rig.base->set_velocity(0.3F, 0.0F);
  rig.cycle();
  rig.emu.silence_heartbeats(kRight, true);
  const std::uint64_t t0 = rig.clock.peek_us();
  CHECK_TRUE(rig.run_until([&] { return rig.base->health() == BaseHealth::kStopped; }));
  CHECK(rig.clock.peek_us() - t0 >= 200000U);  // not before the timeout (300 ms after the last)
  STRCMP_CONTAINS("right axis: heartbeat lost", rig.base->error());
  rig.cycle();
  CHECK(rig.emu.estops(kLeft) >= 1U);
  CHECK_EQUAL(0.0F, rig.emu.vel_setpoint(kLeft));
  // Commands are ignored while stopped.
  rig.base->set_velocity(1.0F, 0.0F);
  rig.cycle();
  CHECK_EQUAL(0.0F, rig.emu.vel_setpoint(kLeft));
}

TEST(BaseOdriveCan, ABusOffErrorFrameStopsTheBase) {
  Rig rig(Rig::emu_config());
  CHECK_TRUE(rig.start());
  rig.base->set_velocity(0.3F, 0.0F);
  rig.cycle();
  rig.emu.send_bus_off();
  rig.cycle();
  CHECK(rig.base->health() == BaseHealth::kStopped);
  STRCMP_CONTAINS("bus-off", rig.base->error());
  CHECK_EQUAL(1U, rig.base->error_frames());
}

TEST(BaseOdriveCan, AnAxisErrorStopsTheBaseWithTheErrorCode) {
  Rig rig(Rig::emu_config());
  CHECK_TRUE(rig.start());
  rig.emu.set_axis_error(kLeft, 0x40);
  CHECK_TRUE(rig.run_until([&] { return rig.base->health() == BaseHealth::kStopped; }));
  STRCMP_CONTAINS("left axis", rig.base->error());
  STRCMP_CONTAINS("0x00000040", rig.base->error());
}

TEST(BaseOdriveCan, StopIsImmediateAndResumeRunsTheStartUpAgain) {
  Rig rig(Rig::emu_config());
  CHECK_TRUE(rig.start());
  rig.base->set_velocity(0.3F, 0.0F);
  rig.cycle();
  rig.base->stop();
  CHECK(rig.base->health() == BaseHealth::kStopped);
  rig.cycle();
  rig.cycle();
  // The perfect emulated controller is at rest at once (its next estimate says so): the
  // brake ends, the axes idle.
  CHECK_FALSE(rig.base->braking());
  CHECK_EQUAL(0U, rig.emu.estops(kLeft));
  CHECK_EQUAL(1, rig.emu.axis_state(kLeft));  // the ODrive disarmed
  CHECK_EQUAL(1, rig.emu.axis_state(kRight));
  CHECK_TRUE(rig.base->resume());
  CHECK_TRUE(rig.run_until([&] { return rig.base->health() == BaseHealth::kReady; }));
  CHECK_EQUAL(0U, rig.emu.axis_error(kLeft));
  CHECK_EQUAL(0.0F, rig.emu.vel_setpoint(kLeft));  // the old setpoint was not kept
}

namespace {

// An ODrive whose velocity controller brakes at 4 turns/s² and whose idle wheel coasts at
// 0.5 turns/s².
OdriveCanEmulatorConfig braking_emu(float accel_turns_s2 = 4.0F) {
  OdriveCanEmulatorConfig ec = Rig::emu_config();
  ec.accel_turns_s2 = accel_turns_s2;
  ec.coast_turns_s2 = 0.5F;
  return ec;
}

// Index of the first frame of `command` in the log (to `state` for Set_Axis_State), or −1.
int first(const std::vector<OdriveCanEmulator::Sent>& log, od::Command command,
          std::uint32_t state = 0) {
  for (std::size_t i = 0; i < log.size(); ++i) {
    if (log[i].command == command &&
        (command != od::Command::kSetAxisState || log[i].state == state)) {
      return static_cast<int>(i);
    }
  }
  return -1;
}

}  // namespace

TEST(BaseOdriveCan, ARequestedStopBrakesInClosedLoopAndIdlesTheAxesOnlyAtStandstill) {
  Rig rig(braking_emu());
  CHECK_TRUE(rig.start());
  rig.base->set_velocity(0.5F, 0.0F);  // 0.80 turns/s each wheel
  for (int i = 0; i < 50; ++i) rig.cycle();
  DOUBLES_EQUAL(0.796, rig.emu.velocity(kLeft), 0.01);
  rig.emu.clear_log();
  rig.base->stop();
  CHECK(rig.base->health() == BaseHealth::kStopped);  // no motion commanded from now on
  CHECK_TRUE(rig.base->braking());
  const std::uint64_t t0 = rig.clock.peek_us();
  CHECK_TRUE(rig.run_until([&] { return !rig.base->braking(); }, 100));
  const std::uint64_t braked_us = rig.clock.peek_us() - t0;
  rig.cycle();
  const auto& log = rig.emu.log();
  // Set_Input_Vel(0) to both axes first, in the stop() call itself.
  CHECK(log.size() >= 2U);
  CHECK(log[0].command == od::Command::kSetInputVel && log[0].input_vel == 0.0F);
  CHECK(log[1].command == od::Command::kSetInputVel && log[1].input_vel == 0.0F);
  CHECK(log[0].node != log[1].node);
  // Idle only once both wheels were at rest; until then only zero setpoints (no Estop).
  const int idle = first(log, od::Command::kSetAxisState, 1);
  CHECK(idle > 2);
  CHECK(std::fabs(log[static_cast<std::size_t>(idle)].wheel_vel[0]) < 0.05F);
  CHECK(std::fabs(log[static_cast<std::size_t>(idle)].wheel_vel[1]) < 0.05F);
  for (int i = 0; i < idle; ++i) {
    CHECK(log[static_cast<std::size_t>(i)].command == od::Command::kSetInputVel);
    CHECK_EQUAL(0.0F, log[static_cast<std::size_t>(i)].input_vel);
  }
  CHECK_EQUAL(-1, first(log, od::Command::kEstop));
  // 0.8 turns/s at 4 turns/s²: 0.2 s of braking, well inside the 0.5 s brake time.
  CHECK(braked_us >= 190000U && braked_us <= 260000U);
  CHECK_EQUAL(1, rig.emu.axis_state(kLeft));
  CHECK_EQUAL(1, rig.emu.axis_state(kRight));
  CHECK_EQUAL(0U, rig.emu.axis_error(kLeft));  // a requested stop is no error
  STRCMP_CONTAINS("stopped by request", rig.base->error());
  // While stopped, the idle state is repeated (not an Estop).
  for (int i = 0; i < 30; ++i) rig.cycle();
  CHECK_EQUAL(0U, rig.emu.estops(kLeft));
  CHECK_TRUE(rig.base->resume());
  CHECK_TRUE(rig.run_until([&] { return rig.base->health() == BaseHealth::kReady; }));
}

TEST(BaseOdriveCan, ABrakeThatTakesTooLongIdlesTheAxesAtTheBrakeTimeout) {
  Rig rig(braking_emu(0.5F));  // 0.8 turns/s at 0.5 turns/s²: 1.6 s to rest
  CHECK_TRUE(rig.start());
  rig.base->set_velocity(0.5F, 0.0F);
  for (int i = 0; i < 300; ++i) rig.cycle();
  rig.emu.clear_log();
  rig.base->stop();
  const std::uint64_t t0 = rig.clock.peek_us();
  CHECK_TRUE(rig.run_until([&] { return !rig.base->braking(); }, 100));
  const std::uint64_t braked_us = rig.clock.peek_us() - t0;
  CHECK(braked_us >= 500000U && braked_us <= 520000U);  // brake_timeout_ms
  rig.cycle();
  const int idle = first(rig.emu.log(), od::Command::kSetAxisState, 1);
  CHECK(idle > 0);
  CHECK(rig.emu.log()[static_cast<std::size_t>(idle)].wheel_vel[0] > 0.3F);  // still turning
  CHECK_EQUAL(1, rig.emu.axis_state(kLeft));
}

TEST(BaseOdriveCan, AnAxisErrorCannotBrakeAndIdlesBothAxesAtOnceWithEstop) {
  Rig rig(braking_emu());
  CHECK_TRUE(rig.start());
  rig.base->set_velocity(0.5F, 0.0F);
  for (int i = 0; i < 50; ++i) rig.cycle();
  rig.emu.clear_log();
  rig.emu.set_axis_error(kLeft, 0x40);  // the left axis is out of closed loop
  CHECK_TRUE(rig.run_until([&] { return rig.base->health() == BaseHealth::kStopped; }, 30));
  CHECK_FALSE(rig.base->braking());
  rig.cycle();
  const auto& log = rig.emu.log();
  const int estop = first(log, od::Command::kEstop);
  CHECK(estop > 0);
  // In the same update: Set_Input_Vel(0) then Estop to each axis, the right wheel still
  // turning (no waiting for rest), and no braked idle.
  const auto e = static_cast<std::size_t>(estop);
  CHECK(log[e - 1].command == od::Command::kSetInputVel && log[e - 1].input_vel == 0.0F);
  CHECK(log[e + 1].command == od::Command::kSetInputVel &&
        log[e + 2].command == od::Command::kEstop);
  CHECK(log[e].node != log[e + 2].node);
  CHECK(std::fabs(log[e].wheel_vel[kRight]) > 0.7F);
  CHECK_EQUAL(-1, first(log, od::Command::kSetAxisState, 1));
  CHECK_EQUAL(1, rig.emu.axis_state(kRight));
}

TEST(BaseOdriveCan, AHeartbeatLostWhileBrakingTurnsTheBrakeIntoAnEstop) {
  Rig rig(braking_emu(0.5F));
  CHECK_TRUE(rig.start());
  rig.base->set_velocity(0.5F, 0.0F);
  for (int i = 0; i < 300; ++i) rig.cycle();
  rig.base->stop();
  rig.emu.silence_heartbeats(kRight, true);
  CHECK_TRUE(rig.run_until([&] { return !rig.base->braking(); }, 100));
  STRCMP_CONTAINS("right axis: heartbeat lost while braking", rig.base->error());
  rig.cycle();
  CHECK(rig.emu.estops(kLeft) >= 1U);
  CHECK(rig.emu.estops(kRight) >= 1U);
}

TEST(BaseOdriveCan, AStartUpWithoutOdrivesTimesOut) {
  Rig rig(Rig::emu_config());
  rig.emu.silence_heartbeats(kLeft, true);
  CHECK_TRUE(rig.base->init());
  CHECK_TRUE(rig.run_until([&] { return rig.base->health() == BaseHealth::kStopped; }));
  STRCMP_CONTAINS("left axis: no heartbeat during start-up", rig.base->error());
  CHECK(rig.emu.count(kLeft, od::Command::kSetAxisState) >= 3U);  // re-sent while waiting
}

TEST(BaseOdriveCan, MalformedFramesAreCountedAndChangeNothing) {
  Rig rig(Rig::emu_config());
  CHECK_TRUE(rig.start());
  rig.base->set_velocity(0.5F, 0.0F);
  for (int i = 0; i < 20; ++i) rig.cycle();
  const auto before = rig.base->odometry();
  const std::uint32_t rejected = rig.base->rejected_frames();
  od::CanFrame f = od::encode_encoder_estimates(3, {1000.0F, 50.0F});
  f.dlc = 4;  // wrong length
  rig.emu.send_frame(f);
  f = od::encode_encoder_estimates(3, {std::nanf(""), 0.0F});  // NaN
  rig.emu.send_frame(f);
  f = od::encode_encoder_estimates(9, {1000.0F, 50.0F});  // another node
  rig.emu.send_frame(f);
  f.id = od::make_id(3, od::Command{0x1E});  // unknown command
  rig.emu.send_frame(f);
  f = od::encode_heartbeat(4, {0xFFFF, 1, 0, false});
  f.extended = true;  // extended id
  rig.emu.send_frame(f);
  const std::uint8_t junk[5] = {1, 2, 3, 4, 5};
  rig.emu.send_bytes(junk, sizeof junk);  // truncated datagram
  rig.base->update();
  CHECK_EQUAL(rejected + 6U, rig.base->rejected_frames());
  CHECK(rig.base->health() == BaseHealth::kReady);
  DOUBLES_EQUAL(before.x_m, rig.base->odometry().x_m, 0.02);
}

TEST(BaseOdriveCan, ImpossibleButFiniteEncoderEstimatesAreRejectedAndTheOdometryStaysFinite) {
  // Found by fuzzing: a velocity of -3.4e38 turns/s made the odometry's speed infinite.
  Rig rig(Rig::emu_config());
  CHECK_TRUE(rig.start());
  rig.base->set_velocity(0.5F, 0.0F);
  for (int i = 0; i < 20; ++i) rig.cycle();
  const auto before = rig.base->odometry();
  const std::uint32_t rejected = rig.base->rejected_frames();
  rig.emu.send_frame(od::encode_encoder_estimates(3, {8.0F, -3.4028e38F}));
  rig.emu.send_frame(od::encode_encoder_estimates(4, {3e38F, 1.0F}));
  rig.emu.send_frame(od::encode_encoder_estimates(3, {-2e7F, 0.0F}));
  rig.emu.send_frame(od::encode_encoder_estimates(4, {0.0F, 1001.0F}));
  rig.base->update();
  CHECK_EQUAL(rejected + 4U, rig.base->rejected_frames());
  const auto after = rig.base->odometry();
  CHECK(std::isfinite(after.x_m) && std::isfinite(after.y_m) && std::isfinite(after.yaw_rad));
  CHECK(std::isfinite(after.v_m_s) && std::isfinite(after.omega_rad_s));
  DOUBLES_EQUAL(before.x_m, after.x_m, 0.02);
  CHECK(rig.base->health() == BaseHealth::kReady);
}

TEST(BaseOdriveCan, BadGeometryIsRefusedAtInit) {
  BaseOdriveCanConfig bc = Rig::config();
  bc.geometry.wheel_radius_m = 0.0F;
  Rig rig(Rig::emu_config(), bc);
  CHECK_FALSE(rig.base->init());
  STRCMP_CONTAINS("bad configuration", rig.base->error());
  ::close(rig.emu.driver_fd());  // not taken over by the driver
}

TEST(BaseOdriveCan, AMissingInterfaceIsAClearError) {
  BaseOdriveCanConfig bc = Rig::config();
  bc.interface = "nosuchcan7";
  FakeClock clock;
  BaseOdriveCan base(bc, clock);
  CHECK_FALSE(base.init());
  // Without CAN support in the kernel the socket itself fails; with it, the interface lookup.
  CHECK(std::string(base.error()).find("CAN") != std::string::npos);
}

TEST(BaseOdriveCan, TheCyclicCallsDoNotAllocate) {
  Rig rig(Rig::emu_config());
  CHECK_TRUE(rig.start());
  for (int i = 0; i < 100; ++i) {
    CHECK_NO_ALLOCATION(rig.base->set_velocity(0.2F, 0.1F));
    CHECK_NO_ALLOCATION(rig.base->update());
    CHECK_NO_ALLOCATION((void)rig.base->odometry());
    rig.emu.service(rig.clock.peek_us());
    rig.clock.advance_us(10000);
  }
  CHECK(rig.base->health() == BaseHealth::kReady);
  CHECK_NO_ALLOCATION(rig.base->stop());
  for (int i = 0; i < 10; ++i) {  // the brake's updates
    CHECK_NO_ALLOCATION(rig.base->update());
    rig.emu.service(rig.clock.peek_us());
    rig.clock.advance_us(10000);
  }
}

TEST(BaseOdriveCan, AWheelWhoseEncoderStreamStopsStopsTheBaseInsteadOfTurningTheOdometry) {
  Rig rig(Rig::emu_config());
  CHECK_TRUE(rig.start());
  rig.base->set_velocity(0.5F, 0.0F);
  for (int i = 0; i < 50; ++i) rig.cycle();
  rig.emu.silence_encoder(kLeft, true);  // its heartbeats go on
  const double yaw_before = rig.base->odometry().yaw_rad;
  CHECK_TRUE(rig.run_until([&] { return rig.base->health() == BaseHealth::kStopped; }, 100));
  STRCMP_CONTAINS("left axis: encoder estimates stopped", rig.base->error());
  // Integrated with the left wheel standing still, the right one's 0.5 m/s would have
  // turned the odometry by 0.5/0.5 = 1 rad/s.
  DOUBLES_EQUAL(yaw_before, rig.base->odometry().yaw_rad, 0.005);
}

// The last gasp of a crashing firmware: a zero velocity to both axes, which their velocity
// controllers brake to (not Estop: that would idle them and let the robot coast), and
// nothing else: no state of the driver changes (it runs inside a signal handler).
TEST(BaseOdriveCan, TheLastGaspSendsAZeroVelocityToBothAxesAndNoEstop) {
  Rig rig(Rig::emu_config());
  CHECK_TRUE(rig.start());
  rig.base->set_velocity(0.3F, 0.2F);
  rig.cycle();
  rig.cycle();
  CHECK(std::fabs(rig.emu.vel_setpoint(kLeft)) > 0.1F);
  const std::uint32_t sent = rig.base->sent_frames();
  rig.base->last_gasp_stop();
  rig.emu.service(rig.clock.peek_us());
  for (int axis : {kLeft, kRight}) {
    DOUBLES_EQUAL(0.0, rig.emu.vel_setpoint(axis), 0.0);
    CHECK_EQUAL(8, rig.emu.axis_state(axis));  // still in closed loop: braking
    CHECK_EQUAL(0U, rig.emu.estops(axis));
  }
  CHECK(rig.base->health() == BaseHealth::kReady);
  CHECK_EQUAL(sent, rig.base->sent_frames());  // no counter touched
}

// The wheel counters are the ODrives' own position estimates as forward wheel travel (the
// right motor mirrored): they do not restart with the driver, which is what lets a resumed
// mission dead-reckon across a restart of the firmware.
TEST(BaseOdriveCan, TheWheelCountersAreTheOdrivesPositionsAsForwardTravelAndOutliveTheDriver) {
  Rig rig(Rig::emu_config());
  CHECK_FALSE(rig.base->odometry().wheels_known);
  CHECK_TRUE(rig.start());
  rig.base->set_velocity(0.5F, 0.0F);
  for (int i = 0; i < 100; ++i) rig.cycle();  // 1 s at 0.5 m/s
  const double per_turn = 2.0 * std::numbers::pi * 0.1;
  const auto odo = rig.base->odometry();
  CHECK(odo.wheels_known);
  DOUBLES_EQUAL(0.5, odo.wheel_left_m, 0.02);
  DOUBLES_EQUAL(0.5, odo.wheel_right_m, 0.02);
  DOUBLES_EQUAL(rig.emu.pos_turns(kLeft) * per_turn, odo.wheel_left_m, 0.006);
  DOUBLES_EQUAL(-rig.emu.pos_turns(kRight) * per_turn, odo.wheel_right_m, 0.006);
  // Stopped and started again: the counters are still the ODrives' positions.
  rig.base->stop();
  rig.cycle();
  const double left_before = rig.base->odometry().wheel_left_m;
  CHECK_TRUE(rig.base->resume());
  CHECK_TRUE(rig.run_until([&] { return rig.base->health() == BaseHealth::kReady; }));
  rig.cycle();
  DOUBLES_EQUAL(left_before, rig.base->odometry().wheel_left_m, 0.006);
  DOUBLES_EQUAL(rig.emu.pos_turns(kLeft) * per_turn, rig.base->odometry().wheel_left_m, 1e-6);
}

TEST(BaseOdriveCan, AJammedWheelStopsTheBaseAfterTheFollowTimeAndIdlesBothAxes) {
  Rig rig(Rig::emu_config());
  CHECK_TRUE(rig.start());
  rig.base->set_velocity(0.5F, 0.0F);
  for (int i = 0; i < 50; ++i) rig.cycle();
  rig.emu.jam(kLeft, true);
  const std::uint64_t t0 = rig.clock.peek_us();
  CHECK_TRUE(rig.run_until([&] { return rig.base->health() == BaseHealth::kStopped; }, 150));
  const std::uint64_t t = rig.clock.peek_us() - t0;
  CHECK(t >= 1000000U && t <= 1050000U);  // follow_timeout_ms, and not before
  STRCMP_CONTAINS("left axis: wheel not following its setpoint", rig.base->error());
  rig.cycle();
  CHECK(rig.emu.estops(kLeft) >= 1U);  // its loop cannot be trusted: idled, not braked
  CHECK(rig.emu.estops(kRight) >= 1U);
}

TEST(BaseOdriveCan, EncoderEstimatesThatStopChangingStopTheBaseLikeAJammedWheel) {
  Rig rig(Rig::emu_config());
  CHECK_TRUE(rig.start());
  rig.base->set_velocity(0.0F, 1.0F);  // turning in place: ∓0.25 m/s, ∓0.40 turns/s
  for (int i = 0; i < 50; ++i) rig.cycle();
  rig.emu.freeze_encoder(kRight, true);  // the estimates go on arriving, always the same
  CHECK_TRUE(rig.run_until([&] { return rig.base->health() == BaseHealth::kStopped; }, 150));
  STRCMP_CONTAINS("right axis: wheel not following its setpoint", rig.base->error());
}

TEST(BaseOdriveCan, AWheelRampingUpOrReversingWithinTheFollowTimeIsNotAFault) {
  OdriveCanEmulatorConfig ec = Rig::emu_config();
  ec.accel_turns_s2 = 2.0F;  // 0.8 turns/s reversed in 0.8 s
  Rig rig(ec);
  CHECK_TRUE(rig.start());
  for (int k = 0; k < 6; ++k) {
    rig.base->set_velocity(k % 2 == 0 ? 0.5F : -0.5F, 0.0F);
    for (int i = 0; i < 150; ++i) rig.cycle();
    CHECK_TEXT(rig.base->health() == BaseHealth::kReady, rig.base->error());
  }
  rig.base->set_velocity(0.03F, 0.0F);  // below follow_min_turns_s: not judged
  rig.emu.jam(kLeft, true);
  for (int i = 0; i < 200; ++i) rig.cycle();
  CHECK_TEXT(rig.base->health() == BaseHealth::kReady, rig.base->error());
}

// Asked to stop again and again while stopped (the e-stop task asks every 10 ms frame while
// the button is held) the driver sends nothing more: the stop is re-sent by update() at its
// own interval, which keeps an ODrive that came back stopped without loading the bus or the
// e-stop task's budget with four frames a frame.
TEST(BaseOdriveCan, AStopAskedAgainWhileStoppedSendsNothingAndUpdateResendsItAtItsInterval) {
  Rig rig(Rig::emu_config());
  CHECK_TRUE(rig.start());
  rig.base->stop();
  CHECK_TRUE(rig.run_until([&] { return !rig.base->braking(); }));
  rig.emu.service(rig.clock.peek_us());
  rig.emu.clear_log();
  for (int i = 0; i < 10; ++i) rig.base->stop();
  rig.emu.service(rig.clock.peek_us());
  CHECK_EQUAL(0U, rig.emu.log().size());
  // Over one second of frames, each asking again: the resends of update() only.
  const std::uint32_t resend_ms = Rig::config().stop_resend_ms;
  for (int i = 0; i < 100; ++i) {
    rig.base->stop();
    rig.cycle();
  }
  const std::size_t frames = rig.emu.log().size();
  const std::size_t per_resend = 4;  // velocity 0 and IDLE to each axis
  CHECK(frames >= per_resend);
  CHECK(frames <= per_resend * (1000U / resend_ms + 1U));
}
