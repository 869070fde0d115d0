// Tests of the sim board's wiring: config, world loading, the HAL bag driving one SimWorld.
#include <fcntl.h>
#include <unistd.h>

#include <cmath>
#include <cstddef>
#include <cstdio>
#include <cstdint>
#include <cstring>
#include <ctime>
#include <memory>
#include <string>

#include "sim_board.h"
#include "sim_test_worlds.h"
#include "test_files.h"
#include "world_truth_file.h"

#include "alloc_guard.h"
#include "CppUTest/TestHarness.h"

using boticelli::hal::sim::test::world_path;
namespace hal = boticelli::hal;

namespace {
char g_error[256];
}  // namespace

TEST_GROUP(SimBoard) {
  // The board holds the world and its textures (a few MB): static in main.cpp, on the heap
  // here so each test gets a fresh one and its buffers are freed with it.
  std::unique_ptr<boticelli::boards::sim::SimBoard> board;
  void setup() override {
    board = std::make_unique<boticelli::boards::sim::SimBoard>();
    g_error[0] = '\0';
  }
  void teardown() override {
    board.reset();
  }
};

TEST(SimBoard, DescribesItselfAsASimulatedBoardWithTheThesisRig) {
  CHECK(board->info().simulated);
  STRCMP_EQUAL("sim", board->info().name);
  const auto& c = board->config();
  UNSIGNED_LONGS_EQUAL(640, c.camera_width_px);
  DOUBLES_EQUAL(150.0, c.focal_px / 4.0F, 1e-6);  // F = 150 px at 160x120 (thesis §3.4)
  DOUBLES_EQUAL(0.21, c.lever_m, 1e-6);
  DOUBLES_EQUAL(7.7 * 3.14159265358979 / 180.0, c.tilt_step_rad, 1e-7);
  CHECK_FALSE(c.realtime);
  CHECK(c.background_units_per_slice > 0);  // work per frame independent of the host
}

// [sim]'s optics errors reach the rig the simulator draws and moves (the renderer's camera and
// the PTU-camera lever), not the configuration the firmware reads.
TEST(SimBoard, TheSimulatorDrawsWithTheTrueRigAndTheFirmwareIsToldTheConfiguredOne) {
  const std::string path = world_path("thesis_room");
  boticelli::firmware::Options options;
  options.world_file = path.c_str();
  board->settings().optics.focal_scale = 1.05F;
  board->settings().optics.lens_k1_error = 0.1F;
  board->settings().optics.lever_error_m = 0.004F;
  CHECK_TEXT(board->init(options, g_error, sizeof g_error), g_error);
  DOUBLES_EQUAL(600.0, board->config().focal_px, 0.0);
  DOUBLES_EQUAL(630.0, board->rig().camera().focal_px, 1e-3);
  DOUBLES_EQUAL(board->config().k1 + 0.1F, board->rig().camera().k1, 1e-6);
  DOUBLES_EQUAL(0.21, board->config().lever_m, 1e-6);
  DOUBLES_EQUAL(0.214, board->rig().params().lever_m, 1e-6);
}

TEST(SimBoard, ABadWorldFailsInitWithTheFileAndLine) {
  boticelli::firmware::Options options;
  options.world_file = "/nonexistent/room.sdf";
  CHECK_FALSE(board->init(options, g_error, sizeof g_error));
  CHECK(std::strstr(g_error, "/nonexistent/room.sdf") != nullptr);
}

TEST(SimBoard, TheHalBagDrivesOneWorldInLockstep) {
  const std::string path = world_path("thesis_room");
  boticelli::firmware::Options options;
  options.world_file = path.c_str();
  options.seed = 5;
  // Few full-size frames, so the test stays quick under the sanitizers and qemu.
  board->settings().camera_fps = 5.0F;
  CHECK_TEXT(board->init(options, g_error, sizeof g_error), g_error);
  hal::Hal& h = board->hal();
  // The renderer uses exactly the config's camera.
  UNSIGNED_LONGS_EQUAL(board->config().camera_width_px, board->renderer().width_px());
  DOUBLES_EQUAL(board->config().k1, board->rig().camera().k1, 0.0);
  CHECK(h.camera.init());
  CHECK(h.pan_tilt.init());
  CHECK(h.base.init());
  CHECK(h.watchdog.start(board->config().watchdog_timeout_ms));
  CHECK(h.pan_tilt.move_to(0.5F, 0.0F) == false);  // not initialised until update()
  h.pan_tilt.update();
  CHECK(h.pan_tilt.move_to(0.5F, 0.0F));
  // A minor frame: services the devices, then sleeps to the next deadline. No allocation.
  const std::uint32_t frame_us = board->config().minor_frame_us;
  hal::Frame frame;
  int frames = 0;
  auto minor_frame = [&] {
    h.pan_tilt.update();
    h.base.update();
    if (h.camera.poll(frame) == hal::CameraPoll::kFrame) {
      ++frames;
      h.camera.release();
    }
    h.watchdog.kick();
    h.status_led.write((h.clock.now_us() / 500000U) % 2U == 0U);
    h.clock.sleep_until_us(h.clock.now_us() + frame_us);
  };
  for (int i = 0; i < 10; ++i) minor_frame();  // the first frame (and any warm-up) here
  CHECK_NO_ALLOCATION(for (int i = 0; i < 100; ++i) minor_frame());
  // 1.1 s of simulated time: frames at 0, 0.2, ... 1.0 s, the pan move (0.75 s) done, the
  // base ready.
  UNSIGNED_LONGS_EQUAL(1100000, h.clock.now_us());
  LONGS_EQUAL(6, frames);
  UNSIGNED_LONGS_EQUAL(640, frame.width_px);
  UNSIGNED_LONGS_EQUAL(1280, frame.stride_bytes);
  CHECK_FALSE(h.pan_tilt.state().moving);
  DOUBLES_EQUAL(0.5, h.pan_tilt.state().pan_rad, 1e-3);
  CHECK(h.base.health() == hal::BaseHealth::kReady);
  UNSIGNED_LONGS_EQUAL(0, board->sim().watchdog_expirations());
  CHECK(board->sim().led_changes() >= 2);
  // Ground truth through the sim-only API.
  auto& sim = board->sim();
  DOUBLES_EQUAL(board->world().start.x_m, sim.true_pose().x_m, 1e-6);
  DOUBLES_EQUAL(-1.6, sim.target_point_m().x(), 1e-3);
  UNSIGNED_LONGS_EQUAL(0, sim.collisions());
  // The scripted e-stop reaches the firmware's input.
  sim.schedule_estop(h.clock.now_us() + 5000, 20000);
  minor_frame();
  CHECK(h.estop.read());
  CHECK(h.estop.activated_since_last_poll());
  for (int i = 0; i < 3; ++i) minor_frame();
  CHECK_FALSE(h.estop.read());
}

// A resumed mission's pose is in the mission frame, whose origin is the world's start pose.
TEST(SimBoard, APlacedRobotStandsAtTheSavedPoseFromTheWorldsStartAndACollidingOneIsRefused) {
  const std::string path = world_path("thesis_room");
  boticelli::firmware::Options options;
  options.world_file = path.c_str();
  board->settings().camera_fps = 5.0F;
  CHECK_TEXT(board->init(options, g_error, sizeof g_error), g_error);
  const boticelli::core::Pose2 start = board->world().start;
  const boticelli::core::Pose2 saved{0.5F, 0.2F, 0.3F};  // 0.5 m ahead, 0.2 m to the left
  CHECK_TEXT(board->place_robot(saved, g_error, sizeof g_error), g_error);
  const boticelli::core::Pose2 p = board->sim().true_pose();
  const boticelli::core::Point2 expected = boticelli::core::to_world(start, {0.5F, 0.2F});
  DOUBLES_EQUAL(expected.x_m, p.x_m, 1e-5);
  DOUBLES_EQUAL(expected.y_m, p.y_m, 1e-5);
  DOUBLES_EQUAL(std::remainder(start.yaw_rad + 0.3F, 6.2831853F), p.yaw_rad, 1e-5);
  // 1.2 m behind the start: on the south wall, refused with a reason; the robot stays.
  CHECK_FALSE(board->place_robot({-1.2F, 0.0F, 0.0F}, g_error, sizeof g_error));
  CHECK(std::strstr(g_error, "collides") != nullptr);
  DOUBLES_EQUAL(expected.x_m, board->sim().true_pose().x_m, 1e-5);
}

namespace {
void remove_truth_dir(const std::string& dir) {
  std::remove((dir + "/sim-world.truth").c_str());
  rmdir(dir.c_str());
}
}  // namespace

// The world outlives the firmware: a run killed while the robot drives leaves the world's
// state in its own file; the next run's board puts the robot there (not at the pose the
// firmware saved), lets it roll until the ODrives' watchdog stops it, and the motor
// controllers' wheel counters carry on from where they were.
TEST(SimBoard, ARestartedBoardPutsTheRobotWhereTheWorldLeftItRollingUntilTheWatchdogStopsIt) {
  const std::string dir = boticelli::test::temp_dir("truth");
  const std::string path = world_path("thesis_room");
  boticelli::firmware::Options options;
  options.world_file = path.c_str();
  options.state_dir = dir.c_str();
  board->settings().camera_fps = 1.0F;
  CHECK_TEXT(board->init(options, g_error, sizeof g_error), g_error);
  STRCMP_EQUAL((dir + "/sim-world.truth").c_str(), board->truth_path());
  hal::Hal& h = board->hal();
  CHECK(h.base.init());
  const std::uint32_t frame_us = board->config().minor_frame_us;
  for (int i = 0; i < 300; ++i) {  // 3 s: ready after 50 ms, then 0.2 m/s straight ahead
    h.base.update();
    h.base.set_velocity(0.2F, 0.0F);
    h.clock.sleep_until_us(h.clock.now_us() + frame_us);
  }
  const auto left = board->sim().physical_state();  // what the file holds now: "kill -9"
  CHECK(left.wheel_left_m_s > 0.19F);
  CHECK(left.wheel_left_m > 0.5);
  board = std::make_unique<boticelli::boards::sim::SimBoard>();  // the next run
  board->settings().camera_fps = 1.0F;
  CHECK_TEXT(board->init(options, g_error, sizeof g_error), g_error);
  CHECK_EQUAL(0.0, board->sim().physical_state().wheel_left_m);  // before the restore
  // The firmware believed itself at its start: the board goes by the world's file instead.
  CHECK_TEXT(board->place_robot({0.0F, 0.0F, 0.0F}, g_error, sizeof g_error), g_error);
  const auto now = board->sim().physical_state();
  // Rolled on for the watchdog's 0.2 s at 0.2 m/s, then coasted to rest with the axes idle
  // (v²/2a at the coasting deceleration): 0.04 + 0.1 m further, straight on.
  const auto& base = board->sim().params().base;
  const double v = left.wheel_left_m_s;
  const double expected = v * static_cast<double>(base.command_timeout_us) * 1e-6 +
                          v * v / (2.0 * static_cast<double>(base.coast_decel_m_s2));
  const double rolled = std::hypot(now.x_m - left.x_m, now.y_m - left.y_m);
  DOUBLES_EQUAL(0.14, expected, 0.005);
  DOUBLES_EQUAL(expected, rolled, 0.005);
  DOUBLES_EQUAL(left.yaw_rad, now.yaw_rad, 1e-6);
  CHECK_EQUAL(0.0F, now.wheel_left_m_s);
  CHECK_EQUAL(0.0F, now.wheel_right_m_s);
  DOUBLES_EQUAL(left.wheel_left_m + rolled, now.wheel_left_m, 1e-4);
  // A new firmware's base start does not reset the controllers' counters.
  CHECK(board->hal().base.init());
  const hal::Odometry o = board->hal().base.odometry();
  CHECK(o.wheels_known);
  DOUBLES_EQUAL(now.wheel_right_m, o.wheel_right_m, 0.0);
  board.reset();
  remove_truth_dir(dir);
}

// Without the world's own file (a state directory from before it was kept), or with the file
// of another world, the robot is put at the saved pose.
TEST(SimBoard, WithoutTheWorldsFileOrWithAnotherWorldsTheRobotGoesToTheSavedPose) {
  const std::string dir = boticelli::test::temp_dir("truth");
  boticelli::firmware::Options options;
  const std::string other = world_path("corridor");
  options.world_file = other.c_str();
  options.state_dir = dir.c_str();
  board->settings().camera_fps = 1.0F;
  CHECK_TEXT(board->init(options, g_error, sizeof g_error), g_error);
  board->hal().clock.sleep_until_us(10000);  // the corridor's state written
  const std::string path = world_path("thesis_room");
  options.world_file = path.c_str();
  for (int run = 0; run < 2; ++run) {
    board = std::make_unique<boticelli::boards::sim::SimBoard>();
    board->settings().camera_fps = 1.0F;
    CHECK_TEXT(board->init(options, g_error, sizeof g_error), g_error);
    if (run == 1) std::remove((dir + "/sim-world.truth").c_str());
    CHECK_TEXT(board->place_robot({0.5F, 0.2F, 0.3F}, g_error, sizeof g_error), g_error);
    const boticelli::core::Point2 expected =
        boticelli::core::to_world(board->world().start, {0.5F, 0.2F});
    DOUBLES_EQUAL(expected.x_m, board->sim().true_pose().x_m, 1e-5);
  }
  board.reset();
  remove_truth_dir(dir);
}

// Two slots written in turn: a record torn by the kill (its checksum wrong) leaves the one
// before it.
TEST(SimBoard, ATornNewestRecordOfTheWorldsFileFallsBackToTheOneBefore) {
  using boticelli::boards::sim::WorldTruthFile;
  const std::string dir = boticelli::test::temp_dir("truth");
  const std::string file = dir + "/sim-world.truth";
  WorldTruthFile truth;
  CHECK_TEXT(truth.open(file.c_str(), 77, g_error, sizeof g_error), g_error);
  boticelli::hal::sim::SimWorld::PhysicalState a, b, out;
  a.x_m = 1.25;
  b.x_m = 2.5;
  truth.record(a);
  truth.record(b);
  CHECK(WorldTruthFile::load(file.c_str(), 77, out, g_error, sizeof g_error) ==
        WorldTruthFile::Load::kLoaded);
  DOUBLES_EQUAL(2.5, out.x_m, 0.0);
  CHECK(WorldTruthFile::load(file.c_str(), 78, out, g_error, sizeof g_error) ==
        WorldTruthFile::Load::kOtherWorld);
  truth.close();
  // b went to slot 0 (sequence 2): flip a byte of its x.
  const int fd = ::open(file.c_str(), O_RDWR);
  CHECK(fd >= 0);
  const off_t at = static_cast<off_t>(offsetof(WorldTruthFile::Layout, slots) +
                                      offsetof(WorldTruthFile::Slot, values) + 7);
  unsigned char byte = 0;
  CHECK(::pread(fd, &byte, 1, at) == 1);
  byte ^= 0x01U;
  CHECK(::pwrite(fd, &byte, 1, at) == 1);
  ::close(fd);
  CHECK(WorldTruthFile::load(file.c_str(), 77, out, g_error, sizeof g_error) ==
        WorldTruthFile::Load::kLoaded);
  DOUBLES_EQUAL(1.25, out.x_m, 0.0);
  remove_truth_dir(dir);
}

namespace {
std::uint64_t host_monotonic_ns() {
  timespec ts{};
  clock_gettime(CLOCK_MONOTONIC, &ts);
  return static_cast<std::uint64_t>(ts.tv_sec) * 1000000000U +
         static_cast<std::uint64_t>(ts.tv_nsec);
}
}  // namespace

// The board's host clock is the firmware's: the simulator's rendering inside a camera poll
// (what a robot's camera does beside the firmware) is left out of its wall time as of its CPU
// time, and the clock still never goes back.
TEST(SimBoard, TheHostClockLeavesTheSimulatorsRenderingOutOfTheFirmwaresWallTime) {
  const std::string path = world_path("thesis_room");
  boticelli::firmware::Options options;
  options.world_file = path.c_str();
  board->settings().camera_fps = 5.0F;
  CHECK_TEXT(board->init(options, g_error, sizeof g_error), g_error);
  hal::Hal& h = board->hal();
  CHECK(h.camera.init());
  boticelli::firmware::HostClock& clock = *board->host_clock();
  const std::uint64_t booked_ns = board->sim().simulator_wall_ns();
  const std::uint64_t host_before_ns = host_monotonic_ns();
  const std::uint64_t before_ns = clock.monotonic_ns();
  hal::Frame frame;
  CHECK(h.camera.poll(frame) == hal::CameraPoll::kFrame);  // renders the first frame
  h.camera.release();
  const std::uint64_t after_ns = clock.monotonic_ns();
  const std::uint64_t host_after_ns = host_monotonic_ns();
  const std::uint64_t rendering_ns = board->sim().simulator_wall_ns() - booked_ns;
  CHECK(rendering_ns > 0U);
  CHECK(after_ns >= before_ns);
  CHECK(after_ns - before_ns <= host_after_ns - host_before_ns - rendering_ns);
  // A poll without a new frame renders nothing, and the clock moves on with the host's.
  const std::uint64_t quiet_ns = clock.monotonic_ns();
  CHECK(h.camera.poll(frame) == hal::CameraPoll::kNoFrame);
  CHECK_EQUAL(board->sim().simulator_wall_ns() - booked_ns, rendering_ns);
  CHECK(clock.monotonic_ns() >= quiet_ns);
}
