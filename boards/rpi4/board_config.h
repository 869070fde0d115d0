// rpi4 board config: the reference robot's devices, lines, rates and capacities, as data (wiring in
// rpi4_board.cpp).
#pragma once

#include <cstdint>

#include "firmware/board.h"

namespace boticelli::boards::rpi4 {

// Where each device is on the reference robot (Raspberry Pi 4, Debian 12 arm64).
struct Rpi4Devices {
  // UVC webcam, V4L2 mmap streaming, YUYV 640x480.
  const char* camera_device = "/dev/video0";
  // FLIR / Directed Perception PTU-D46 on a USB-serial adapter, 9600 8N1.
  const char* ptu_device = "/dev/ttyUSB0";
  std::uint32_t ptu_baud = 9600;
  // Two ODrive axes on SocketCAN (bitrate set by boticelli-can0.service: 250 kbit/s).
  const char* can_interface = "can0";
  std::uint8_t odrive_left_node_id = 0;
  std::uint8_t odrive_right_node_id = 1;
  float odrive_max_wheel_turns_s = 8.0F;
  // GPIO on the 40-pin header (gpiochip0 = the BCM2711's lines, numbered as BCM GPIOs).
  const char* gpio_chip = "gpiochip0";
  unsigned estop_line = 17;       // pin 11: e-stop switch to GND, normally closed
  bool estop_active_low = false;  // NC switch to GND: the line goes high (pulled up) when pressed
  unsigned bumper_line = 27;      // pin 13: bumper microswitches to GND, normally open
  bool bumper_active_low = true;
  unsigned led_line = 22;  // pin 15: status LED through 330 Ω to GND
  bool led_active_low = false;
  // Console UART on pins 8/10 (GPIO 14/15), 115200 8N1 (enable_uart=1, no serial getty).
  const char* console_device = "/dev/ttyAMA0";
  // Hardware watchdog of the BCM2711 (bcm2835_wdt; max timeout about 15 s).
  const char* watchdog_device = "/dev/watchdog0";
};

inline constexpr Rpi4Devices kDevices{};

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
  c.watchdog_timeout_ms = 5000;  // /dev/watchdog; systemd's WatchdogSec=3s acts first
  c.background_units_per_slice = 0;
  c.checkpoint_period_ms = 1000;
  return c;
}

}  // namespace boticelli::boards::rpi4
