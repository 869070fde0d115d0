// DebouncedInput: lock-out debounce with an activation latch (pure).
#include "hal/codec/debounced_input.h"

namespace boticelli::codec {

void DebouncedInput::reset(bool physical_high, std::uint64_t now_us) {
  raw_ = stable_ = logical(physical_high);
  latch_ = false;
  have_change_ = false;
  last_change_us_ = now_us;
}

void DebouncedInput::settle(std::uint64_t now_us) {
  if (raw_ == stable_) return;
  if (have_change_ && now_us - last_change_us_ < debounce_us_) return;
  stable_ = raw_;
  have_change_ = true;
  last_change_us_ = now_us;
  if (stable_) latch_ = true;
}

void DebouncedInput::on_edge(bool rising, std::uint64_t t_us) {
  raw_ = logical(rising);
  settle(t_us);
}

void DebouncedInput::on_level(bool physical_high, std::uint64_t now_us) {
  raw_ = logical(physical_high);
  settle(now_us);
}

bool DebouncedInput::take_activation() {
  const bool was = latch_;
  latch_ = false;
  return was;
}

}  // namespace boticelli::codec
