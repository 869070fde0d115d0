// DigitalInGpiod / DigitalOutGpiod: thin libgpiod 1.6 wrappers; the logic is in DebouncedInput.
#include "hal/linux/gpio_gpiod.h"

#include <linux/gpio.h>
#include <poll.h>
#include <sys/ioctl.h>

#include <algorithm>
#include <cerrno>
#include <cstdio>
#include <exception>
#include <string>
#include <system_error>

#include "hal/linux/error_text.h"

namespace boticelli::hal_linux {

namespace {

void describe(char* out, std::size_t size, const char* what, const GpioLineConfig& c,
              const std::exception& e) {
  std::snprintf(out, size, "gpio %s:%u: %s: %s", c.chip, c.offset, what, e.what());
}

}  // namespace

DigitalInGpiod::DigitalInGpiod(const GpioLineConfig& config, hal::Clock& clock, bool fail_active)
    : config_(config),
      clock_(clock),
      fail_active_(fail_active),
      filter_(config.active_low, std::uint64_t{config.debounce_ms} * 1000U) {}

bool DigitalInGpiod::init() {
  ok_ = false;
  try {
    chip_ = gpiod::chip(config_.chip, gpiod::chip::OPEN_LOOKUP);
    line_ = chip_.get_line(config_.offset);
    gpiod::line_request req;
    req.consumer = config_.consumer;
    req.request_type = gpiod::line_request::EVENT_BOTH_EDGES;
    if (config_.pull_up) req.flags = gpiod::line_request::FLAG_BIAS_PULL_UP;
    line_.request(req);
    event_fd_ = line_.event_get_fd();
    last_event_us_ = clock_.now_us();
    filter_.reset(line_.get_value() != 0, last_event_us_);
  } catch (const std::exception& e) {
    describe(error_, sizeof error_, "cannot request the input line", config_, e);
    return false;
  }
  ok_ = true;
  error_[0] = '\0';
  return true;
}

void DigitalInGpiod::service() {
  if (!ok_) return;
  try {
    const std::uint64_t now = clock_.now_us();
    for (int i = 0; i < 32; ++i) {  // bounded: a bouncing contact cannot keep us here
      pollfd p{event_fd_, POLLIN, 0};
      if (::poll(&p, 1, 0) <= 0 || (p.revents & POLLIN) == 0) break;
      const gpiod::line_event ev = line_.event_read();
      ++events_;
      // The kernel stamps each edge on CLOCK_MONOTONIC (the Linux board's clock) when it
      // happens; kept in order and never later than now, whatever clock the board uses.
      const auto stamp_ns = static_cast<std::uint64_t>(ev.timestamp.count());
      last_event_us_ = std::clamp(stamp_ns / 1000U, last_event_us_, now);
      filter_.on_edge(ev.event_type == gpiod::line_event::RISING_EDGE, last_event_us_);
    }
    // The kernel's queue holds 16 events and drops the newest when full, so after a long
    // bounce the last edge may be gone: the line's level now has the last word. One ioctl
    // on the event descriptor (GPIOHANDLE_GET_LINE_VALUES_IOCTL), nothing allocated.
    gpiohandle_data level{};
    if (::ioctl(event_fd_, GPIOHANDLE_GET_LINE_VALUES_IOCTL, &level) != 0) {
      set_error(error_, "gpio: reading the input line's level failed", errno);
      ok_ = false;
      return;
    }
    filter_.on_level(level.values[0] != 0, now);
  } catch (const std::exception& e) {
    describe(error_, sizeof error_, "reading events failed", config_, e);
    ok_ = false;
  }
}

bool DigitalInGpiod::read() {
  service();
  if (!ok_) return fail_active_;
  return filter_.active();
}

bool DigitalInGpiod::activated_since_last_poll() {
  service();
  if (!ok_) return fail_active_;
  return filter_.take_activation();
}

DigitalOutGpiod::DigitalOutGpiod(const GpioLineConfig& config) : config_(config) {}

DigitalOutGpiod::~DigitalOutGpiod() {
  close();
}

void DigitalOutGpiod::close() {
  if (line_ != nullptr) ::gpiod_line_release(line_);
  if (chip_ != nullptr) ::gpiod_chip_close(chip_);
  line_ = nullptr;
  chip_ = nullptr;
  ok_ = false;
}

bool DigitalOutGpiod::init() {
  close();
  chip_ = ::gpiod_chip_open_lookup(config_.chip);
  if (chip_ == nullptr) {
    set_error(error_, "gpio: cannot open the chip of the output line", errno);
    return false;
  }
  line_ = ::gpiod_chip_get_line(chip_, config_.offset);
  const bool level = codec::physical_level(config_.initial_active, config_.active_low);
  if (line_ == nullptr ||
      ::gpiod_line_request_output(line_, config_.consumer, level ? 1 : 0) != 0) {
    set_error(error_, "gpio: cannot request the output line", errno);
    line_ = nullptr;  // never requested: nothing to release
    close();
    return false;
  }
  last_ = level ? 1 : 0;
  ok_ = true;
  error_[0] = '\0';
  return true;
}

void DigitalOutGpiod::write(bool active) {
  if (!ok_) return;
  const int level = codec::physical_level(active, config_.active_low) ? 1 : 0;
  if (level == last_) return;
  if (::gpiod_line_set_value(line_, level) != 0) {
    set_error(error_, "gpio: set_value failed", errno);
    ok_ = false;
    return;
  }
  last_ = level;
}

}  // namespace boticelli::hal_linux
