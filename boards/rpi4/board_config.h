// rpi4 board config: the reference robot's devices, lines, rates and capacities, as data (wiring in
// rpi4_board.cpp); these are the defaults /etc/boticelli/boticelli.conf may change.
#pragma once

#include <cstdint>

#include "firmware/app/board.h"
#include "firmware/app/config_file.h"

namespace boticelli::boards::rpi4 {

// Where each device is on the reference robot (Raspberry Pi 4, Debian 12 arm64).
struct Rpi4Devices {
  // UVC webcam, V4L2 mmap streaming, YUYV 640x480.
  firmware::DeviceName camera_device = {"/dev/video0"};
  // FLIR / Directed Perception PTU-D46 on a USB-serial adapter, 9600 8N1.
  firmware::DeviceName ptu_device = {"/dev/ttyUSB0"};
  std::uint32_t ptu_baud = 9600;
  // Two ODrive axes on SocketCAN (bitrate set by boticelli-can0.service: 250 kbit/s).
  firmware::DeviceName can_interface = {"can0"};
  std::uint8_t odrive_left_node_id = 0;
  std::uint8_t odrive_right_node_id = 1;
  float odrive_max_wheel_turns_s = 8.0F;
  // A requested stop brakes in closed loop and idles the axes at rest, or after this [ms].
  std::uint32_t odrive_brake_timeout_ms = 500;
  // GPIO on the 40-pin header (gpiochip0 = the BCM2711's lines, numbered as BCM GPIOs).
  firmware::DeviceName gpio_chip = {"gpiochip0"};
  std::uint32_t estop_line = 17;   // pin 11: e-stop switch to GND, normally closed
  bool estop_active_low = false;   // NC switch to GND: the line goes high (pulled up) when pressed
  std::uint32_t bumper_line = 27;  // pin 13: bumper microswitches to GND, normally open
  bool bumper_active_low = true;
  std::uint32_t led_line = 22;  // pin 15: status LED through 330 Ω to GND
  bool led_active_low = false;
  // Console UART on pins 8/10 (GPIO 14/15), 115200 8N1 (enable_uart=1, no serial getty).
  firmware::DeviceName console_device = {"/dev/ttyAMA0"};
  // Hardware watchdog of the BCM2711 (bcm2835_wdt; max timeout about 15 s).
  firmware::DeviceName watchdog_device = {"/dev/watchdog0"};
};

// The configuration file's keys for the devices (besides add_board_config_keys()), bound to
// `d`. CAN node ids are 6 bits (CAN Simple: id = node << 5 | cmd), GPIO offsets those of
// the BCM2711's 58 lines.
inline bool add_device_config_keys(firmware::ConfigSchema& s, Rpi4Devices& d) {
  using firmware::ConfigKey;
  return s.add(ConfigKey::path("camera", "device", d.camera_device)) &&
         s.add(ConfigKey::path("ptu", "device", d.ptu_device)) &&
         s.add(ConfigKey::baud("ptu", "baud", d.ptu_baud)) &&
         s.add(ConfigKey::interface_name("base", "can_interface", d.can_interface)) &&
         s.add(ConfigKey::whole("base", "left_node_id", d.odrive_left_node_id, 0, 63)) &&
         s.add(ConfigKey::whole("base", "right_node_id", d.odrive_right_node_id, 0, 63)) &&
         s.add(ConfigKey::number("base", "max_wheel_turns_s", d.odrive_max_wheel_turns_s, 0.1,
                                 50.0)) &&
         s.add(ConfigKey::whole("base", "brake_timeout_ms", d.odrive_brake_timeout_ms, 50, 5000)) &&
         s.add(ConfigKey::interface_name("gpio", "chip", d.gpio_chip)) &&
         s.add(ConfigKey::whole("gpio", "estop_line", d.estop_line, 0, 57)) &&
         s.add(ConfigKey::flag_key("gpio", "estop_active_low", d.estop_active_low)) &&
         s.add(ConfigKey::whole("gpio", "bumper_line", d.bumper_line, 0, 57)) &&
         s.add(ConfigKey::flag_key("gpio", "bumper_active_low", d.bumper_active_low)) &&
         s.add(ConfigKey::whole("gpio", "led_line", d.led_line, 0, 57)) &&
         s.add(ConfigKey::flag_key("gpio", "led_active_low", d.led_active_low)) &&
         s.add(ConfigKey::path("console", "device", d.console_device)) &&
         s.add(ConfigKey::path("watchdog", "device", d.watchdog_device));
}

// The robot itself (thesis §3.4 and App. A for the camera arm), rates and capacities.
inline firmware::BoardConfig make_config() {
  firmware::BoardConfig c;
  c.camera_width_px = 640;
  c.camera_height_px = 480;
  c.focal_px = 600.0F;
  c.principal_x_px = 320.0F;
  c.principal_y_px = 240.0F;
  c.ptu_height_m = 0.6F;
  c.lever_m = 0.21F;
  c.tilt_step_rad = 0.134390352F;  // Φ = 7.7°
  c.robot_radius_m = 0.25F;
  c.robot_height_m = 0.8F;
  c.wheel_radius_m = 0.08F;
  c.track_width_m = 0.40F;
  c.max_speed_m_s = 0.3F;
  c.max_turn_rate_rad_s = 0.8F;
  c.minor_frame_us = 10000;  // 100 Hz executive
  c.console_baud = 115200;
  c.telemetry_period_ms = 1000;
  c.realtime = true;  // mlockall, prefaulted stack, SCHED_FIFO 50
  c.fifo_priority = 50;
  // /dev/watchdog: longer than systemd's whole restart chain after a hang (WatchdogSec 2 s,
  // TimeoutAbortSec 2 s, RestartSec 1 s, start-up to the watchdog's open about 3 s), so the
  // service restarts before the board resets (docs/flashing.md, "Watchdogs"). The range a
  // configuration may set: that chain (8 s) plus 2 s to spare, up to the most the BCM2711's
  // watchdog counts (bcm2835_wdt: 15 s). test_service_unit checks the bottom against the unit.
  c.device_retry_s = 30.0F;  // the unit's start limit assumes it (test_service_unit)
  c.watchdog_enabled = true;
  c.watchdog_timeout_ms = 12000;
  c.watchdog_min_timeout_ms = 10000;
  c.watchdog_max_timeout_ms = 15000;
  c.background_units_per_slice = 0;
  c.checkpoint_period_ms = 1000;
  return c;
}

}  // namespace boticelli::boards::rpi4
