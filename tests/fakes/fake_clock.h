// FakeClock: a manual hal::Clock for deterministic tests (time moves only when told to).
#pragma once

#include <cstdint>

#include "hal/clock.h"

namespace boticelli::fakes {

// now_us() returns the manual time; sleep_until_us() jumps to the deadline instead of
// waiting (never backwards). With set_auto_advance_us(d) every now_us() call also moves
// time forward by d, so code that polls until a timeout terminates without real waiting.
class FakeClock final : public hal::Clock {
 public:
  explicit FakeClock(std::uint64_t start_us = 0) : now_us_(start_us) {}

  std::uint64_t now_us() override;
  void sleep_until_us(std::uint64_t deadline_us) override;
  // The wall clock: wall_ms_at_zero + now [ms] once set (0 until then: no wall clock).
  std::int64_t wall_time_ms() override {
    return wall_ms_at_zero == 0 ? 0 : wall_ms_at_zero + static_cast<std::int64_t>(now_us_ / 1000U);
  }
  std::int64_t wall_ms_at_zero = 0;

  void advance_us(std::uint64_t delta_us) { now_us_ += delta_us; }
  // Sets the time; ignored when it would go backwards (the clock is monotonic).
  void set_us(std::uint64_t t_us) {
    if (t_us > now_us_) now_us_ = t_us;
  }
  void set_auto_advance_us(std::uint64_t step_us) { auto_advance_us_ = step_us; }
  // How often sleep_until_us() was called and the last deadline it was given.
  std::uint64_t sleep_calls() const { return sleep_calls_; }
  std::uint64_t last_deadline_us() const { return last_deadline_us_; }
  // Current time without the auto-advance side effect.
  std::uint64_t peek_us() const { return now_us_; }
  // What last_wake_latency_ns() reports (-1, the default: not a wall clock).
  std::int64_t last_wake_latency_ns() const override { return wake_latency_ns_; }
  void set_wake_latency_ns(std::int64_t ns) { wake_latency_ns_ = ns; }

 private:
  std::uint64_t now_us_;
  std::uint64_t auto_advance_us_ = 0;
  std::uint64_t sleep_calls_ = 0;
  std::uint64_t last_deadline_us_ = 0;
  std::int64_t wake_latency_ns_ = -1;
};

}  // namespace boticelli::fakes
