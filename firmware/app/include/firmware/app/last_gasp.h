// LastGasp: a dying firmware's last act — on a fatal signal (SIGSEGV, SIGBUS, SIGILL, SIGFPE,
// SIGABRT) the base is commanded to brake to a stop before the process dies.
#pragma once

#include "hal/base.h"

namespace boticelli::firmware {

// While armed, a fatal signal calls `base.last_gasp_stop()` (async-signal-safe: it only
// writes prepared frames) on an alternate signal stack (a stack overflow is one such death),
// then hands the signal to the handler found at arm() (the default action: a core dump and
// the wait status systemd sees; or a sanitizer's report). One instance at a time; disarm()
// or the destructor puts back the handlers found at arm().
class LastGasp {
 public:
  LastGasp() = default;
  ~LastGasp() { disarm(); }
  LastGasp(const LastGasp&) = delete;
  LastGasp& operator=(const LastGasp&) = delete;
  // False (nothing armed) when another LastGasp is armed or the handlers cannot be set.
  bool arm(hal::Base& base);
  void disarm();
  bool armed() const { return armed_; }

 private:
  bool armed_ = false;
};

}  // namespace boticelli::firmware
