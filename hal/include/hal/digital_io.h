// DigitalIn / DigitalOut: GPIO lines (e-stop, bumper, status LED); logical levels, polarity handled
// below.
#pragma once

#include "hal/noncopyable.h"

namespace boticelli::hal {

class DigitalIn : private NonCopyable {
 public:
  virtual ~DigitalIn() = default;
  // Logical level: true = active (pressed, in contact), whatever the wiring's polarity.
  virtual bool read() = 0;
  // True once for every transition to active since the last call (edge events,
  // non-blocking), so a short press between two polls is not missed.
  virtual bool activated_since_last_poll() { return false; }
};

class DigitalOut : private NonCopyable {
 public:
  virtual ~DigitalOut() = default;
  virtual void write(bool active) = 0;
};

}  // namespace boticelli::hal
