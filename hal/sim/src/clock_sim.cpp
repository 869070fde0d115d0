// ClockSim: simulated time stepped in lockstep, paced to wall time when a speed is set.
#include "hal/sim/clock_sim.h"

#include <cerrno>
#include <ctime>

namespace boticelli::hal::sim {
namespace {

std::uint64_t monotonic_ns() {
  timespec ts{};
  ::clock_gettime(CLOCK_MONOTONIC, &ts);
  return static_cast<std::uint64_t>(ts.tv_sec) * 1000000000U +
         static_cast<std::uint64_t>(ts.tv_nsec);
}

// A host that falls further behind than this stops trying to catch up (no burst of frames
// after a stall, e.g. a suspended terminal): the pacing starts again from now.
constexpr std::uint64_t kMaxLagNs = 200000000U;  // 0.2 s

}  // namespace

void ClockSim::set_speed(double speed) {
  speed_ = speed > 0.0 ? speed : 0.0;
  anchored_ = false;
}

void ClockSim::sleep_until_us(std::uint64_t deadline_us) {
  last_wake_latency_ns_ = -1;
  world_.advance_to(deadline_us);
  FaultType fault = FaultType::kOff;
  if (world_.faults().failing(FaultDevice::kMainLoop, fault)) {
    const FaultInjector& faults = world_.faults();
    if (fault == FaultType::kStuck &&
        faults.active_since_us(FaultDevice::kMainLoop) != stalled_since_us_) {
      stalled_since_us_ = faults.active_since_us(FaultDevice::kMainLoop);
      world_.advance_to(faults.active_until_us(FaultDevice::kMainLoop));
    } else if (fault == FaultType::kSlow) {
      world_.advance_to(world_.now_us() + kSlowUs);
    }
  }
  if (after_advance_ != nullptr) after_advance_(after_advance_context_);
  if (speed_ <= 0.0) return;
  const std::uint64_t now_ns = monotonic_ns();
  const std::uint64_t sim_us = world_.now_us();
  if (!anchored_) {
    anchored_ = true;
    anchor_sim_us_ = sim_us;
    anchor_wall_ns_ = now_ns;
    return;
  }
  const double wall_ns = static_cast<double>(sim_us - anchor_sim_us_) * 1e3 / speed_;
  const std::uint64_t due_ns = anchor_wall_ns_ + static_cast<std::uint64_t>(wall_ns);
  if (now_ns > due_ns + kMaxLagNs) {
    last_wake_latency_ns_ = static_cast<std::int64_t>(now_ns - due_ns);
    anchor_sim_us_ = sim_us;
    anchor_wall_ns_ = now_ns;
    return;
  }
  if (due_ns <= now_ns) {
    last_wake_latency_ns_ = static_cast<std::int64_t>(now_ns - due_ns);
    return;
  }
  timespec ts{};
  ts.tv_sec = static_cast<std::time_t>(due_ns / 1000000000U);
  ts.tv_nsec = static_cast<long>(due_ns % 1000000000U);
  // EINTR (a signal, e.g. SIGINT): sleep on to the same deadline; the firmware sees the
  // signal after the frame.
  while (::clock_nanosleep(CLOCK_MONOTONIC, TIMER_ABSTIME, &ts, nullptr) == EINTR) {
  }
  last_wake_latency_ns_ =
      static_cast<std::int64_t>(monotonic_ns()) - static_cast<std::int64_t>(due_ns);
}

}  // namespace boticelli::hal::sim
