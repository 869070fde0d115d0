// BaseSim: the differential-drive base with an ODrive-like velocity interface, on SimWorld.
#pragma once

#include "hal/base.h"
#include "hal/sim/sim_world.h"

namespace boticelli::hal::sim {

// Start-up takes BaseParams::startup_us of simulated time (closed-loop entry); a collision
// stops the base at once (health kStopped, error "collision with 'model'") until resume().
// stop() brakes the wheels in closed loop, as the ODrive driver's controlled stop does.
// Injected axis and CAN faults stop it at the next update() with the ODrive driver's words
// and idle the axes (the wheels coast), and resume() fails while they last.
class BaseSim final : public Base {
 public:
  explicit BaseSim(SimWorld& world) : world_(world) {}
  bool init() override {
    world_.base_start();
    return true;
  }
  void update() override { world_.base_update(); }
  void set_velocity(float v_m_s, float omega_rad_s) override {
    world_.base_set_velocity(v_m_s, omega_rad_s);
  }
  void stop() override { world_.base_stop("stopped", SimWorld::StopKind::kBrake); }
  bool resume() override { return world_.base_resume(); }
  BaseHealth health() const override { return world_.base_health(); }
  Odometry odometry() const override { return world_.odometry(); }
  const char* error() const override { return world_.base_error(); }

 private:
  SimWorld& world_;
};

}  // namespace boticelli::hal::sim
