// DebouncedInput: polarity, debounce and the "activated since last poll" latch of a GPIO input,
// pure.
#pragma once

#include <cstdint>

namespace boticelli::codec {

// Lock-out debounce: a change of the (polarity-corrected) level is accepted at once when the
// last accepted change is at least `debounce_us` old, so an e-stop press acts without delay;
// changes inside the lock-out (contact bounce) are held back, and the level is reconciled
// with the latest raw level once the lock-out has passed (settle()). Every accepted change
// to active sets a latch that take_activation() reads and clears, so a press shorter than
// the poll period is not missed.
class DebouncedInput {
 public:
  DebouncedInput(bool active_low, std::uint64_t debounce_us)
      : active_low_(active_low), debounce_us_(debounce_us) {}

  // The level read at start-up (physical: true = high); no activation is latched for it.
  void reset(bool physical_high, std::uint64_t now_us);
  // A physical edge (rising = to high) seen at `t_us`; edges must come in time order.
  void on_edge(bool rising, std::uint64_t t_us);
  // A polled physical level (for when events may have been lost).
  void on_level(bool physical_high, std::uint64_t now_us);
  // Applies a held-back change once the lock-out has passed.
  void settle(std::uint64_t now_us);

  bool active() const { return stable_; }
  // True once per accepted transition to active since the last call.
  bool take_activation();

 private:
  bool logical(bool physical_high) const { return physical_high != active_low_; }
  bool active_low_;
  std::uint64_t debounce_us_;
  bool raw_ = false;
  bool stable_ = false;
  bool latch_ = false;
  bool have_change_ = false;
  std::uint64_t last_change_us_ = 0;
};

// The physical level that drives an output to the logical state `active`.
constexpr bool physical_level(bool active, bool active_low) {
  return active != active_low;
}

}  // namespace boticelli::codec
