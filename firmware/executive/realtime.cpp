// Realtime process set-up: mlockall, stack prefault, SCHED_FIFO (see realtime.h).
#include "firmware/executive/realtime.h"

#include <sched.h>
#include <sys/mman.h>

#include <cerrno>
#include <cstdio>
#include <cstring>

namespace boticelli::firmware {
namespace {

// Touches `bytes` of stack below the caller so those pages are mapped (and, after mlockall,
// locked) before the first frame.
__attribute__((noinline)) void prefault_stack(std::size_t bytes) {
  constexpr std::size_t kChunk = 4096;
  unsigned char page[kChunk];
  for (std::size_t i = 0; i < kChunk; i += 64) page[i] = 0;
  // Keep the writes: the compiler must assume the asm reads the page.
  asm volatile("" : : "r"(page) : "memory");
  if (bytes > kChunk) prefault_stack(bytes - kChunk);
}

}  // namespace

RealtimeReport prepare_realtime(const RealtimeConfig& config) {
  RealtimeReport report;
  char memory[128] = "memory not locked (disabled)";
  char sched[160] = "default scheduler (SCHED_FIFO disabled)";
  if (config.lock_memory) {
    if (::mlockall(MCL_CURRENT | MCL_FUTURE) == 0) {
      report.memory_locked = true;
      std::snprintf(memory, sizeof memory, "memory locked");
    } else {
      std::snprintf(memory, sizeof memory, "mlockall refused (%s; raise LimitMEMLOCK)",
                    std::strerror(errno));
    }
  }
  prefault_stack(config.prefault_stack_bytes);
  if (config.fifo) {
    sched_param param{};
    const int max = ::sched_get_priority_max(SCHED_FIFO);
    const int min = ::sched_get_priority_min(SCHED_FIFO);
    param.sched_priority = config.fifo_priority < min   ? min
                           : config.fifo_priority > max ? max
                                                        : config.fifo_priority;
    if (::sched_setscheduler(0, SCHED_FIFO, &param) == 0) {
      report.fifo = true;
      std::snprintf(sched, sizeof sched, "SCHED_FIFO priority %d", param.sched_priority);
    } else {
      std::snprintf(sched, sizeof sched,
                    "SCHED_FIFO not permitted (%s; needs LimitRTPRIO or CAP_SYS_NICE): "
                    "running with the default scheduler, timing is best effort",
                    std::strerror(errno));
    }
  }
  std::snprintf(report.message, sizeof report.message, "realtime: %s, stack prefaulted %zu KiB, %s",
                memory, config.prefault_stack_bytes / 1024, sched);
  return report;
}

}  // namespace boticelli::firmware
