// FaultInjector: the faults of a FaultPlan (and the console's) active at the simulated time,
// which the sim devices consult at their HAL boundary; deterministic for a seed.
#pragma once

#include <array>
#include <cstdint>

#include "hal/sim/fault_plan.h"

namespace boticelli::hal::sim {

class FaultInjector {
 public:
  // Length of one on/off slot of an intermittent fault [µs].
  static constexpr std::uint64_t kSlotUs = 250000;

  // A new run: no faults, `seed` for the intermittent faults' coins.
  void reset(std::uint64_t seed);
  // Replaces the plan (at init, before the run).
  void set_plan(const FaultPlan& plan);
  // Adds a fault from `now_us` for `duration_us` (0 = until the end): the console's `fault`
  // command. False when the plan is full.
  bool inject(FaultDevice device, FaultType type, std::uint64_t now_us, std::uint64_t duration_us);
  // Recomputes which faults are active when one starts or ends at or before `now_us`
  // (cheap otherwise); SimWorld calls it every physics step. No allocation.
  void update(std::uint64_t now_us);

  // The fault active on `device` (the one started last when several overlap); false if none.
  bool active(FaultDevice device, FaultType& type) const;
  // Active and, for an intermittent fault, in a failing slot: the device misbehaves now.
  bool failing(FaultDevice device, FaultType& type) const;
  // When the device's active fault started [µs of simulated time]; 0 when none is active.
  std::uint64_t active_since_us(FaultDevice device) const {
    return active_[static_cast<std::size_t>(device)].since_us;
  }
  // When it ends (UINT64_MAX: never); 0 when none is active.
  std::uint64_t active_until_us(FaultDevice device) const {
    return active_[static_cast<std::size_t>(device)].until_us;
  }
  const FaultPlan& plan() const { return plan_; }
  // Faults that started / ended so far (each counted once).
  std::uint32_t started() const { return started_; }
  std::uint32_t ended() const { return ended_; }

 private:
  struct Active {
    bool on = false;
    FaultType type = FaultType::kOff;
    std::size_t index = 0;  // in the plan
    std::uint64_t since_us = 0;
    std::uint64_t until_us = 0;
  };
  void recompute(std::uint64_t now_us);

  FaultPlan plan_;
  std::array<Active, kFaultDeviceCount> active_{};
  std::array<bool, FaultPlan::kMaxFaults> seen_start_{};
  std::array<bool, FaultPlan::kMaxFaults> seen_end_{};
  std::uint64_t seed_ = 1;
  std::uint64_t now_us_ = 0;
  std::uint64_t next_event_us_ = 0;
  std::uint32_t started_ = 0;
  std::uint32_t ended_ = 0;
};

}  // namespace boticelli::hal::sim
