// Realtime: process set-up for the cyclic executive on Linux (mlockall, prefaulted stack,
// SCHED_FIFO).
#pragma once

#include <cstddef>

namespace boticelli::firmware {

struct RealtimeConfig {
  bool lock_memory = true;  // mlockall(MCL_CURRENT | MCL_FUTURE)
  // The stack touched once at start, so that it takes no page fault later.
  std::size_t prefault_stack_bytes = std::size_t{256} * 1024;
  bool fifo = true;        // SCHED_FIFO when permitted
  int fifo_priority = 50;  // 1..99
};

struct RealtimeReport {
  bool memory_locked = false;
  bool fifo = false;
  char message[512] = "";  // one line for the log: what was set up and what was refused, and why
};

// Applies what it can; refusals (no CAP_IPC_LOCK / RLIMIT_MEMLOCK, no CAP_SYS_NICE /
// RLIMIT_RTPRIO) are reported in the message, never fatal.
RealtimeReport prepare_realtime(const RealtimeConfig& config);

}  // namespace boticelli::firmware
