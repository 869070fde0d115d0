// Tests of the e-stop latch (firmware::Safety) against CppUMock mocks of its inputs and base:
// which calls it makes on the HAL each poll, not only the state it ends in.
#include "firmware/safety/safety.h"
#include "hal_mocks.h"

#include "CppUTest/TestHarness.h"
#include "CppUTestExt/MockSupport.h"

using boticelli::firmware::Safety;
using boticelli::firmware::StopCause;
namespace hal = boticelli::hal;
namespace mocks = boticelli::mocks;

TEST_GROUP(SafetyWithMocks) {
  mocks::MockDigitalIn button;
  mocks::MockDigitalIn bumper;
  mocks::MockBase base;
  Safety safety{button, bumper, base};

  // One poll's reads of one input: its level and its edge flag.
  void expect_input(mocks::MockDigitalIn & in, bool level, bool edge) {
    mock().expectOneCall("DigitalIn.read").onObject(&in).andReturnValue(level);
    mock().expectOneCall("DigitalIn.activated_since_last_poll").onObject(&in).andReturnValue(edge);
  }
};

TEST(SafetyWithMocks, EveryPollConsumesBothEdgeFlagsEvenWhileAButtonIsHeld) {
  // A press shorter than a frame is seen only through the edge flag: it must be read (and
  // so cleared) every poll, or a stale edge would re-engage the latch after a clear.
  for (int poll = 0; poll < 3; ++poll) {
    expect_input(button, true, poll == 0);
    expect_input(bumper, false, false);
    mock().expectOneCall("Base.stop").onObject(&base);
    safety.poll();
    mock().checkExpectations();
  }
  CHECK(safety.cause() == StopCause::kButton);
  CHECK_EQUAL(1U, safety.engagements());
}

TEST(SafetyWithMocks, QuietInputsAndAReleasedLatchLeaveTheBaseAlone) {
  expect_input(button, false, false);
  expect_input(bumper, false, false);
  safety.poll();  // no call on the base at all (CppUMock fails on an unexpected one)
  CHECK_FALSE(safety.engaged());
}

TEST(SafetyWithMocks, AnEngagedLatchStopsABaseResumedBehindItsBackButNotAStoppedOne) {
  mock().expectOneCall("Base.stop").onObject(&base);
  safety.engage(StopCause::kConsole);
  mock().checkExpectations();
  expect_input(button, false, false);
  expect_input(bumper, false, false);
  mock()
      .expectOneCall("Base.health")
      .onObject(&base)
      .andReturnValue(static_cast<int>(hal::BaseHealth::kReady));
  mock().expectOneCall("Base.stop").onObject(&base);
  safety.poll();
  mock().checkExpectations();
  expect_input(button, false, false);
  expect_input(bumper, false, false);
  mock()
      .expectOneCall("Base.health")
      .onObject(&base)
      .andReturnValue(static_cast<int>(hal::BaseHealth::kStopped));
  safety.poll();
}

TEST(SafetyWithMocks, ClearingReadsBothInputsAndLeavesTheBaseStoppedUntilResume) {
  mock().expectOneCall("Base.stop").onObject(&base);
  safety.engage(StopCause::kConsole);
  mock().expectOneCall("DigitalIn.read").onObject(&button).andReturnValue(true);
  STRCMP_EQUAL("e-stop button still pressed", safety.clear());
  mock().expectOneCall("DigitalIn.read").onObject(&button).andReturnValue(false);
  mock().expectOneCall("DigitalIn.read").onObject(&bumper).andReturnValue(true);
  STRCMP_EQUAL("bumper still in contact", safety.clear());
  mock().checkExpectations();
  // The reset: no call on the base (CppUMock fails on an unexpected one).
  mock().expectOneCall("DigitalIn.read").onObject(&button).andReturnValue(false);
  mock().expectOneCall("DigitalIn.read").onObject(&bumper).andReturnValue(false);
  POINTERS_EQUAL(nullptr, safety.clear());
  CHECK_FALSE(safety.engaged());
  mock().checkExpectations();
  // The restart: the base is asked to resume, once.
  mock().expectOneCall("Base.resume").onObject(&base).andReturnValue(true);
  POINTERS_EQUAL(nullptr, safety.resume());
  CHECK_FALSE(safety.holds());
  POINTERS_EQUAL(nullptr, safety.resume());  // nothing waits for it any more: no call
}
