// Watchdog: hardware or service watchdog that resets the board unless kicked in time.
#pragma once

#include <cstdint>

#include "hal/noncopyable.h"

namespace boticelli::hal {

class Watchdog : private NonCopyable {
 public:
  virtual ~Watchdog() = default;
  // Arms the watchdog with a timeout [ms]; false when unavailable (see error()).
  virtual bool start(std::uint32_t timeout_ms) = 0;
  // Keep-alive; call only while every task is healthy. False when the device refused it (see
  // error()): unless a later one is taken, the board resets when the timeout runs out. True
  // when the watchdog is not armed (nothing to keep alive).
  virtual bool kick() = 0;
  // Disarms on an orderly shutdown (magic close on /dev/watchdog).
  virtual void stop() = 0;
  virtual const char* error() const { return ""; }
};

}  // namespace boticelli::hal
