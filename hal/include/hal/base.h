// Base: non-blocking differential-drive base (ODrive over CAN, or the simulated base).
#pragma once

#include <cstdint>

#include "hal/noncopyable.h"

namespace boticelli::hal {

// Pose and velocity from wheel odometry, in the odometry frame fixed at init().
struct Odometry {
  double x_m = 0.0;
  double y_m = 0.0;
  double yaw_rad = 0.0;      // counter-clockwise from +x
  float v_m_s = 0.0F;        // forward speed
  float omega_rad_s = 0.0F;  // yaw rate
  std::uint64_t timestamp_us = 0;
  // Each wheel's travel as its motor controller counts it [m], forward positive: counted
  // since the controller powered up, so it carries on across a restart of the firmware (a
  // resumed mission dead-reckons the robot's motion while no firmware ran from it). Unknown
  // until the controller has reported it.
  bool wheels_known = false;
  double wheel_left_m = 0.0;
  double wheel_right_m = 0.0;
};

enum class BaseHealth : std::uint8_t {
  kStarting,  // start-up sequence in progress
  kReady,     // accepting velocity commands
  kStopped,   // stopped by stop(), a fault or a lost link; see error()
};

class Base : private NonCopyable {
 public:
  virtual ~Base() = default;
  // Starts the start-up sequence; update() completes it without blocking.
  virtual bool init() = 0;
  // Services the device each frame: re-sends the setpoint, reads feedback. Returns at once.
  virtual void update() = 0;
  // Velocity setpoint [m/s, rad/s], held until changed; ignored unless kReady.
  virtual void set_velocity(float v_m_s, float omega_rad_s) = 0;
  // Immediate stop (e-stop path); the base stays stopped until resume().
  virtual void stop() = 0;
  // Leaves kStopped after stop() or a cleared fault; false if it cannot.
  virtual bool resume() = 0;
  virtual BaseHealth health() const = 0;
  virtual Odometry odometry() const = 0;
  virtual const char* error() const { return ""; }
  // The last gasp of a dying process, from a fatal signal's handler (SIGSEGV, SIGABRT, ...):
  // commands the wheels to brake to a stop. Async-signal-safe: no lock, no allocation, no
  // state change, nothing but write(2) of what init() prepared. The default does nothing (a
  // base the process's death stops by itself).
  virtual void last_gasp_stop() noexcept {}
};

}  // namespace boticelli::hal
