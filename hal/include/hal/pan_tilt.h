// PanTilt: non-blocking pan-tilt unit (PTU-D46 over serial, or the simulated PTU).
#pragma once

#include <cstdint>

#include "hal/noncopyable.h"

namespace boticelli::hal {

struct PanTiltLimits {
  float pan_min_rad = 0.0F;
  float pan_max_rad = 0.0F;
  float tilt_min_rad = 0.0F;
  float tilt_max_rad = 0.0F;
  float pan_resolution_rad = 0.0F;  // one position step
  float tilt_resolution_rad = 0.0F;
};

struct PanTiltState {
  float pan_rad = 0.0F;  // current position (last reported by the unit)
  float tilt_rad = 0.0F;
  bool moving = false;  // a commanded move has not completed yet
  bool fault = false;   // the unit reported an error or stopped answering; see error()
};

class PanTilt : private NonCopyable {
 public:
  virtual ~PanTilt() = default;
  // Starts initialisation (limits, resolution); update() completes it without blocking.
  virtual bool init() = 0;
  // Services the device: sends queued commands, parses replies. Returns at once.
  virtual void update() = 0;
  // Queues an absolute move [rad]; false when outside the limits or the unit is faulted.
  virtual bool move_to(float pan_rad, float tilt_rad) = 0;
  // Stops both axes where they are.
  virtual void halt() = 0;
  virtual PanTiltState state() const = 0;
  virtual PanTiltLimits limits() const = 0;
  // Axis speeds [rad/s]; false when not supported or out of range.
  virtual bool set_speed(float /*pan_rad_s*/, float /*tilt_rad_s*/) { return false; }
  virtual const char* error() const { return ""; }
};

}  // namespace boticelli::hal
