// FaultInjector: active faults by simulated time, and the intermittent faults' seeded coins.
#include "hal/sim/fault_injector.h"

namespace boticelli::hal::sim {

void FaultInjector::reset(std::uint64_t seed) {
  plan_.clear();
  active_ = {};
  seen_start_ = {};
  seen_end_ = {};
  seed_ = seed;
  now_us_ = 0;
  next_event_us_ = 0;
  started_ = ended_ = 0;
}

void FaultInjector::set_plan(const FaultPlan& plan) {
  plan_ = plan;
  active_ = {};
  seen_start_ = {};
  seen_end_ = {};
  next_event_us_ = 0;
  started_ = ended_ = 0;
  recompute(now_us_);  // a fault from now on is active before the time next moves
}

bool FaultInjector::inject(FaultDevice device, FaultType type, std::uint64_t now_us,
                           std::uint64_t duration_us) {
  Fault f;
  f.device = device;
  f.type = type;
  f.start_us = now_us;
  f.duration_us = duration_us;
  if (!plan_.add(f)) return false;
  recompute(now_us);
  return true;
}

void FaultInjector::update(std::uint64_t now_us) {
  now_us_ = now_us;
  if (now_us < next_event_us_) return;
  recompute(now_us);
}

void FaultInjector::recompute(std::uint64_t now_us) {
  now_us_ = now_us;
  active_ = {};
  std::uint64_t next = UINT64_MAX;
  for (std::size_t i = 0; i < plan_.size(); ++i) {
    const Fault& f = plan_[i];
    const std::uint64_t end = f.end_us();
    if (now_us < f.start_us) {
      if (f.start_us < next) next = f.start_us;
      continue;
    }
    if (!seen_start_[i]) {
      seen_start_[i] = true;
      ++started_;
    }
    if (now_us >= end) {
      if (!seen_end_[i]) {
        seen_end_[i] = true;
        ++ended_;
      }
      continue;
    }
    if (end < next) next = end;
    Active& a = active_[static_cast<std::size_t>(f.device)];
    if (!a.on || f.start_us >= a.since_us) {
      a.on = true;
      a.type = f.type;
      a.index = i;
      a.since_us = f.start_us;
      a.until_us = end;
    }
  }
  next_event_us_ = next;
}

bool FaultInjector::active(FaultDevice device, FaultType& type) const {
  const Active& a = active_[static_cast<std::size_t>(device)];
  if (!a.on) return false;
  type = a.type;
  return true;
}

bool FaultInjector::failing(FaultDevice device, FaultType& type) const {
  if (!active(device, type)) return false;
  if (type != FaultType::kIntermittent) return true;
  // A seeded coin per device and 250 ms slot (splitmix64 of the three).
  std::uint64_t z = seed_ * 0x9E3779B97F4A7C15ULL + (now_us_ / kSlotUs) * 0xBF58476D1CE4E5B9ULL +
                    (static_cast<std::uint64_t>(device) + 1U) * 0x94D049BB133111EBULL;
  z = (z ^ (z >> 30U)) * 0xBF58476D1CE4E5B9ULL;
  z = (z ^ (z >> 27U)) * 0x94D049BB133111EBULL;
  z ^= z >> 31U;
  return (z & 1U) != 0U;
}

}  // namespace boticelli::hal::sim
