// ClockSim: lockstep simulated time; sleeping to a deadline steps the world to it, optionally
// paced to wall time (--speed).
#pragma once

#include <cstdint>

#include "hal/clock.h"
#include "hal/sim/sim_world.h"

namespace boticelli::hal::sim {

class ClockSim final : public Clock {
 public:
  explicit ClockSim(SimWorld& world) : world_(world) {}
  std::uint64_t now_us() override { return world_.now_us(); }
  // Advances simulated time (and the PTU, base and contacts) to the deadline at once; with a
  // speed, then waits until as much wall time has passed as simulated time, divided by the speed.
  // Injected main-loop faults act here, where the executive hands over its time: stuck =
  // the executive stalls for the fault's whole duration once (time runs on, nothing of the
  // firmware runs), slow = every sleep ends 12 ms late (every frame overruns).
  void sleep_until_us(std::uint64_t deadline_us) override;
  // With a speed: how late the wall clock woke for the simulated deadline (-1 in lockstep
  // without a speed, and at the first paced sleep, which only anchors the pacing).
  std::int64_t last_wake_latency_ns() const override { return last_wake_latency_ns_; }
  // Simulated seconds per wall second: 1 = real time, 0 = as fast as possible (the default).
  void set_speed(double speed);
  double speed() const { return speed_; }
  // Called after each sleep has stepped the world (the sim board records the world's state
  // there); nullptr for none.
  void set_after_advance(void (*callback)(void* context), void* context) {
    after_advance_ = callback;
    after_advance_context_ = context;
  }

 private:
  SimWorld& world_;
  static constexpr std::uint64_t kSlowUs = 12000;
  double speed_ = 0.0;
  std::uint64_t stalled_since_us_ = UINT64_MAX;  // start of the stall already served
  bool anchored_ = false;
  std::uint64_t anchor_sim_us_ = 0;   // simulated time at the anchor
  std::uint64_t anchor_wall_ns_ = 0;  // CLOCK_MONOTONIC at the anchor
  std::int64_t last_wake_latency_ns_ = -1;
  void (*after_advance_)(void* context) = nullptr;
  void* after_advance_context_ = nullptr;
};

}  // namespace boticelli::hal::sim
