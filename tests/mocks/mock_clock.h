// MockClock: CppUMock mock of hal::Clock ("Clock.now_us", "Clock.sleep_until_us"); see also
// FakeClock.
#pragma once

#include "hal/clock.h"

#include "CppUTestExt/MockSupport.h"

namespace boticelli::mocks {

class MockClock final : public hal::Clock {
 public:
  std::uint64_t now_us() override {
    return static_cast<std::uint64_t>(mock()
                                          .actualCall("Clock.now_us")
                                          .onObject(this)
                                          .returnUnsignedLongLongIntValueOrDefault(0ULL));
  }
  void sleep_until_us(std::uint64_t deadline_us) override {
    mock()
        .actualCall("Clock.sleep_until_us")
        .onObject(this)
        .withParameter("deadline_us", static_cast<cpputest_ulonglong>(deadline_us));
  }
};

}  // namespace boticelli::mocks
