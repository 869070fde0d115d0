// Rpi4Board: the Raspberry Pi 4 reference robot — Linux HAL drivers wired from board_config.h.
#pragma once

#include <cstddef>
#include <optional>

#include "board_config.h"
#include "firmware/app/board.h"
#include "hal/hal.h"
#include "hal/linux/console_port.h"
#include "hal/linux/base_odrive_can.h"
#include "hal/linux/camera_v4l2.h"
#include "hal/linux/clock_posix.h"
#include "hal/linux/gpio_gpiod.h"
#include "hal/linux/pan_tilt_ptu46.h"
#include "hal/linux/serial_termios.h"
#include "hal/linux/watchdog_linux.h"

namespace boticelli::boards::rpi4 {

// One static instance (main.cpp). reset_config() binds the configuration file's keys to the
// defaults of board_config.h; init() builds the drivers from the result, picks the console
// and requests the GPIO lines (without its e-stop line the robot must not run); the
// firmware then calls init()/open() of the camera, PTU, base and console.
class Rpi4Board final : public firmware::Board {
 public:
  Rpi4Board();
  const firmware::BoardInfo& info() const override { return kInfo; }
  const firmware::BoardConfig& config() const override { return config_; }
  bool reset_config(firmware::ConfigSchema& schema) override;
  const char* default_config_path() const override { return "/etc/boticelli/boticelli.conf"; }
  bool init(const firmware::Options& options, char* error, std::size_t error_size) override;
  hal::Hal& hal() override { return *hal_; }

 private:
  static constexpr firmware::BoardInfo kInfo{"rpi4", "Raspberry Pi 4 reference robot", false};

  // The drivers are built in init() from the configured values (reset_config() and the
  // file), in declaration order; the Hal bag last, as it refers to them.
  firmware::BoardConfig config_;
  Rpi4Devices devices_;
  hal_linux::ClockPosix clock_;
  std::optional<hal_linux::SerialTermios> ptu_port_;
  std::optional<hal_linux::PanTiltPtu46> pan_tilt_;
  std::optional<hal_linux::BaseOdriveCan> base_;
  std::optional<hal_linux::CameraV4l2> camera_;
  std::optional<hal_linux::DigitalInGpiod> estop_;
  std::optional<hal_linux::DigitalInGpiod> bumper_;
  std::optional<hal_linux::DigitalOutGpiod> status_led_;
  std::optional<hal_linux::WatchdogLinux> watchdog_;
  std::optional<hal_linux::ConsolePort> console_;
  std::optional<hal::Hal> hal_;
};

}  // namespace boticelli::boards::rpi4
