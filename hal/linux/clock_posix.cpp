// ClockPosix: CLOCK_MONOTONIC time and absolute sleeps.
#include "hal/linux/clock_posix.h"

#include <cerrno>
#include <ctime>

namespace boticelli::hal_linux {
namespace {

std::int64_t monotonic_ns() {
  timespec ts{};
  ::clock_gettime(CLOCK_MONOTONIC, &ts);
  return static_cast<std::int64_t>(ts.tv_sec) * 1000000000LL +
         static_cast<std::int64_t>(ts.tv_nsec);
}

}  // namespace

std::uint64_t ClockPosix::now_us() {
  timespec ts{};
  ::clock_gettime(CLOCK_MONOTONIC, &ts);
  return static_cast<std::uint64_t>(ts.tv_sec) * 1000000ULL +
         static_cast<std::uint64_t>(ts.tv_nsec) / 1000ULL;
}

std::int64_t ClockPosix::wall_time_ms() {
  timespec ts{};
  ::clock_gettime(CLOCK_REALTIME, &ts);
  return static_cast<std::int64_t>(ts.tv_sec) * 1000 +
         static_cast<std::int64_t>(ts.tv_nsec) / 1000000;
}

void ClockPosix::sleep_until_us(std::uint64_t deadline_us) {
  timespec ts{};
  ts.tv_sec = static_cast<time_t>(deadline_us / 1000000ULL);
  ts.tv_nsec = static_cast<long>((deadline_us % 1000000ULL) * 1000ULL);
  // clock_nanosleep returns the error number (not -1/errno); with TIMER_ABSTIME a restart
  // after EINTR simply waits for the same absolute deadline again.
  int rc = 0;
  do {
    rc = ::clock_nanosleep(CLOCK_MONOTONIC, TIMER_ABSTIME, &ts, nullptr);
  } while (rc == EINTR);
  last_wake_latency_ns_ = monotonic_ns() - static_cast<std::int64_t>(deadline_us) * 1000LL;
}

}  // namespace boticelli::hal_linux
