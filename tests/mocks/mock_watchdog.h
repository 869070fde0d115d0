// MockWatchdog: CppUMock mock of hal::Watchdog ("Watchdog.start" with "timeout_ms",
// "Watchdog.kick", ...).
#pragma once

#include "hal/watchdog.h"

#include "CppUTestExt/MockSupport.h"

namespace boticelli::mocks {

class MockWatchdog final : public hal::Watchdog {
 public:
  bool start(std::uint32_t timeout_ms) override {
    return mock()
        .actualCall("Watchdog.start")
        .onObject(this)
        .withParameter("timeout_ms", static_cast<unsigned int>(timeout_ms))
        .returnBoolValueOrDefault(true);
  }
  bool kick() override {
    return mock().actualCall("Watchdog.kick").onObject(this).returnBoolValueOrDefault(true);
  }
  void stop() override { mock().actualCall("Watchdog.stop").onObject(this); }
  const char* error() const override {
    return mock().actualCall("Watchdog.error").onObject(this).returnStringValueOrDefault("");
  }
};

}  // namespace boticelli::mocks
