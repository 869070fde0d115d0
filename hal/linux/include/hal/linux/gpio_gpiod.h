// DigitalInGpiod / DigitalOutGpiod: hal::DigitalIn/Out on a GPIO line through libgpiod 1.6 (C++
// binding).
#pragma once

#include <gpiod.hpp>

#include <cstdint>

#include "hal/clock.h"
#include "hal/codec/debounced_input.h"
#include "hal/digital_io.h"

namespace boticelli::hal_linux {

struct GpioLineConfig {
  const char* chip = "gpiochip0";  // name, path (/dev/gpiochip0), label or number
  unsigned int offset = 0;         // line offset on that chip
  bool active_low = false;         // true: the line reads low when the input is active
  bool pull_up = false;            // request the chip's pull-up bias (inputs)
  std::uint32_t debounce_ms = 10;  // inputs: lock-out after an accepted change
  bool initial_active = false;     // outputs: level at request time
  const char* consumer = "boticelli";
};

// Requests the line for both-edge events (gpiod::line_request EVENT_BOTH_EDGES).
// read()/activated_since_last_poll() drain the pending events without blocking (poll on
// event_get_fd(), then event_read(), which does not allocate, unlike event_wait()) and run
// them through DebouncedInput (polarity, debounce, latch) at the kernel's event timestamps;
// then the line's level is read and given to DebouncedInput too, because the kernel's event
// queue (16 events) drops the newest edges of a long bounce. libgpiod's exceptions are caught:
// a failed line reads inactive, or active when `fail_active` is set (an e-stop input should
// fail safe); error() says why.
class DigitalInGpiod final : public hal::DigitalIn {
 public:
  DigitalInGpiod(const GpioLineConfig& config, hal::Clock& clock, bool fail_active = false);
  bool init();
  bool read() override;
  bool activated_since_last_poll() override;
  const char* error() const { return error_; }
  std::uint32_t events() const { return events_; }  // edge events read so far

 private:
  void service();
  GpioLineConfig config_;
  hal::Clock& clock_;
  bool fail_active_;
  gpiod::chip chip_;
  gpiod::line line_;
  int event_fd_ = -1;
  bool ok_ = false;
  std::uint64_t last_event_us_ = 0;
  std::uint32_t events_ = 0;
  codec::DebouncedInput filter_;
  char error_[160] = "not initialised";
};

// The output uses libgpiod's C calls (declared by gpiod.hpp too): the 1.6 C++ binding's
// line::set_value() builds a line_bulk (a std::vector) on every call, which the cyclic
// path must not do. Writes of an unchanged level make no system call.
class DigitalOutGpiod final : public hal::DigitalOut {
 public:
  explicit DigitalOutGpiod(const GpioLineConfig& config);
  ~DigitalOutGpiod() override;
  DigitalOutGpiod(const DigitalOutGpiod&) = delete;
  DigitalOutGpiod& operator=(const DigitalOutGpiod&) = delete;
  bool init();
  void write(bool active) override;
  const char* error() const { return error_; }

 private:
  void close();
  GpioLineConfig config_;
  ::gpiod_chip* chip_ = nullptr;
  ::gpiod_line* line_ = nullptr;
  bool ok_ = false;
  int last_ = -1;
  char error_[160] = "not initialised";
};

}  // namespace boticelli::hal_linux
