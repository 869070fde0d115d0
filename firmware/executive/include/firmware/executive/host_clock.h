// HostClock: the processor's own clocks, for timing work apart from the board's notion of time.
#pragma once

#include <cstdint>

namespace boticelli::firmware {

// What the executive times task bodies, background slices and frames with. On a Linux board
// the board's clock is CLOCK_MONOTONIC too; on the sim board the board's time is simulated
// and stands still while the host computes, so only this clock sees how long work takes.
// Tests give the executive a fake one (nothing here reads the OS).
class HostClock {
 public:
  virtual ~HostClock() = default;
  // Monotonic wall time [ns] since an arbitrary epoch (CLOCK_MONOTONIC on Linux).
  virtual std::uint64_t monotonic_ns() = 0;
  // CPU time the calling thread has used [ns] (CLOCK_THREAD_CPUTIME_ID on Linux): what an
  // execution-time budget means on a core of its own, whatever else the host runs.
  virtual std::uint64_t thread_cpu_ns() = 0;

 protected:
  HostClock() = default;
  HostClock(const HostClock&) = default;
  HostClock& operator=(const HostClock&) = default;
};

// The Linux clocks (clock_gettime, POSIX; host_clock_posix.cpp).
class PosixHostClock final : public HostClock {
 public:
  std::uint64_t monotonic_ns() override;
  std::uint64_t thread_cpu_ns() override;
};

}  // namespace boticelli::firmware
