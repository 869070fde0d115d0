// Tests of the safety part: the e-stop latch (Safety) and the rule that ends a held mission
// after a button stop (ButtonRelease).
#include <cstdint>

#include "firmware/safety/button_release.h"
#include "firmware/safety/safety.h"
#include "firmware_fakes.h"

#include "CppUTest/TestHarness.h"

using boticelli::firmware::ButtonRelease;
using boticelli::firmware::Safety;
using boticelli::firmware::StopCause;
using boticelli::test::FakeBase;
using boticelli::test::FakeInput;

TEST_GROUP(Safety) {
  FakeInput button, bumper;
  FakeBase base;
  Safety safety{button, bumper, base};
};

TEST(Safety, ACatchesAPressShorterThanAFrameThroughTheEdge) {
  button.edge = true;  // pressed and released between two polls
  safety.poll();
  CHECK(safety.engaged());
  CHECK(safety.cause() == StopCause::kButton);
  CHECK(base.health() == boticelli::hal::BaseHealth::kStopped);
}

TEST(Safety, ABumperTapShorterThanAFrameStopsTheBaseAndCountsAsACollision) {
  bumper.edge = true;  // touched and released between two polls
  safety.poll();
  CHECK(safety.engaged());
  CHECK(safety.cause() == StopCause::kBumper);
  CHECK_EQUAL(1U, safety.collisions());
  CHECK(base.health() == boticelli::hal::BaseHealth::kStopped);
}

TEST(Safety, StaysLatchedUntilClearedAndRefusesToClearWhileAnInputIsActive) {
  bumper.level = true;
  safety.poll();
  CHECK(safety.cause() == StopCause::kBumper);
  CHECK_EQUAL(1U, safety.collisions());
  safety.poll();
  CHECK_EQUAL(1U, safety.collisions());
  STRCMP_EQUAL("bumper still in contact", safety.clear());
  CHECK(safety.engaged());
  bumper.level = false;
  safety.poll();
  CHECK(safety.engaged());
  base.refuse_resume = true;
  STRCMP_EQUAL("base cannot resume", safety.clear());
  CHECK(safety.engaged());
  base.refuse_resume = false;
  CHECK(safety.clear() == nullptr);
  CHECK_FALSE(safety.engaged());
  CHECK(base.health() == boticelli::hal::BaseHealth::kReady);
}

TEST(Safety, ABumperReleasedAndHitAgainBetweenTwoPollsCountsAsASecondCollision) {
  bumper.press();
  safety.poll();
  CHECK_EQUAL(1U, safety.collisions());
  safety.poll();  // still in contact: the same collision
  CHECK_EQUAL(1U, safety.collisions());
  bumper.edge = true;  // let go and hit again within one frame: the level never dropped
  safety.poll();
  CHECK_EQUAL(2U, safety.collisions());
  bumper.level = false;
  safety.poll();
  bumper.press();  // a new contact after a poll saw it released
  safety.poll();
  CHECK_EQUAL(3U, safety.collisions());
  CHECK(safety.cause() == StopCause::kBumper);
}

TEST(Safety, StopsTheBaseAgainIfSomethingResumesItBehindTheLatch) {
  safety.engage(StopCause::kConsole);
  base.health_ = boticelli::hal::BaseHealth::kReady;
  safety.poll();
  CHECK(base.health() == boticelli::hal::BaseHealth::kStopped);
}

TEST(Safety, ABaseResumedWhileTheButtonIsHeldIsStoppedAgainAtTheNextPoll) {
  button.level = true;
  safety.poll();
  CHECK(base.health() == boticelli::hal::BaseHealth::kStopped);
  CHECK(base.resume());  // something resumes the base while the button is still held
  safety.poll();
  CHECK(base.health() == boticelli::hal::BaseHealth::kStopped);
  CHECK_EQUAL(1U, safety.engagements());  // the same engagement, stopped again
}

TEST(Safety, EngagingALatchThatIsAlreadyEngagedStopsTheBaseAgainAndKeepsTheFirstCause) {
  safety.engage(StopCause::kButton);
  CHECK(base.resume());
  safety.engage(StopCause::kConsole);
  CHECK(base.health() == boticelli::hal::BaseHealth::kStopped);
  CHECK(safety.cause() == StopCause::kButton);
  CHECK_EQUAL(2, base.stops);
}

TEST_GROUP(ButtonRelease) {
  FakeInput button, bumper;
  FakeBase base;
  Safety safety{button, bumper, base};
  ButtonRelease release{500000};

  // Presses the button and polls: the latch engages for the button.
  void press() {
    button.level = true;
    safety.poll();
    release.restart();  // the mission's hold begins
  }
  // One frame of the hold at `now_us`; true when it cleared the latch.
  bool frame(std::uint64_t now_us) {
    safety.poll();
    return safety.engaged() && release.update(safety, button, now_us);
  }
};

TEST(ButtonRelease, ClearsAButtonStopOnceTheButtonStayedReleasedForTheHoldTime) {
  press();
  CHECK_FALSE(frame(1000000));  // still held
  button.level = false;
  CHECK_FALSE(frame(1010000));  // released: the wait starts
  CHECK_FALSE(frame(1500000));  // 0.49 s
  CHECK(frame(1510000));        // 0.5 s
  CHECK_FALSE(safety.engaged());
}

TEST(ButtonRelease, APressDuringTheWaitStartsItAgain) {
  press();
  button.level = false;
  CHECK_FALSE(frame(1000000));
  button.level = true;  // pressed again 0.3 s later ...
  CHECK_FALSE(frame(1300000));
  button.level = false;  // ... and released
  CHECK_FALSE(frame(1310000));
  CHECK_FALSE(frame(1600000));  // 0.6 s after the first release, 0.29 s after the second
  CHECK(safety.engaged());
  CHECK(frame(1810000));
}

TEST(ButtonRelease, ANewHoldDoesNotCountAReleaseSeenInTheLastOne) {
  press();
  button.level = false;
  CHECK_FALSE(frame(1000000));
  CHECK(frame(1500000));  // the first hold ends after its release
  // A tap shorter than a frame: the latch engages by the edge, the button already up.
  button.edge = true;
  safety.poll();
  CHECK(safety.engaged());
  release.restart();            // the new hold begins
  CHECK_FALSE(frame(3000000));  // its wait starts now, not at the first hold's release
  CHECK_FALSE(frame(3400000));
  CHECK(safety.engaged());
  CHECK(frame(3500000));
}

TEST(ButtonRelease, LeavesAConsoleOrBumperStopToItsOwnClear) {
  safety.engage(StopCause::kConsole);
  release.restart();
  CHECK_FALSE(frame(1000000));
  CHECK_FALSE(frame(2000000));
  CHECK(safety.engaged());
  bumper.level = true;
  safety.poll();
  bumper.level = false;
  CHECK_FALSE(frame(3000000));
  CHECK(safety.engaged());
}
