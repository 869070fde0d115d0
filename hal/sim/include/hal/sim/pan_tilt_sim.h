// PanTiltSim: a PTU-D46-like unit on SimWorld — quantised positions, speed and acceleration
// limits, pan/tilt limits, moves that take simulated time, errors on out-of-limit commands.
#pragma once

#include "hal/pan_tilt.h"
#include "hal/sim/sim_world.h"

namespace boticelli::hal::sim {

// Injected faults (FaultDevice::kPtu): off = the unit stops answering (a fault 0.5 s later,
// axes stopped), stuck = a move never ends, garbage = garbled replies (a fault at once),
// wrong = every command answered `!`, slow = a tenth of the speed, delayed = each move
// starts 0.3 s late, intermittent = garbled replies in its failing slots.
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
  static constexpr std::uint64_t kSilenceUs = 500000;  // no reply for this long: a fault
  static constexpr std::uint64_t kDelayUs = 300000;    // a delayed reply
  // The unit's fault now, with its reason in error_; false while it answers.
  bool faulted() const;

  SimWorld& world_;
  bool initialising_ = false;
  bool ready_ = false;
  bool delayed_pending_ = false;
  std::uint64_t delayed_due_us_ = 0;
  float delayed_pan_rad_ = 0.0F;
  float delayed_tilt_rad_ = 0.0F;
  mutable char error_[96] = {};
};

}  // namespace boticelli::hal::sim
