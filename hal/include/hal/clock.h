// Clock: the board's monotonic time; on the sim board it is simulated and advances in lockstep.
#pragma once

#include <cstdint>

#include "hal/noncopyable.h"

namespace boticelli::hal {

class Clock : private NonCopyable {
 public:
  virtual ~Clock() = default;
  // Monotonic time [µs] since an arbitrary epoch.
  virtual std::uint64_t now_us() = 0;
  // Waits until now_us() ≥ deadline_us (clock_nanosleep TIMER_ABSTIME on Linux; the sim
  // board advances simulated time to the deadline instead). Returns at once if past.
  virtual void sleep_until_us(std::uint64_t deadline_us) = 0;
  // How late the last sleep_until_us() returned on the host's CLOCK_MONOTONIC [ns]: the
  // actual minus the intended wake-up, as cyclictest measures it (a deadline already past
  // counts how far past). -1 when that sleep did not wait on the host's clock (the sim
  // board in lockstep, without --speed) or before the first sleep.
  virtual std::int64_t last_wake_latency_ns() const { return -1; }
  // Wall-clock time [ms since the Unix epoch], which outlives a restart and a reboot (how old
  // a saved pose is); 0 when the board has none (the sim board: its runs stay repeatable).
  virtual std::int64_t wall_time_ms() { return 0; }
};

}  // namespace boticelli::hal
