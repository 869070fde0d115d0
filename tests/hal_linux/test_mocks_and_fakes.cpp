// Tests of the test fakes FakeClock and FakeSerialPort (the HAL mocks are exercised where they
// test production code, e.g. tests/firmware/safety/test_safety_mocks.cpp).
#include <cstdint>
#include <cstring>
#include <string>

#include "fake_clock.h"
#include "fake_serial_port.h"

#include "CppUTest/TestHarness.h"

using boticelli::fakes::FakeClock;
using boticelli::fakes::FakeSerialPort;

TEST_GROUP(FakeClock){};

TEST(FakeClock, TimeMovesOnlyWhenTold) {
  FakeClock c(100);
  CHECK_EQUAL(100U, c.now_us());
  CHECK_EQUAL(100U, c.now_us());
  c.advance_us(50);
  CHECK_EQUAL(150U, c.now_us());
}

TEST(FakeClock, SleepingJumpsToTheDeadlineButNeverBackwards) {
  FakeClock c(1000);
  c.sleep_until_us(5000);
  CHECK_EQUAL(5000U, c.now_us());
  c.sleep_until_us(10);
  CHECK_EQUAL(5000U, c.now_us());
  CHECK_EQUAL(2U, c.sleep_calls());
  CHECK_EQUAL(10U, c.last_deadline_us());
  c.set_us(1);
  CHECK_EQUAL(5000U, c.peek_us());
}

TEST(FakeClock, AutoAdvanceMovesTimeOnEveryRead) {
  FakeClock c;
  c.set_auto_advance_us(10);
  CHECK_EQUAL(0U, c.now_us());
  CHECK_EQUAL(10U, c.now_us());
  CHECK_EQUAL(20U, c.peek_us());
}

TEST_GROUP(FakeSerialPort){};

TEST(FakeSerialPort, ReadsWhatWasFedAndKeepsWhatWasWritten) {
  FakeSerialPort p;
  CHECK_TRUE(p.open());
  p.feed("hello");
  std::uint8_t buf[3];
  CHECK_EQUAL(3, p.read(buf, 3));
  MEMCMP_EQUAL("hel", buf, 3);
  CHECK_EQUAL(2, p.read(buf, 3));
  CHECK_EQUAL(0, p.read(buf, 3));
  p.set_write_limit(2);
  CHECK_EQUAL(2, p.write(reinterpret_cast<const std::uint8_t*>("xyz"), 3));
  STRCMP_EQUAL("xy", p.written().c_str());
  p.set_fault(true);
  CHECK_EQUAL(-1, p.read(buf, 3));
}
