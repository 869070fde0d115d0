// WatchdogSim: stand-in watchdog on simulated time; expirations are counted, not reset.
#pragma once

#include "hal/sim/fault_injector.h"
#include "hal/sim/sim_world.h"
#include "hal/watchdog.h"

namespace boticelli::hal::sim {

// Faults (`watchdog ...` in a plan): `stuck` is a busy device (another process holds it:
// start() fails as the kernel's EBUSY), `off` and `intermittent` refuse keep-alives (the
// driver's EIO), which then do not reach the stand-in: it expires as the board would reset.
class WatchdogSim final : public Watchdog {
 public:
  explicit WatchdogSim(SimWorld& world) : world_(world) {}
  bool start(std::uint32_t timeout_ms) override {
    if (timeout_ms == 0) {
      error_ = "watchdog: a zero timeout";
      return false;
    }
    FaultType fault = FaultType::kOff;
    if (world_.faults().failing(FaultDevice::kWatchdog, fault) && fault == FaultType::kStuck) {
      error_ =
          "watchdog: /dev/watchdog is busy (another process holds it, e.g. systemd with "
          "RuntimeWatchdogSec=): Device or resource busy";
      return false;
    }
    world_.watchdog_start(timeout_ms);
    armed_ = true;
    error_ = "";
    return true;
  }
  bool kick() override {
    if (!armed_) return true;
    FaultType fault = FaultType::kOff;
    if (world_.faults().failing(FaultDevice::kWatchdog, fault) && fault != FaultType::kStuck) {
      error_ = "watchdog: keep-alive refused: Input/output error";
      return false;
    }
    world_.watchdog_kick();
    return true;
  }
  void stop() override {
    world_.watchdog_stop();
    armed_ = false;
  }
  const char* error() const override { return error_; }

 private:
  SimWorld& world_;
  const char* error_ = "";
  bool armed_ = false;
};

}  // namespace boticelli::hal::sim
