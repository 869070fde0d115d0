// Helpers of the kernel-in-the-loop tests: shell commands in the guest, real-time cycles.
#pragma once

#include <cstdint>

#include "hal/linux/clock_posix.h"

namespace boticelli::kernel_test {

// Runs `command` with /bin/sh (busybox in the guest); its exit status, −1 if it could not run.
int sh(const char* command);

// Reads a whole small file (sysfs attribute, log) into `out` (NUL-terminated); false if absent.
bool read_text(const char* path, char* out, unsigned size);
// Writes `text` to an existing file (a sysfs attribute); false on failure.
bool write_text(const char* path, const char* text);

// A fixed-rate loop on CLOCK_MONOTONIC, like the executive's minor frame.
class Cycles {
 public:
  explicit Cycles(std::uint32_t period_us = 10000) : period_us_(period_us) {}
  // Sleeps until the next frame boundary (absolute deadlines: no drift).
  void wait();
  std::uint64_t now_us() { return clock_.now_us(); }
  hal_linux::ClockPosix& clock() { return clock_; }

 private:
  hal_linux::ClockPosix clock_;
  std::uint32_t period_us_;
  std::uint64_t next_us_ = 0;
};

}  // namespace boticelli::kernel_test
