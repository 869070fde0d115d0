// The configuration file's keys every board has, bound to its BoardConfig (see config_file.h).
#include "algo/image/low_res_frame.h"
#include "firmware/app/board.h"
#include "firmware/app/config_file.h"

namespace boticelli::firmware {

bool add_board_config_keys(ConfigSchema& s, BoardConfig& c) {
  // The watchdog's range is the board's (BoardConfig::watchdog_min/max_timeout_ms); 0 no
  // longer switches it off, `enabled = false` does.
  ConfigKey watchdog_timeout =
      ConfigKey::whole("watchdog", "timeout_ms", c.watchdog_timeout_ms, c.watchdog_min_timeout_ms,
                       c.watchdog_max_timeout_ms);
  watchdog_timeout.below_min_note =
      "shorter, the hardware watchdog would reset the board before systemd restarts a hung "
      "firmware (to switch the watchdog off: enabled = false)";
  watchdog_timeout.above_max_note = "longer than the board's watchdog can count";
  // Full resolution is downsampled by 4 (rig.h) into at most LowResFrame's 320x240; YUYV
  // needs an even width, the 4x4 blocks whole ones.
  constexpr std::uint32_t kMaxWidth = image::LowResFrame::kMaxWidth * 4;
  constexpr std::uint32_t kMaxHeight = image::LowResFrame::kMaxHeight * 4;
  return s.add(ConfigKey::whole("camera", "width_px", c.camera_width_px, 160, kMaxWidth, 8)) &&
         s.add(ConfigKey::whole("camera", "height_px", c.camera_height_px, 120, kMaxHeight, 4)) &&
         s.add(ConfigKey::number("camera", "focal_px", c.focal_px, 50.0, 5000.0)) &&
         s.add(ConfigKey::number("camera", "principal_x_px", c.principal_x_px, 0.0, kMaxWidth)) &&
         s.add(ConfigKey::number("camera", "principal_y_px", c.principal_y_px, 0.0, kMaxHeight)) &&
         // OpenCV's distortion coefficients; wider than any webcam's calibration needs.
         s.add(ConfigKey::number("camera", "k1", c.k1, -1.0, 1.0)) &&
         s.add(ConfigKey::number("camera", "k2", c.k2, -1.0, 1.0)) &&
         s.add(ConfigKey::number("camera", "p1", c.p1, -0.1, 0.1)) &&
         s.add(ConfigKey::number("camera", "p2", c.p2, -0.1, 0.1)) &&
         s.add(ConfigKey::number("camera", "k3", c.k3, -1.0, 1.0)) &&
         s.add(ConfigKey::number("ptu", "height_m", c.ptu_height_m, 0.1, 2.0)) &&
         s.add(ConfigKey::number("ptu", "lever_m", c.lever_m, 0.01, 1.0)) &&
         s.add(ConfigKey::number("ptu", "support_angle_rad", c.support_angle_rad, -1.0, 1.0)) &&
         s.add(ConfigKey::number("ptu", "tilt_step_rad", c.tilt_step_rad, 0.01, 0.5)) &&
         s.add(ConfigKey::number("robot", "radius_m", c.robot_radius_m, 0.05, 1.0)) &&
         s.add(ConfigKey::number("robot", "height_m", c.robot_height_m, 0.1, 2.5)) &&
         s.add(ConfigKey::number("base", "wheel_radius_m", c.wheel_radius_m, 0.01, 0.5)) &&
         s.add(ConfigKey::number("base", "track_width_m", c.track_width_m, 0.05, 2.0)) &&
         s.add(ConfigKey::number("base", "odometry_track_scale", c.odometry_track_scale, 0.8,
                                 1.25)) &&
         s.add(ConfigKey::number("base", "odometry_diameter_ratio", c.odometry_diameter_ratio, 0.9,
                                 1.1)) &&
         s.add(ConfigKey::number("base", "max_speed_m_s", c.max_speed_m_s, 0.01, 2.0)) &&
         s.add(
             ConfigKey::number("base", "max_turn_rate_rad_s", c.max_turn_rate_rad_s, 0.05, 5.0)) &&
         s.add(ConfigKey::baud("console", "baud", c.console_baud)) &&
         s.add(
             ConfigKey::whole("console", "telemetry_period_ms", c.telemetry_period_ms, 0, 60000)) &&
         s.add(ConfigKey::number("faults", "retry_s", c.device_retry_s, 1.0, 600.0)) &&
         s.add(ConfigKey::flag_key("watchdog", "enabled", c.watchdog_enabled)) &&
         s.add(watchdog_timeout) &&
         s.add(ConfigKey::flag_key("mission", "thesis_planner", c.thesis_planner)) &&
         s.add(ConfigKey::flag_key("mission", "register_looks", c.register_looks)) &&
         s.add(ConfigKey::number("mission", "floor_range_error", c.floor_range_error, 0.0, 0.3)) &&
         s.add(
             ConfigKey::flag_key("mission", "stereo_self_calibration", c.stereo_self_calibration));
}

}  // namespace boticelli::firmware
