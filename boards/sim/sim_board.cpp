// SimBoard: wiring of the sim HAL from board_config.h and the world file (see sim_board.h).
#include "sim_board.h"

#include "../console_mode.h"

#include <cerrno>
#include <cmath>
#include <cstdio>

#include "algo/core/angles.h"
#include "firmware/common/log.h"
#include "firmware/state/atomic_file.h"

namespace boticelli::boards::sim {
namespace {

using hal::sim::FaultDevice;
using hal::sim::FaultType;

// The state directory's faults at the firmware's file calls: off = unwritable (EACCES when
// the temporary file is created), stuck = a read-only file system (EROFS there), wrong = full
// (ENOSPC on a write), intermittent = I/O errors (EIO on a write) in its failing slots.
int storage_fault(firmware::StorageCall call, void* context) {
  const auto* world = static_cast<const hal::sim::SimWorld*>(context);
  FaultType type = FaultType::kOff;
  if (!world->faults().failing(FaultDevice::kStorage, type)) return 0;
  switch (type) {
    case FaultType::kOff:
      return call == firmware::StorageCall::kCreate ? EACCES : 0;
    case FaultType::kStuck:  // a read-only file system (a card remounted read-only)
      return call == firmware::StorageCall::kCreate ? EROFS : 0;
    case FaultType::kWrong:
      return call == firmware::StorageCall::kWrite ? ENOSPC : 0;
    case FaultType::kIntermittent:
      return call == firmware::StorageCall::kWrite ? EIO : 0;
    default:
      return 0;
  }
}

}  // namespace

SimBoard::SimBoard()
    : config_(make_config()),
      settings_(make_settings(config_, 1)),
      camera_(sim_, renderer_),
      pan_tilt_(sim_),
      base_(sim_),
      estop_(sim_),
      bumper_(sim_),
      status_led_(sim_),
      clock_(sim_),
      watchdog_(sim_),
      console_("/dev/tty", config_.console_baud),
      hal_{camera_, pan_tilt_, base_, estop_, bumper_, status_led_, console_, clock_, watchdog_} {}

SimBoard::~SimBoard() {
  firmware::set_storage_fault_hook(nullptr, nullptr);  // it points into this board's world
}

bool SimBoard::reset_config(firmware::ConfigSchema& schema) {
  config_ = make_config();
  return firmware::add_board_config_keys(schema, config_) && add_sim_config_keys(schema, sim_keys_);
}

bool SimBoard::init(const firmware::Options& options, char* error, std::size_t error_size) {
  const char* path =
      options.world_file != nullptr ? options.world_file : BOTICELLI_SIM_DEFAULT_WORLD;
  if (!hal::sim::load_world(path, world_, error, error_size)) return false;
  char why[200] = "";
  if (!textures_.build(world_, why, sizeof why)) {
    std::snprintf(error, error_size, "%s: %s", path, why);
    return false;
  }
  // The seed drives the sensor noise and the odometry noise; the rest is deterministic.
  settings_.render.seed = options.seed;
  settings_.physics.seed = options.seed;
  // The sim draws and drives the robot the firmware is told about (a --config FILE may have
  // changed it).
  const SimSettings geometry = make_settings(config_, options.seed);
  settings_.physics.base.robot_radius_m = geometry.physics.base.robot_radius_m;
  settings_.physics.base.robot_height_m = geometry.physics.base.robot_height_m;
  settings_.physics.base.track_width_m = geometry.physics.base.track_width_m;
  settings_.physics.base.odometry_track_scale = geometry.physics.base.odometry_track_scale;
  settings_.physics.base.odometry_left_scale = geometry.physics.base.odometry_left_scale;
  settings_.physics.base.odometry_right_scale = geometry.physics.base.odometry_right_scale;
  settings_.physics.base.max_speed_m_s = geometry.physics.base.max_speed_m_s;
  settings_.physics.base.max_turn_rate_rad_s = geometry.physics.base.max_turn_rate_rad_s;
  // The simulator's realism as the configuration file set it (unset keys keep the settings).
  if (!apply_sim_config(sim_keys_, settings_, why, sizeof why)) {
    std::snprintf(error, error_size, "configuration: %s", why);
    return false;
  }
  // The simulator's camera and rig are the configured ones with the optics' errors; the
  // firmware's stereo works with the configured ones.
  rig_.emplace(true_rig_params(config_, settings_.optics));
  if (!sim_.init(world_, *rig_, settings_.physics, why, sizeof why)) {
    std::snprintf(error, error_size, "%s: %s", path, why);
    return false;
  }
  if (!renderer_.init(world_, textures_, rig_->camera(), settings_.render, error, error_size)) {
    return false;
  }
  if (!camera_.setup(settings_.camera_fps, error, error_size)) return false;
  // Faults: --faults FILE, else the tests' default plan (empty unless a test set one).
  if (options.faults_file != nullptr) {
    if (!hal::sim::load_fault_plan(options.faults_file, plan_, error, error_size)) return false;
  } else {
    plan_ = default_faults_;
  }
  sim_.faults().set_plan(plan_);
  firmware::set_storage_fault_hook(storage_fault, &sim_);
  // The world's true state, beside the firmware's (a new mission: the robot at the world's
  // start, the file started afresh at the first step).
  truth_file_.close();
  truth_failed_ = false;
  truth_path_[0] = '\0';
  if (options.state_dir != nullptr) {
    std::snprintf(truth_path_.data(), truth_path_.size(), "%s/sim-world.truth", options.state_dir);
  }
  clock_.set_after_advance(record_world, this);
  console_.set_baud(config_.console_baud);
  console_.select(console_mode(options.console), options.console_path);
  clock_.set_speed(options.speed);
  outline_count_ = circle_count_ = 0;
  for (std::size_t i = 0; i < world_.collider_count; ++i) {
    const hal::sim::Collider& c = world_.colliders[i];
    if (c.circle) {
      circles_[circle_count_++] = {{c.centre_x_m, c.centre_y_m}, c.radius_m};
    } else {
      outlines_[outline_count_++] = {c.hull, c.hull_size};
    }
  }
  return true;
}

void SimBoard::record_world(void* context) {
  auto* board = static_cast<SimBoard*>(context);
  if (!board->truth_file_.is_open()) {
    if (board->truth_failed_ || board->truth_path_[0] == '\0') return;
    char why[600] = "";
    if (!board->truth_file_.open(board->truth_path_.data(), WorldTruthFile::world_id(board->world_),
                                 why, sizeof why)) {
      board->truth_failed_ = true;
      firmware::service_log().log(firmware::LogLevel::kWarn,
                                  "sim: the world's state is not kept (%s)", why);
      return;
    }
  }
  board->truth_file_.record(board->sim_.physical_state());
}

bool SimBoard::place_robot(const core::Pose2& mission_pose, char* error, std::size_t error_size) {
  // The mission's frame is the odometry frame of its first run, which started at the world's
  // start pose.
  const core::Pose2 saved = core::compose(world_.start, mission_pose);
  firmware::ServiceLog& slog = firmware::service_log();
  hal::sim::SimWorld::PhysicalState truth;
  char why[600] = "";
  if (truth_path_[0] == '\0') std::snprintf(why, sizeof why, "no --state directory");
  const WorldTruthFile::Load loaded =
      truth_path_[0] == '\0'
          ? WorldTruthFile::Load::kMissing
          : WorldTruthFile::load(truth_path_.data(), WorldTruthFile::world_id(world_), truth, why,
                                 sizeof why);
  if (loaded == WorldTruthFile::Load::kLoaded && sim_.restore_physical_state(truth)) {
    // Nobody commands the wheels while no firmware runs: they roll until the ODrives'
    // watchdog stops them, and the new firmware starts with them at rest.
    const std::uint64_t give_up_us = sim_.now_us() + 5000000U;
    while (sim_.now_us() < give_up_us) {
      const hal::sim::SimWorld::PhysicalState now = sim_.physical_state();
      if (now.wheel_left_m_s == 0.0F && now.wheel_right_m_s == 0.0F) break;
      sim_.advance_to(sim_.now_us() + 10000U);
    }
    const core::Pose2 here = sim_.true_pose();
    slog.log(firmware::LogLevel::kInfo,
             "sim: the robot stands where the world left it (%.3f, %.3f, %.3f); the saved pose is "
             "%.3f m and %.1f deg from there",
             static_cast<double>(here.x_m), static_cast<double>(here.y_m),
             static_cast<double>(here.yaw_rad),
             static_cast<double>(core::distance_m({here.x_m, here.y_m}, {saved.x_m, saved.y_m})),
             static_cast<double>(std::fabs(core::wrap_pi(here.yaw_rad - saved.yaw_rad))) * 180.0 /
                 3.14159265358979323846);
    record_world(this);
    return true;
  }
  if (loaded == WorldTruthFile::Load::kLoaded) {
    std::snprintf(why, sizeof why, "%s: its pose collides", truth_path_.data());
  }
  // No true state to go by (a state directory from before it was kept, another world's): the
  // robot is put where the firmware believed it was.
  slog.log(firmware::LogLevel::kWarn,
           "sim: no state of the simulated world (%s): the robot is put at the saved pose", why);
  if (sim_.teleport(saved)) return true;
  std::snprintf(error, error_size, "saved pose (%.2f, %.2f) m in the world collides",
                static_cast<double>(saved.x_m), static_cast<double>(saved.y_m));
  return false;
}

}  // namespace boticelli::boards::sim

namespace boticelli::boards::sim {

bool SimBoard::inject(std::string_view device, std::string_view type, double seconds,
                      firmware::TextBufferBase& reply) {
  FaultDevice d = FaultDevice::kCamera;
  FaultType t = FaultType::kOff;
  if (!hal::sim::parse_fault_device(device, d)) {
    reply.append(
        "unknown device (camera, ptu, axis-left, axis-right, can, estop, bumper, "
        "storage, main-loop, watchdog)");
    return false;
  }
  if (!hal::sim::parse_fault_type(type, t)) {
    reply.append("unknown fault type (off, stuck, garbage, wrong, slow, delayed, intermittent)");
    return false;
  }
  if (!hal::sim::fault_applies(d, t)) {
    reply.appendf("%s cannot be %s", hal::sim::fault_device_name(d), hal::sim::fault_type_name(t));
    return false;
  }
  const auto duration_us = static_cast<std::uint64_t>(std::llround(seconds * 1e6));
  if (d == FaultDevice::kMainLoop && t == FaultType::kStuck &&
      (duration_us == 0 || duration_us > hal::sim::kMaxStallUs)) {
    reply.append("a main-loop stall needs SECONDS, at most 60");
    return false;
  }
  const std::uint64_t now_us = sim_.now_us();
  if (!sim_.faults().inject(d, t, now_us, duration_us)) {
    reply.append("fault plan full");
    return false;
  }
  reply.appendf("fault %s %s seconds=", hal::sim::fault_device_name(d),
                hal::sim::fault_type_name(t));
  if (duration_us == 0) {
    reply.append("end");
  } else {
    reply.appendf("%.1f", seconds);
  }
  reply.appendf(" from_t_s=%.2f", static_cast<double>(now_us) * 1e-6);
  return true;
}

void SimBoard::describe_active(firmware::TextBufferBase& out) const {
  const hal::sim::FaultInjector& faults = sim_.faults();
  for (std::size_t i = 0; i < hal::sim::kFaultDeviceCount; ++i) {
    const auto d = static_cast<FaultDevice>(i);
    FaultType t = FaultType::kOff;
    if (!faults.active(d, t)) continue;
    out.appendf("fault %s %s since_t_s=%.2f until_t_s=", hal::sim::fault_device_name(d),
                hal::sim::fault_type_name(t),
                static_cast<double>(faults.active_since_us(d)) * 1e-6);
    if (faults.active_until_us(d) == UINT64_MAX) {
      out.append("end\r\n");
    } else {
      out.appendf("%.2f\r\n", static_cast<double>(faults.active_until_us(d)) * 1e-6);
    }
  }
}

}  // namespace boticelli::boards::sim
