// FakeClock: manual time for tests.
#include "fake_clock.h"

namespace boticelli::fakes {

std::uint64_t FakeClock::now_us() {
  const std::uint64_t t = now_us_;
  now_us_ += auto_advance_us_;
  return t;
}

void FakeClock::sleep_until_us(std::uint64_t deadline_us) {
  ++sleep_calls_;
  last_deadline_us_ = deadline_us;
  if (deadline_us > now_us_) now_us_ = deadline_us;
}

}  // namespace boticelli::fakes
