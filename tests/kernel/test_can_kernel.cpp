// Kernel in the loop, CAN: BaseOdriveCan on vcan0 against the ODrive emulator's own raw socket.
#include <linux/can.h>
#include <linux/can/error.h>

#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <functional>
#include <memory>
#include <numbers>

#include "hal/linux/base_odrive_can.h"
#include "kernel_rig.h"
#include "odrive_can_emulator.h"

#include "CppUTest/TestHarness.h"
#include "alloc_guard.h"

using boticelli::fakes::OdriveCanEmulator;
using boticelli::hal::BaseHealth;
using boticelli::hal_linux::BaseOdriveCan;
using boticelli::hal_linux::BaseOdriveCanConfig;
using boticelli::kernel_test::Cycles;
using boticelli::kernel_test::sh;

namespace {

constexpr int kLeft = 0;
constexpr int kRight = 1;
constexpr const char* kInterface = "vcan0";
// The board's geometry: wheel radius 0.08 m, track 0.40 m, right motor mirrored.
constexpr double kTurnMetres = 2.0 * std::numbers::pi * 0.08;

bool add_interface() {
  return sh("ip link add dev vcan0 type vcan 2>/dev/null; ip link set up vcan0") == 0;
}

// One 10 ms cycle: the driver's update, then the emulator's service, on the real clock.
struct CanRig {
  CanRig() {
    CHECK_TRUE_TEXT(emu.open_can(kInterface), "the emulator cannot open vcan0");
    BaseOdriveCanConfig c;
    c.interface = kInterface;
    base = std::make_unique<BaseOdriveCan>(c, cycles.clock());
  }
  void cycle() {
    base->update();
    for (int i = 0; i < flood_per_cycle; ++i) emu.send_error_frame(CAN_ERR_PROT | CAN_ERR_BUSERROR);
    emu.service(cycles.now_us());
    cycles.wait();
  }
  bool run_until(const std::function<bool()>& done, int max_ms) {
    const std::uint64_t end = cycles.now_us() + static_cast<std::uint64_t>(max_ms) * 1000U;
    while (cycles.now_us() < end) {
      if (done()) return true;
      cycle();
    }
    return done();
  }
  void run_ms(int ms) {
    run_until([] { return false; }, ms);
  }
  bool ready_within(int ms) {
    return run_until([&] { return base->health() == BaseHealth::kReady; }, ms);
  }
  bool stopped_within(int ms) {
    return run_until([&] { return base->health() == BaseHealth::kStopped; }, ms);
  }
  bool start() {
    emu.service(cycles.now_us());
    return base->init() && ready_within(1500);
  }
  Cycles cycles;
  OdriveCanEmulator emu;
  std::unique_ptr<BaseOdriveCan> base;
  int flood_per_cycle = 0;
};

}  // namespace

TEST_GROUP(KernelCan){};

TEST(KernelCan, StartUpReachesClosedLoopAndVelocityCommandsMoveTheWheels) {
  CanRig rig;
  CHECK_TRUE_TEXT(rig.start(), rig.base->error());
  for (int axis : {kLeft, kRight}) {
    CHECK_EQUAL(8, rig.emu.axis_state(axis));
    CHECK_EQUAL(2U, rig.emu.control_mode(axis));
    CHECK_EQUAL(1U, rig.emu.input_mode(axis));
  }
  rig.base->set_velocity(0.2F, 0.0F);
  rig.run_ms(100);
  DOUBLES_EQUAL(0.2 / kTurnMetres, rig.emu.vel_setpoint(kLeft), 1e-4);
  DOUBLES_EQUAL(-0.2 / kTurnMetres, rig.emu.vel_setpoint(kRight), 1e-4);
}

TEST(KernelCan, OdometryFromTheEncoderEstimatesFollowsTheWheels) {
  CanRig rig;
  CHECK_TRUE_TEXT(rig.start(), rig.base->error());
  rig.base->set_velocity(0.2F, 0.0F);
  for (int i = 0; i < 100; ++i) {  // 1 s
    CHECK_NO_ALLOCATION(rig.base->update());
    rig.emu.service(rig.cycles.now_us());
    rig.cycles.wait();
  }
  // The wheels moved what the emulator integrated; the odometry must say the same.
  const double left_m = rig.emu.pos_turns(kLeft) * kTurnMetres;
  CHECK(left_m > 0.15);
  DOUBLES_EQUAL(left_m, rig.base->odometry().x_m, 0.02);
  DOUBLES_EQUAL(0.0, rig.base->odometry().yaw_rad, 0.01);
  rig.base->set_velocity(0.0F, 0.5F);
  rig.run_ms(1000);
  // Turning in place: each wheel moved yaw · track / 2.
  const double turned_rad = (rig.emu.pos_turns(kLeft) * kTurnMetres - left_m) / 0.20;
  DOUBLES_EQUAL(-turned_rad, rig.base->odometry().yaw_rad, 0.03);
  CHECK(std::fabs(turned_rad) > 0.3);
  CHECK(rig.base->health() == BaseHealth::kReady);
}

TEST(KernelCan, OneAxisLosingItsHeartbeatStopsTheBaseAndNamesTheAxis) {
  CanRig rig;
  CHECK_TRUE_TEXT(rig.start(), rig.base->error());
  rig.base->set_velocity(0.2F, 0.0F);
  rig.run_ms(50);
  rig.emu.silence_heartbeats(kRight, true);
  CHECK_TRUE(rig.stopped_within(1000));
  STRCMP_CONTAINS("right axis: heartbeat lost", rig.base->error());
  rig.run_ms(50);
  CHECK(rig.emu.estops(kLeft) >= 1U);
  CHECK_EQUAL(0.0F, rig.emu.vel_setpoint(kLeft));
}

TEST(KernelCan, ABusOffErrorFrameStopsTheBaseUntilTheControllerRestarts) {
  CanRig rig;
  CHECK_TRUE_TEXT(rig.start(), rig.base->error());
  rig.emu.send_error_frame(CAN_ERR_BUSOFF);
  CHECK_TRUE(rig.stopped_within(200));
  STRCMP_CONTAINS("bus-off", rig.base->error());
  CHECK_TRUE(rig.base->bus_off());
  CHECK_FALSE(rig.base->resume());  // the controller has not restarted yet
  STRCMP_CONTAINS("bus-off", rig.base->error());
  rig.emu.send_error_frame(CAN_ERR_RESTARTED);
  rig.run_ms(50);
  CHECK_FALSE(rig.base->bus_off());
  CHECK_TRUE_TEXT(rig.base->resume(), rig.base->error());
  CHECK_TRUE_TEXT(rig.ready_within(1500), rig.base->error());
}

TEST(KernelCan, AFloodOfBusErrorFramesDoesNotCrowdOutTheHeartbeats) {
  CanRig rig;
  CHECK_TRUE_TEXT(rig.start(), rig.base->error());
  rig.flood_per_cycle = 100;  // 10 000 error frames a second, as a bus with a bad node
  rig.run_ms(1500);
  rig.flood_per_cycle = 0;
  CHECK_TRUE_TEXT(rig.base->health() == BaseHealth::kReady, rig.base->error());
}

// The link's own troubles: run apart from KernelCan, whose bus candump records (candump
// ends when the interface goes down).
TEST_GROUP(KernelCanLink){void teardown() override{CHECK_TRUE(add_interface());
}
}
;

TEST(KernelCanLink, TheLinkGoingDownStopsTheBaseAndResumeWaitsUntilItIsUp) {
  CanRig rig;
  CHECK_TRUE_TEXT(rig.start(), rig.base->error());
  CHECK_EQUAL(0, sh("ip link set down vcan0"));
  CHECK_TRUE(rig.stopped_within(500));
  CHECK_FALSE(rig.base->resume());
  STRCMP_CONTAINS("down", rig.base->error());
  CHECK_EQUAL(0, sh("ip link set up vcan0"));
  CHECK_TRUE_TEXT(rig.base->resume(), rig.base->error());
  CHECK_TRUE_TEXT(rig.ready_within(1500), rig.base->error());
}

TEST(KernelCanLink, ABusOffIsOverOnceTheLinkHasBeenTakenDownAndUp) {
  CanRig rig;
  CHECK_TRUE_TEXT(rig.start(), rig.base->error());
  rig.emu.send_error_frame(CAN_ERR_BUSOFF);
  CHECK_TRUE(rig.stopped_within(200));
  CHECK_TRUE(rig.base->bus_off());
  // What an operator does when the controller has no restart-ms: the controller starts
  // afresh, and no CAN_ERR_RESTARTED frame says so.
  CHECK_EQUAL(0, sh("ip link set down vcan0"));
  rig.run_ms(100);
  CHECK_EQUAL(0, sh("ip link set up vcan0"));
  CHECK_FALSE(rig.base->bus_off());
  CHECK_TRUE_TEXT(rig.base->resume(), rig.base->error());
  CHECK_TRUE_TEXT(rig.ready_within(1500), rig.base->error());
}

TEST(KernelCanLink, AStopThatCouldNotBeSentWhileTheLinkWasDownIsSentWhenItIsBack) {
  CanRig rig;
  CHECK_TRUE_TEXT(rig.start(), rig.base->error());
  rig.base->set_velocity(0.2F, 0.0F);
  rig.run_ms(50);
  CHECK_EQUAL(0, sh("ip link set down vcan0"));
  CHECK_TRUE(rig.stopped_within(500));  // its Set_Input_Vel(0) and Estop could not be sent
  CHECK(rig.base->send_failures() > 0U);
  CHECK_EQUAL(0, sh("ip link set up vcan0"));
  rig.run_ms(300);
  // The ODrives never heard a stop while the link was down: they must hear it now.
  for (int axis : {kLeft, kRight}) {
    CHECK(rig.emu.estops(axis) >= 1U);
    CHECK_EQUAL(0.0F, rig.emu.vel_setpoint(axis));
    CHECK(rig.emu.axis_state(axis) != 8);
  }
}

TEST(KernelCanLink, AnInterfaceDeletedAndAddedAgainIsOpenedAnewByResume) {
  CanRig rig;
  CHECK_TRUE_TEXT(rig.start(), rig.base->error());
  CHECK_EQUAL(0, sh("ip link del vcan0"));
  CHECK_TRUE(rig.stopped_within(500));
  CHECK_FALSE(rig.base->resume());  // nothing to resume on
  STRCMP_CONTAINS("vcan0", rig.base->error());
  CHECK_TRUE(add_interface());
  CHECK_TRUE(rig.emu.open_can(kInterface));  // the emulator's old socket is dead too
  CHECK_TRUE_TEXT(rig.base->resume(), rig.base->error());
  CHECK_TRUE_TEXT(rig.ready_within(1500), rig.base->error());
  rig.base->set_velocity(0.2F, 0.0F);
  rig.run_ms(100);
  DOUBLES_EQUAL(0.2 / kTurnMetres, rig.emu.vel_setpoint(kLeft), 1e-4);
}

// The bus as candump recorded it while KernelCan ran (`candump -L vcan0`, one frame a line:
// "(seconds) vcan0 ID#HEXDATA" or "ID#R" for a remote request), checked against the table
// of docs/protocols.md: standard ids node<<5|cmd of nodes 0 and 1, the documented commands
// with their lengths, and start-up's order (Clear_Errors and Set_Controller_Mode velocity /
// passthrough before the first Set_Axis_State of that node), and the ODrives' watchdog kept
// fed: while a node is driven (its heartbeat reports closed loop after a Set_Axis_State(8),
// until an Estop, a Set_Axis_State(1) or a heartbeat without closed loop), no two
// Set_Input_Vel frames to it are further apart than kMaxSetpointGapS, half the 0.2 s
// `watchdog_timeout` docs/flashing.md sets on the ODrives.
TEST_GROUP(KernelCanRecord){};

namespace {
constexpr double kMaxSetpointGapS = 0.1;
}  // namespace

TEST(KernelCanRecord, EveryFrameOnTheBusIsADocumentedCanSimpleFrame) {
  const char* path = std::getenv("CAN_LOG") != nullptr ? std::getenv("CAN_LOG") : "/tmp/can.log";
  FILE* f = std::fopen(path, "r");
  CHECK_TEXT(f != nullptr, "no candump log");
  char line[160];
  int frames = 0;
  int heartbeats = 0;
  int set_input_vel = 0;
  bool clear_seen[2] = {false, false};
  bool mode_seen[2] = {false, false};
  bool state_seen[2] = {false, false};
  bool closed_loop_asked[2] = {false, false};
  bool driven[2] = {false, false};
  double last_setpoint_s[2] = {-1.0, -1.0};
  double worst_gap_s = 0.0;
  int gaps_checked = 0;
  while (std::fgets(line, sizeof line, f) != nullptr) {
    char ifname[16];
    char frame[64];
    double t = 0.0;
    if (std::sscanf(line, "(%lf) %15s %63s", &t, ifname, frame) != 3) continue;
    ++frames;
    STRCMP_EQUAL("vcan0", ifname);
    char* hash = std::strchr(frame, '#');
    CHECK_TEXT(hash != nullptr, line);
    *hash = '\0';
    CHECK_EQUAL_TEXT(3U, std::strlen(frame), line);  // 11-bit ids only
    const unsigned long id = std::strtoul(frame, nullptr, 16);
    const unsigned node = static_cast<unsigned>(id >> 5U);
    const unsigned cmd = static_cast<unsigned>(id & 0x1FU);
    CHECK_TEXT(node <= 1U, line);
    const char* data = hash + 1;
    const bool remote = data[0] == 'R';
    const std::size_t dlc = remote ? 0U : std::strlen(data) / 2;
    switch (cmd) {
      case 0x01: {  // Heartbeat: u32 axis error, u8 axis state, ...
        CHECK_EQUAL_TEXT(8U, dlc, line);
        ++heartbeats;
        const bool closed_loop = std::strncmp(data + 8, "08", 2) == 0;
        if (!closed_loop) {
          driven[node] = false;
        } else if (closed_loop_asked[node]) {
          driven[node] = true;
        }
        break;
      }
      case 0x02:  // Estop
        CHECK_EQUAL_TEXT(0U, dlc, line);
        driven[node] = closed_loop_asked[node] = false;
        break;
      case 0x07:  // Set_Axis_State: u32 8 (closed loop) or 1 (idle)
        CHECK_EQUAL_TEXT(4U, dlc, line);
        CHECK_TEXT(std::strcmp(data, "08000000") == 0 || std::strcmp(data, "01000000") == 0, line);
        CHECK_TEXT(clear_seen[node] && mode_seen[node], line);
        state_seen[node] = true;
        closed_loop_asked[node] = std::strcmp(data, "08000000") == 0;
        if (!closed_loop_asked[node]) driven[node] = false;
        break;
      case 0x09:  // Get_Encoder_Estimates: the ODrive's 8 bytes or the host's request
        CHECK_TEXT(remote || dlc == 8U, line);
        break;
      case 0x0B:  // Set_Controller_Mode: velocity control, passthrough
        STRCMP_EQUAL_TEXT("0200000001000000", data, line);
        mode_seen[node] = true;
        break;
      case 0x0D:  // Set_Input_Vel: f32 velocity, f32 torque feed-forward
        CHECK_EQUAL_TEXT(8U, dlc, line);
        ++set_input_vel;
        if (driven[node] && last_setpoint_s[node] >= 0.0) {
          const double gap = t - last_setpoint_s[node];
          ++gaps_checked;
          if (gap > worst_gap_s) worst_gap_s = gap;
          CHECK_TEXT(gap <= kMaxSetpointGapS, line);
        }
        last_setpoint_s[node] = driven[node] ? t : -1.0;
        break;
      case 0x18:  // Clear_Errors: identify byte 0
        STRCMP_EQUAL_TEXT("00", data, line);
        clear_seen[node] = true;
        break;
      default:
        FAIL(line);
    }
  }
  std::fclose(f);
  std::printf(
      "\ncandump: %d frames checked (%d heartbeats, %d Set_Input_Vel; %d setpoint gaps of a "
      "driven axis, the longest %.1f ms)\n",
      frames, heartbeats, set_input_vel, gaps_checked, worst_gap_s * 1e3);
  CHECK(frames > 500);
  CHECK(heartbeats > 50);
  CHECK(set_input_vel > 200);
  CHECK(gaps_checked > 100);
  CHECK_TRUE(state_seen[0] && state_seen[1]);
}
