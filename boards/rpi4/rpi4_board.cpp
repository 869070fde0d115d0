// Rpi4Board: wiring of the Linux HAL for the reference robot (see rpi4_board.h, board_config.h).
#include "rpi4_board.h"

#include "../console_mode.h"
#include "firmware/log.h"

#include <cstdio>

namespace boticelli::boards::rpi4 {
namespace {

hal_linux::BaseOdriveCanConfig base_config(const firmware::BoardConfig& c) {
  hal_linux::BaseOdriveCanConfig b;
  b.interface = kDevices.can_interface;
  b.left_node_id = kDevices.odrive_left_node_id;
  b.right_node_id = kDevices.odrive_right_node_id;
  b.geometry.wheel_radius_m = c.wheel_radius_m;
  b.geometry.track_width_m = c.track_width_m;
  b.max_wheel_turns_s = kDevices.odrive_max_wheel_turns_s;
  return b;
}

hal_linux::CameraV4l2Config camera_config(const firmware::BoardConfig& c) {
  hal_linux::CameraV4l2Config k;
  k.device = kDevices.camera_device;
  k.width_px = c.camera_width_px;
  k.height_px = c.camera_height_px;
  return k;
}

}  // namespace

Rpi4Board::Rpi4Board()
    : config_(make_config()),
      ptu_port_(hal_linux::SerialConfig{kDevices.ptu_device, kDevices.ptu_baud}),
      pan_tilt_(ptu_port_, clock_),
      base_(base_config(config_), clock_),
      camera_(camera_config(config_), clock_),
      // Inputs fail safe: a line that cannot be read counts as pressed / in contact.
      estop_({kDevices.gpio_chip, kDevices.estop_line, kDevices.estop_active_low, true, 10, false,
              "boticelli-estop"},
             clock_, true),
      bumper_({kDevices.gpio_chip, kDevices.bumper_line, kDevices.bumper_active_low, true, 10,
               false, "boticelli-bumper"},
              clock_, true),
      status_led_({kDevices.gpio_chip, kDevices.led_line, kDevices.led_active_low, false, 0, false,
                   "boticelli-led"}),
      watchdog_(hal_linux::WatchdogConfig{kDevices.watchdog_device}),
      console_(kDevices.console_device, config_.console_baud),
      hal_{camera_, pan_tilt_, base_, estop_, bumper_, status_led_, console_, clock_, watchdog_} {}

bool Rpi4Board::init(const firmware::Options& options, char* error, std::size_t error_size) {
  if (options.world_file != nullptr) {
    std::snprintf(error, error_size, "the rpi4 board drives real devices; --world is for sim");
    return false;
  }
  console_.select(console_mode(options.console), options.console_path);
  // The GPIO lines are requested here: without the e-stop line the robot must not run.
  if (!estop_.init()) {
    std::snprintf(error, error_size, "e-stop line: %s", estop_.error());
    return false;
  }
  if (!bumper_.init()) {
    std::snprintf(error, error_size, "bumper line: %s", bumper_.error());
    return false;
  }
  if (!status_led_.init()) {
    // The LED is only a signal: run without it.
    firmware::service_log().log(firmware::LogLevel::kWarn, "status LED unavailable (%s)",
                                status_led_.error());
  }
  return true;
}

}  // namespace boticelli::boards::rpi4
