// ClockPosix: hal::Clock on CLOCK_MONOTONIC (clock_gettime, clock_nanosleep TIMER_ABSTIME).
#pragma once

#include <cstdint>

#include "hal/clock.h"

namespace boticelli::hal_linux {

class ClockPosix final : public hal::Clock {
 public:
  // Monotonic time [µs] since boot (CLOCK_MONOTONIC's epoch).
  std::uint64_t now_us() override;
  // Absolute sleep on CLOCK_MONOTONIC; resumes after a signal (EINTR) until the deadline.
  void sleep_until_us(std::uint64_t deadline_us) override;
  std::int64_t last_wake_latency_ns() const override { return last_wake_latency_ns_; }
  // CLOCK_REALTIME [ms] (a vDSO call: no I/O).
  std::int64_t wall_time_ms() override;

 private:
  std::int64_t last_wake_latency_ns_ = -1;
};

}  // namespace boticelli::hal_linux
