// Rpi4Board: wiring of the Linux HAL for the reference robot (see rpi4_board.h, board_config.h).
#include "rpi4_board.h"

#include "../console_mode.h"
#include "firmware/common/log.h"

#include <cstdio>

namespace boticelli::boards::rpi4 {
namespace {

hal_linux::BaseOdriveCanConfig base_config(const firmware::BoardConfig& c, const Rpi4Devices& d) {
  hal_linux::BaseOdriveCanConfig b;
  b.interface = d.can_interface.data();
  b.left_node_id = d.odrive_left_node_id;
  b.right_node_id = d.odrive_right_node_id;
  b.geometry.wheel_radius_m = c.wheel_radius_m;
  b.geometry.track_width_m = c.odometry_track_m();
  b.geometry.left_scale = c.odometry_left_scale();
  b.geometry.right_scale = c.odometry_right_scale();
  b.max_wheel_turns_s = d.odrive_max_wheel_turns_s;
  b.brake_timeout_ms = d.odrive_brake_timeout_ms;
  return b;
}

hal_linux::CameraV4l2Config camera_config(const firmware::BoardConfig& c, const Rpi4Devices& d) {
  hal_linux::CameraV4l2Config k;
  k.device = d.camera_device.data();
  k.width_px = c.camera_width_px;
  k.height_px = c.camera_height_px;
  return k;
}

// What one key cannot say: two wheels on one node, two signals on one line.
bool check_devices(const Rpi4Devices& d, char* error, std::size_t error_size) {
  if (d.odrive_left_node_id == d.odrive_right_node_id) {
    std::snprintf(error, error_size,
                  "configuration: base.left_node_id and base.right_node_id are both %u",
                  static_cast<unsigned>(d.odrive_left_node_id));
    return false;
  }
  if (d.estop_line == d.bumper_line || d.estop_line == d.led_line || d.bumper_line == d.led_line) {
    std::snprintf(error, error_size,
                  "configuration: gpio.estop_line, bumper_line and led_line must differ "
                  "(%u, %u, %u)",
                  d.estop_line, d.bumper_line, d.led_line);
    return false;
  }
  return true;
}

}  // namespace

Rpi4Board::Rpi4Board() : config_(make_config()) {}

bool Rpi4Board::reset_config(firmware::ConfigSchema& schema) {
  config_ = make_config();
  devices_ = Rpi4Devices{};
  return firmware::add_board_config_keys(schema, config_) &&
         add_device_config_keys(schema, devices_);
}

bool Rpi4Board::init(const firmware::Options& options, char* error, std::size_t error_size) {
  if (options.world_file != nullptr) {
    std::snprintf(error, error_size, "the rpi4 board drives real devices; --world is for sim");
    return false;
  }
  if (!check_devices(devices_, error, error_size)) return false;
  const Rpi4Devices& d = devices_;
  // A second run in the same process: the old drivers go first, users before what they use.
  hal_.reset();
  console_.reset();
  watchdog_.reset();
  status_led_.reset();
  bumper_.reset();
  estop_.reset();
  camera_.reset();
  base_.reset();
  pan_tilt_.reset();
  ptu_port_.reset();
  ptu_port_.emplace(hal_linux::SerialConfig{d.ptu_device.data(), d.ptu_baud});
  pan_tilt_.emplace(*ptu_port_, clock_);
  base_.emplace(base_config(config_, d), clock_);
  camera_.emplace(camera_config(config_, d), clock_);
  // Inputs fail safe: a line that cannot be read counts as pressed / in contact.
  estop_.emplace(hal_linux::GpioLineConfig{d.gpio_chip.data(), d.estop_line, d.estop_active_low,
                                           true, 10, false, "boticelli-estop"},
                 clock_, true);
  bumper_.emplace(hal_linux::GpioLineConfig{d.gpio_chip.data(), d.bumper_line, d.bumper_active_low,
                                            true, 10, false, "boticelli-bumper"},
                  clock_, true);
  status_led_.emplace(hal_linux::GpioLineConfig{d.gpio_chip.data(), d.led_line, d.led_active_low,
                                                false, 0, false, "boticelli-led"});
  watchdog_.emplace(hal_linux::WatchdogConfig{d.watchdog_device.data()});
  console_.emplace(d.console_device.data(), config_.console_baud);
  hal_.emplace(hal::Hal{*camera_, *pan_tilt_, *base_, *estop_, *bumper_, *status_led_, *console_,
                        clock_, *watchdog_});
  console_->select(console_mode(options.console), options.console_path);
  // The GPIO lines are requested here: without the e-stop line the robot must not run.
  if (!estop_->init()) {
    std::snprintf(error, error_size, "e-stop line: %s", estop_->error());
    return false;
  }
  if (!bumper_->init()) {
    std::snprintf(error, error_size, "bumper line: %s", bumper_->error());
    return false;
  }
  if (!status_led_->init()) {
    // The LED is only a signal: run without it.
    firmware::service_log().log(firmware::LogLevel::kWarn, "status LED unavailable (%s)",
                                status_led_->error());
  }
  return true;
}

}  // namespace boticelli::boards::rpi4
