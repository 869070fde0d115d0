// PosixHostClock: HostClock on clock_gettime (see host_clock.h).
#include "firmware/executive/host_clock.h"

#include <ctime>

namespace boticelli::firmware {
namespace {

std::uint64_t read_ns(clockid_t id) {
  timespec ts{};
  if (::clock_gettime(id, &ts) != 0) return 0;
  return static_cast<std::uint64_t>(ts.tv_sec) * 1000000000U +
         static_cast<std::uint64_t>(ts.tv_nsec);
}

}  // namespace

std::uint64_t PosixHostClock::monotonic_ns() {
  return read_ns(CLOCK_MONOTONIC);
}

std::uint64_t PosixHostClock::thread_cpu_ns() {
  return read_ns(CLOCK_THREAD_CPUTIME_ID);
}

}  // namespace boticelli::firmware
