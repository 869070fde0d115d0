// PanTiltSim: command checking and quantisation of the simulated PTU-D46 (motion is in SimWorld).
#include "hal/sim/pan_tilt_sim.h"

#include <algorithm>
#include <cmath>
#include <cstdio>

namespace boticelli::hal::sim {

namespace {
float quantise(float rad, float resolution_rad) {
  return resolution_rad > 0.0F ? std::round(rad / resolution_rad) * resolution_rad : rad;
}
}  // namespace

bool PanTiltSim::init() {
  // Like the D46 after a reset: ready once update() has run (limits, resolution read back).
  initialising_ = true;
  ready_ = false;
  delayed_pending_ = false;
  error_[0] = '\0';
  return true;
}

void PanTiltSim::update() {
  if (initialising_) {
    initialising_ = false;
    ready_ = true;
  }
  if (delayed_pending_ && world_.now_us() >= delayed_due_us_) {
    delayed_pending_ = false;
    world_.pan().target_rad = delayed_pan_rad_;
    world_.tilt().target_rad = delayed_tilt_rad_;
  }
}

bool PanTiltSim::faulted() const {
  FaultType type = FaultType::kOff;
  if (!world_.faults().failing(FaultDevice::kPtu, type)) return false;
  switch (type) {
    case FaultType::kOff:
      if (world_.now_us() - world_.faults().active_since_us(FaultDevice::kPtu) < kSilenceUs) {
        return false;  // not noticed yet: the driver waits for its reply timeout
      }
      std::snprintf(error_, sizeof error_, "PTU: no reply for %.1f s",
                    static_cast<double>(kSilenceUs) * 1e-6);
      return true;
    case FaultType::kGarbage:
    case FaultType::kIntermittent:
      std::snprintf(error_, sizeof error_, "PTU: garbled reply (not * or !)");
      return true;
    default:
      return false;
  }
}

bool PanTiltSim::move_to(float pan_rad, float tilt_rad) {
  if (!ready_) {
    std::snprintf(error_, sizeof error_, "PTU not initialised");
    return false;
  }
  if (faulted()) return false;
  FaultType type = FaultType::kOff;
  if (world_.faults().failing(FaultDevice::kPtu, type) && type == FaultType::kWrong) {
    std::snprintf(error_, sizeof error_, "! PTU refused the command (error reply)");
    return false;
  }
  const PanTiltLimits l = limits();
  const float pan = quantise(pan_rad, l.pan_resolution_rad);
  const float tilt = quantise(tilt_rad, l.tilt_resolution_rad);
  // The unit answers "!" to a position beyond its limits and does not move.
  // Compare in whole steps (limits are whole steps), with a hair of tolerance for rounding.
  const float pan_eps = 1e-3F * l.pan_resolution_rad;
  const float tilt_eps = 1e-3F * l.tilt_resolution_rad;
  if (!std::isfinite(pan_rad) || pan < l.pan_min_rad - pan_eps || pan > l.pan_max_rad + pan_eps) {
    std::snprintf(error_, sizeof error_, "! pan %.4f rad outside [%.4f, %.4f]",
                  static_cast<double>(pan_rad), static_cast<double>(l.pan_min_rad),
                  static_cast<double>(l.pan_max_rad));
    return false;
  }
  if (!std::isfinite(tilt_rad) || tilt < l.tilt_min_rad - tilt_eps ||
      tilt > l.tilt_max_rad + tilt_eps) {
    std::snprintf(error_, sizeof error_, "! tilt %.4f rad outside [%.4f, %.4f]",
                  static_cast<double>(tilt_rad), static_cast<double>(l.tilt_min_rad),
                  static_cast<double>(l.tilt_max_rad));
    return false;
  }
  const float pan_target = std::clamp(pan, l.pan_min_rad, l.pan_max_rad);
  const float tilt_target = std::clamp(tilt, l.tilt_min_rad, l.tilt_max_rad);
  error_[0] = '\0';
  if (world_.faults().failing(FaultDevice::kPtu, type) && type == FaultType::kDelayed) {
    delayed_pending_ = true;
    delayed_due_us_ = world_.now_us() + kDelayUs;
    delayed_pan_rad_ = pan_target;
    delayed_tilt_rad_ = tilt_target;
    return true;
  }
  delayed_pending_ = false;
  world_.pan().target_rad = pan_target;
  world_.tilt().target_rad = tilt_target;
  return true;
}

void PanTiltSim::halt() {
  // Decelerate to a stop: the new target is where braking ends, rounded to a step.
  const PanTiltLimits l = limits();
  const float a = world_.params().ptu.accel_rad_s2;
  for (PtuAxis* axis : {&world_.pan(), &world_.tilt()}) {
    const float v = axis->velocity_rad_s;
    const float stop = axis->position_rad + v * std::fabs(v) / (2.0F * a);
    const float res = axis == &world_.pan() ? l.pan_resolution_rad : l.tilt_resolution_rad;
    axis->target_rad = quantise(stop, res);
    if (v == 0.0F) axis->target_rad = axis->position_rad;
  }
}

PanTiltState PanTiltSim::state() const {
  const PanTiltLimits l = limits();
  PanTiltState s;
  // Positions are reported in whole steps, as the unit does.
  s.pan_rad = quantise(world_.pan().position_rad, l.pan_resolution_rad);
  s.tilt_rad = quantise(world_.tilt().position_rad, l.tilt_resolution_rad);
  s.moving = world_.pan().moving() || world_.tilt().moving() || initialising_ || delayed_pending_;
  s.fault = faulted();
  return s;
}

bool PanTiltSim::set_speed(float pan_rad_s, float tilt_rad_s) {
  const float max = world_.params().ptu.max_speed_rad_s;
  if (!(pan_rad_s > 0.0F && pan_rad_s <= max && tilt_rad_s > 0.0F && tilt_rad_s <= max)) {
    std::snprintf(error_, sizeof error_, "! speed outside (0, %.3f] rad/s",
                  static_cast<double>(max));
    return false;
  }
  world_.pan().speed_rad_s = pan_rad_s;
  world_.tilt().speed_rad_s = tilt_rad_s;
  return true;
}

}  // namespace boticelli::hal::sim
