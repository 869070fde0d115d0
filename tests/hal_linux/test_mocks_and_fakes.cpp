// Tests of the HAL mocks (expectations are checked) and of FakeClock / FakeSerialPort.
#include <cstdint>
#include <cstring>
#include <string>

#include "fake_clock.h"
#include "fake_serial_port.h"
#include "hal_mocks.h"

#include "CppUTest/TestHarness.h"
#include "CppUTestExt/MockSupport.h"

using boticelli::fakes::FakeClock;
using boticelli::fakes::FakeSerialPort;
namespace hal = boticelli::hal;
namespace mocks = boticelli::mocks;

TEST_GROUP(HalMocks){void teardown() override{mock().checkExpectations();
mock().clear();
}
}
;

TEST(HalMocks, PanTiltMockRecordsTheCommandedAngles) {
  mocks::MockPanTilt ptu;
  mock()
      .expectOneCall("PanTilt.move_to")
      .onObject(&ptu)
      .withParameter("pan_rad", 0.5)
      .withParameter("tilt_rad", -0.25)
      .andReturnValue(false);
  hal::PanTilt& p = ptu;
  CHECK_FALSE(p.move_to(0.5F, -0.25F));
}

TEST(HalMocks, PanTiltMockReturnsTheStateTheTestSet) {
  mocks::MockPanTilt ptu;
  hal::PanTiltState s;
  s.pan_rad = 1.0F;
  s.moving = true;
  ptu.set_state(s);
  mock().expectOneCall("PanTilt.state").onObject(&ptu);
  const hal::PanTiltState got = static_cast<hal::PanTilt&>(ptu).state();
  CHECK_EQUAL(1.0F, got.pan_rad);
  CHECK_TRUE(got.moving);
}

TEST(HalMocks, BaseMockChecksTheVelocitySetpoint) {
  mocks::MockBase base;
  mock()
      .expectOneCall("Base.set_velocity")
      .onObject(&base)
      .withParameter("v_m_s", 0.5)
      .withParameter("omega_rad_s", 0.0);
  mock()
      .expectOneCall("Base.health")
      .onObject(&base)
      .andReturnValue(static_cast<int>(hal::BaseHealth::kStopped));
  hal::Base& b = base;
  b.set_velocity(0.5F, 0.0F);
  CHECK(b.health() == hal::BaseHealth::kStopped);
}

TEST(HalMocks, BaseMockReturnsTheOdometryTheTestSet) {
  mocks::MockBase base;
  hal::Odometry o;
  o.x_m = 2.5;
  base.set_odometry(o);
  mock().expectOneCall("Base.odometry").onObject(&base);
  DOUBLES_EQUAL(2.5, static_cast<hal::Base&>(base).odometry().x_m, 0.0);
}

TEST(HalMocks, CameraMockFillsTheFrameFromTheExpectation) {
  mocks::MockCamera cam;
  static const std::uint8_t pixels[4] = {1, 2, 3, 4};
  hal::Frame f;
  f.data = pixels;
  f.width_px = 2;
  f.sequence = 7;
  mock()
      .expectOneCall("Camera.poll")
      .onObject(&cam)
      .withOutputParameterReturning("frame", &f, sizeof f)
      .andReturnValue(static_cast<int>(hal::CameraPoll::kFrame));
  hal::Frame got;
  CHECK(static_cast<hal::Camera&>(cam).poll(got) == hal::CameraPoll::kFrame);
  POINTERS_EQUAL(pixels, got.data);
  CHECK_EQUAL(7U, got.sequence);
}

TEST(HalMocks, SerialMockReturnsBytesAndChecksWrites) {
  mocks::MockSerialPort port;
  const std::uint8_t in[3] = {'a', 'b', 'c'};
  const std::uint8_t out[2] = {'o', 'k'};
  mock()
      .expectOneCall("SerialPort.read")
      .onObject(&port)
      .withOutputParameterReturning("buffer", in, 3)
      .ignoreOtherParameters()
      .andReturnValue(3L);
  mock()
      .expectOneCall("SerialPort.write")
      .onObject(&port)
      .withMemoryBufferParameter("data", out, 2);
  std::uint8_t buf[8] = {};
  hal::SerialPort& s = port;
  CHECK_EQUAL(3, s.read(buf, sizeof buf));
  MEMCMP_EQUAL(in, buf, 3);
  CHECK_EQUAL(2, s.write(out, 2));
}

TEST(HalMocks, ClockWatchdogAndDigitalMocksRecordTheirCalls) {
  mocks::MockClock clock;
  mocks::MockWatchdog wd;
  mocks::MockDigitalIn estop;
  mocks::MockDigitalOut led;
  mock()
      .expectOneCall("Clock.now_us")
      .onObject(&clock)
      .andReturnValue(static_cast<cpputest_ulonglong>(123456789012ULL));
  mock()
      .expectOneCall("Clock.sleep_until_us")
      .onObject(&clock)
      .withParameter("deadline_us", static_cast<cpputest_ulonglong>(5ULL));
  mock().expectOneCall("Watchdog.start").onObject(&wd).withParameter("timeout_ms", 1000U);
  mock().expectOneCall("Watchdog.kick").onObject(&wd);
  mock().expectOneCall("DigitalIn.activated_since_last_poll").onObject(&estop).andReturnValue(true);
  mock().expectOneCall("DigitalOut.write").onObject(&led).withParameter("active", true);
  CHECK_EQUAL(123456789012ULL, static_cast<hal::Clock&>(clock).now_us());
  static_cast<hal::Clock&>(clock).sleep_until_us(5);
  CHECK_TRUE(static_cast<hal::Watchdog&>(wd).start(1000));
  static_cast<hal::Watchdog&>(wd).kick();
  CHECK_TRUE(static_cast<hal::DigitalIn&>(estop).activated_since_last_poll());
  static_cast<hal::DigitalOut&>(led).write(true);
}

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
