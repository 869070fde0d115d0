// SimBoard: the host simulation board — sim HAL devices on one SimWorld loaded from --world.
#pragma once

#include <array>
#include <cstddef>
#include <optional>
#include <span>
#include <string_view>

#include "board_config.h"
#include "sim_config.h"
#include "world_truth_file.h"
#include "firmware/app/board.h"
#include "hal/hal.h"
#include "hal/linux/console_port.h"
#include "hal/sim/base_sim.h"
#include "hal/sim/camera_sim.h"
#include "hal/sim/clock_sim.h"
#include "hal/sim/fault_plan.h"
#include "hal/sim/gpio_sim.h"
#include "hal/sim/pan_tilt_sim.h"
#include "hal/sim/renderer.h"
#include "hal/sim/sim_world.h"
#include "hal/sim/textures.h"
#include "hal/sim/watchdog_sim.h"
#include "hal/sim/world.h"

namespace boticelli::boards::sim {

// One static instance (it holds the world and its textures, a few MB): main.cpp's, or a
// test's. init() loads the world (--world, else the shipped thesis room), builds textures,
// rig, physics and renderer; the firmware then calls init()/open() of each device. The
// sim-only accessors give tests the ground truth the firmware never sees.
class SimBoard final : public firmware::Board,
                       public firmware::TruthSource,
                       public firmware::FaultInjection {
 public:
  SimBoard();
  ~SimBoard() override;
  SimBoard(const SimBoard&) = delete;
  SimBoard& operator=(const SimBoard&) = delete;
  const firmware::BoardInfo& info() const override { return kInfo; }
  const firmware::BoardConfig& config() const override { return config_; }
  // The keys every board has (add_board_config_keys) and the simulator's realism ([sim],
  // sim_config.h); no device keys, no default file: the sim board reads a configuration only
  // with --config FILE.
  bool reset_config(firmware::ConfigSchema& schema) override;
  bool init(const firmware::Options& options, char* error, std::size_t error_size) override;
  hal::Hal& hal() override { return hal_; }
  const firmware::TruthSource* truth() const override { return this; }
  firmware::HostClock* host_clock() override { return &host_clock_; }
  firmware::FaultInjection* fault_injection() override { return this; }
  // FaultInjection: the console's `fault DEVICE TYPE [SECONDS]`, into the world's injector.
  bool inject(std::string_view device, std::string_view type, double seconds,
              firmware::TextBufferBase& reply) override;
  void describe_active(firmware::TextBufferBase& out) const override;
  // A resumed mission: the robot stands where the simulated world's own state file
  // (`sim-world.truth` in --state DIR, written as the world moves) says the last run left it,
  // rolling on as the ODrives' watchdog lets it; `mission_pose` is only compared with that. A
  // state directory without that file (or one of another world) puts the robot at
  // `mission_pose`, with a warning.
  bool place_robot(const core::Pose2& mission_pose, char* error, std::size_t error_size) override;
  // The file the world's true state goes to ("" without --state).
  const char* truth_path() const { return truth_path_.data(); }
  // TruthSource: the simulator's own pose and target (trace, target error).
  core::Pose2 robot_pose() const override { return sim_.true_pose(); }
  core::Pose2 odometry_origin() const override { return sim_.odometry_origin(); }
  Eigen::Vector3f target_m() const override { return sim_.target_point_m(); }
  std::span<const std::span<const core::Point2>> outlines() const override {
    return {outlines_.data(), outline_count_};
  }
  std::span<const firmware::SnapshotCircle> circles() const override {
    return {circles_.data(), circle_count_};
  }

  // ---- sim-only: ground truth and scripting (valid after a successful init) ----
  hal::sim::SimWorld& sim() { return sim_; }  // true pose, collisions, target, e-stop script
  const hal::sim::World& world() const { return world_; }
  // The target taken away (its paper removed from the wall): from the next frame on the
  // renderer draws its face as the surface's own. The world's target point stays, the truth
  // the trace is checked against; the next init() loads the world as its file has it.
  void remove_target() { world_.surfaces[world_.target_surface].target_face = hal::sim::kNoFace; }
  hal::sim::CameraSim& camera() { return camera_; }  // depth of the last frame, its pose
  const hal::sim::Renderer& renderer() const { return renderer_; }
  // The rig the simulator draws and moves: the configured one with [sim]'s optics errors.
  const stereo::RigModel& rig() const { return *rig_; }
  // Settings used by the next init() (tests may change noise, rates, physics).
  SimSettings& settings() { return settings_; }
  // The fault plan the next init() starts with when there is no --faults FILE (tests).
  hal::sim::FaultPlan& default_faults() { return default_faults_; }

 private:
  static constexpr firmware::BoardInfo kInfo{"sim", "host simulation board", true};

  // The POSIX clocks, less the simulator's own work inside device calls (the camera's
  // rendering, SimWorld::simulator_cpu_ns and simulator_wall_ns): the thread CPU time and the
  // wall time the executive sees are the firmware's. The wall clock stands still while the
  // simulator renders, as a robot's camera works beside the firmware; everything else on the
  // host (preemption, other processes) stays in it.
  class SimHostClock final : public firmware::HostClock {
   public:
    explicit SimHostClock(const hal::sim::SimWorld& world) : world_(world) {}
    std::uint64_t monotonic_ns() override {
      const std::uint64_t wall_ns = host_.monotonic_ns();
      const std::uint64_t simulator_ns = world_.simulator_wall_ns();
      return wall_ns > simulator_ns ? wall_ns - simulator_ns : 0;
    }
    std::uint64_t thread_cpu_ns() override {
      const std::uint64_t cpu_ns = host_.thread_cpu_ns();
      const std::uint64_t simulator_ns = world_.simulator_cpu_ns();
      return cpu_ns > simulator_ns ? cpu_ns - simulator_ns : 0;
    }

   private:
    firmware::PosixHostClock host_;
    const hal::sim::SimWorld& world_;
  };

  firmware::BoardConfig config_;
  SimSettings settings_;
  SimConfigKeys sim_keys_;  // what the configuration file set in [sim]
  hal::sim::World world_;
  hal::sim::TextureBank textures_;
  std::optional<stereo::RigModel> rig_;
  hal::sim::SimWorld sim_;
  hal::sim::Renderer renderer_;
  hal::sim::CameraSim camera_;
  hal::sim::PanTiltSim pan_tilt_;
  hal::sim::BaseSim base_;
  hal::sim::EstopInputSim estop_;
  hal::sim::BumperInputSim bumper_;
  hal::sim::LedOutputSim status_led_;
  hal::sim::ClockSim clock_;
  SimHostClock host_clock_{sim_};
  hal::sim::WatchdogSim watchdog_;
  hal_linux::ConsolePort console_;
  hal::Hal hal_;
  static void record_world(void* board);
  WorldTruthFile truth_file_;
  std::array<char, 512> truth_path_{};
  bool truth_failed_ = false;  // the file could not be opened: said once, not tried again
  hal::sim::FaultPlan plan_;
  hal::sim::FaultPlan default_faults_;
  std::array<std::span<const core::Point2>, hal::sim::kMaxColliders> outlines_{};
  std::size_t outline_count_ = 0;
  std::array<firmware::SnapshotCircle, hal::sim::kMaxColliders> circles_{};
  std::size_t circle_count_ = 0;
};

}  // namespace boticelli::boards::sim
