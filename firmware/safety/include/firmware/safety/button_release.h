// ButtonRelease: when a held mission carries on after a button e-stop — once the button has
// stayed released for hold_us. The one place this rule lives (mission and fault harness).
#pragma once

#include <cstdint>

#include "firmware/safety/safety.h"
#include "hal/digital_io.h"

namespace boticelli::firmware {

class ButtonRelease {
 public:
  static constexpr std::uint64_t kDefaultHoldUs = 500000;  // released this long → clear [µs]

  explicit ButtonRelease(std::uint64_t hold_us = kDefaultHoldUs) : hold_us_(hold_us) {}

  // A new hold begins: no release seen yet.
  void restart() { released_ = false; }
  // Every frame while the latch is engaged: a button stop is cleared once the button has been
  // released for hold_us (any press restarts the wait); a console or bumper stop is left as
  // it is. True when this call cleared the latch.
  bool update(Safety& safety, hal::DigitalIn& button, std::uint64_t now_us) {
    if (safety.cause() == StopCause::kButton && !button.read()) {
      if (!released_) {
        released_ = true;
        released_since_us_ = now_us;
      } else if (now_us - released_since_us_ >= hold_us_) {
        return safety.clear() == nullptr;
      }
    } else {
      released_ = false;
    }
    return false;
  }

 private:
  std::uint64_t hold_us_;
  std::uint64_t released_since_us_ = 0;
  bool released_ = false;
};

}  // namespace boticelli::firmware
