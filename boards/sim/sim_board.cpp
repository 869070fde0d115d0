// SimBoard: wiring of the sim HAL from board_config.h and the world file (see sim_board.h).
#include "sim_board.h"

#include "../console_mode.h"

#include <cstdio>

namespace boticelli::boards::sim {

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

bool SimBoard::reset_config(firmware::ConfigSchema& schema) {
  config_ = make_config();
  return firmware::add_board_config_keys(schema, config_);
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
  settings_.physics.base.max_speed_m_s = geometry.physics.base.max_speed_m_s;
  settings_.physics.base.max_turn_rate_rad_s = geometry.physics.base.max_turn_rate_rad_s;
  rig_.emplace(make_rig_params(config_));
  if (!sim_.init(world_, *rig_, settings_.physics, why, sizeof why)) {
    std::snprintf(error, error_size, "%s: %s", path, why);
    return false;
  }
  if (!renderer_.init(world_, textures_, rig_->camera(), settings_.render, error, error_size)) {
    return false;
  }
  if (!camera_.setup(settings_.camera_fps, error, error_size)) return false;
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

bool SimBoard::place_robot(const core::Pose2& mission_pose, char* error, std::size_t error_size) {
  // The mission's frame is the odometry frame of its first run, which started at the world's
  // start pose.
  const core::Pose2 world = core::compose(world_.start, mission_pose);
  if (sim_.teleport(world)) return true;
  std::snprintf(error, error_size, "saved pose (%.2f, %.2f) m in the world collides",
                static_cast<double>(world.x_m), static_cast<double>(world.y_m));
  return false;
}

}  // namespace boticelli::boards::sim
