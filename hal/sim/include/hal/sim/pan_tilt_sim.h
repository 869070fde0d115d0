// PanTiltSim: a PTU-D46-like unit on SimWorld — quantised positions, speed and acceleration
// limits, pan/tilt limits, moves that take simulated time, errors on out-of-limit commands.
#pragma once

#include "hal/pan_tilt.h"
#include "hal/sim/sim_world.h"

namespace boticelli::hal::sim {

class PanTiltSim final : public PanTilt {
 public:
  explicit PanTiltSim(SimWorld& world) : world_(world) {}
  bool init() override;
  void update() override;
  bool move_to(float pan_rad, float tilt_rad) override;
  void halt() override;
  PanTiltState state() const override;
  PanTiltLimits limits() const override { return world_.params().ptu.limits; }
  bool set_speed(float pan_rad_s, float tilt_rad_s) override;
  const char* error() const override { return error_; }

 private:
  SimWorld& world_;
  bool initialising_ = false;
  bool ready_ = false;
  char error_[96] = {};
};

}  // namespace boticelli::hal::sim
