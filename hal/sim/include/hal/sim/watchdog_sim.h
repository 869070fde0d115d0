// WatchdogSim: stand-in watchdog on simulated time; expirations are counted, not reset.
#pragma once

#include "hal/sim/sim_world.h"
#include "hal/watchdog.h"

namespace boticelli::hal::sim {

class WatchdogSim final : public Watchdog {
 public:
  explicit WatchdogSim(SimWorld& world) : world_(world) {}
  bool start(std::uint32_t timeout_ms) override {
    if (timeout_ms == 0) return false;
    world_.watchdog_start(timeout_ms);
    return true;
  }
  void kick() override { world_.watchdog_kick(); }
  void stop() override { world_.watchdog_stop(); }

 private:
  SimWorld& world_;
};

}  // namespace boticelli::hal::sim
