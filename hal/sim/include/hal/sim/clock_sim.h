// ClockSim: lockstep simulated time; sleeping to a deadline steps the world to it.
#pragma once

#include "hal/clock.h"
#include "hal/sim/sim_world.h"

namespace boticelli::hal::sim {

class ClockSim final : public Clock {
 public:
  explicit ClockSim(SimWorld& world) : world_(world) {}
  std::uint64_t now_us() override { return world_.now_us(); }
  // Advances simulated time (and the PTU, base and contacts) to the deadline at once.
  void sleep_until_us(std::uint64_t deadline_us) override { world_.advance_to(deadline_us); }

 private:
  SimWorld& world_;
};

}  // namespace boticelli::hal::sim
