// Tests of the safety part: the e-stop latch (Safety), which only the operator's `clear-estop`
// (the reset) and then `resume` (the restart) release.
#include "firmware/safety/safety.h"
#include "firmware_fakes.h"

#include "CppUTest/TestHarness.h"

using boticelli::firmware::awaited_command;
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
  CHECK(safety.engaged());  // the bumper let go: still latched
  button.level = true;      // and the button pressed meanwhile
  safety.poll();
  STRCMP_EQUAL("e-stop button still pressed", safety.clear());
  CHECK(safety.cause() == StopCause::kBumper);
  button.level = false;
  safety.poll();
  CHECK(safety.clear() == nullptr);
  CHECK_FALSE(safety.engaged());
}

TEST(Safety, AReleasedButtonNeverClearsTheLatch) {
  button.level = true;
  safety.poll();
  button.level = false;
  // An hour of 10 ms frames with the button up (or a line that came back): still latched.
  for (int frame = 0; frame < 360000; ++frame) safety.poll();
  CHECK(safety.engaged());
  CHECK(safety.cause() == StopCause::kButton);
  CHECK(safety.holds());
  CHECK(base.health() == boticelli::hal::BaseHealth::kStopped);
  CHECK_EQUAL(1U, safety.engagements());
}

TEST(Safety, AChatteringButtonKeepsTheLatchEngagedThroughEveryRelease) {
  for (int frame = 0; frame < 1000; ++frame) {
    button.level = frame % 7 < 2;  // pressed two frames in seven
    safety.poll();
    CHECK(safety.engaged());
    CHECK(base.health() == boticelli::hal::BaseHealth::kStopped);
  }
  CHECK_EQUAL(1U, safety.engagements());
}

TEST(Safety, AfterTheResetTheBaseStaysStoppedUntilResume) {
  button.level = true;
  safety.poll();
  button.level = false;
  safety.poll();
  CHECK(safety.clear() == nullptr);  // the reset
  CHECK_FALSE(safety.engaged());
  CHECK(safety.cause() == StopCause::kNone);
  CHECK(safety.awaiting_resume());
  CHECK(safety.holds());
  CHECK(base.health() == boticelli::hal::BaseHealth::kStopped);  // restarts nothing
  for (int frame = 0; frame < 1000; ++frame) safety.poll();
  CHECK(safety.holds());
  CHECK(base.health() == boticelli::hal::BaseHealth::kStopped);
  CHECK(safety.resume() == nullptr);  // the restart
  CHECK_FALSE(safety.holds());
  CHECK(base.health() == boticelli::hal::BaseHealth::kReady);
  safety.poll();
  CHECK(base.health() == boticelli::hal::BaseHealth::kReady);
}

TEST(Safety, ABaseResumedBehindItsBackAfterTheResetIsStoppedAgainAtTheNextPoll) {
  safety.engage(StopCause::kConsole);
  CHECK(safety.clear() == nullptr);
  CHECK(base.resume());  // something other than `resume` restarts the base
  safety.poll();
  CHECK(base.health() == boticelli::hal::BaseHealth::kStopped);
  CHECK(safety.awaiting_resume());
}

TEST(Safety, ResumeIsRefusedWhileTheLatchIsEngagedAndDoesNotCountAsTheRestartAfterIt) {
  button.level = true;
  safety.poll();
  button.level = false;
  safety.poll();
  STRCMP_EQUAL("e-stop latched: clear-estop first", safety.resume());
  CHECK(safety.engaged());
  CHECK(base.health() == boticelli::hal::BaseHealth::kStopped);
  CHECK(safety.clear() == nullptr);
  CHECK(safety.holds());  // the refused resume before the reset does not count
  CHECK(base.health() == boticelli::hal::BaseHealth::kStopped);
}

TEST(Safety, ABaseThatCannotResumeKeepsTheRobotWaitingForResume) {
  safety.engage(StopCause::kConsole);
  CHECK(safety.clear() == nullptr);
  base.refuse_resume = true;
  STRCMP_EQUAL("base cannot resume", safety.resume());
  CHECK(safety.awaiting_resume());
  base.refuse_resume = false;
  CHECK(safety.resume() == nullptr);
  CHECK_FALSE(safety.holds());
}

TEST(Safety, APressAfterTheResetLatchesAgainAndNeedsAnotherReset) {
  safety.engage(StopCause::kConsole);
  CHECK(safety.clear() == nullptr);
  button.press();
  safety.poll();
  CHECK(safety.cause() == StopCause::kButton);
  STRCMP_EQUAL("e-stop latched: clear-estop first", safety.resume());
  button.level = false;
  safety.poll();
  CHECK(safety.clear() == nullptr);
  CHECK(safety.resume() == nullptr);
  CHECK_FALSE(safety.holds());
  CHECK(base.health() == boticelli::hal::BaseHealth::kReady);
}

TEST(Safety, NamesWhatTheOperatorMustTypeNext) {
  STRCMP_EQUAL("none", awaited_command(safety, false));
  STRCMP_EQUAL("resume", awaited_command(safety, true));  // paused
  safety.engage(StopCause::kButton);
  STRCMP_EQUAL("clear-estop", awaited_command(safety, false));
  STRCMP_EQUAL("clear-estop", awaited_command(safety, true));
  CHECK(safety.clear() == nullptr);
  STRCMP_EQUAL("resume", awaited_command(safety, false));
  CHECK(safety.resume() == nullptr);
  STRCMP_EQUAL("none", awaited_command(safety, false));
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

TEST(Safety, ClearingWhenNoStopIsLatchedLeavesABaseThatStoppedForAFaultStopped) {
  base.health_ = boticelli::hal::BaseHealth::kStopped;  // the base stopped itself: a fault
  CHECK(safety.clear() == nullptr);                     // clear-estop with nothing latched
  CHECK_FALSE(safety.awaiting_resume());
  CHECK_FALSE(safety.holds());
  CHECK(safety.resume() == nullptr);  // nothing waits for it: the base is not asked to resume
  CHECK_EQUAL(0, base.resume_calls);
  CHECK(base.health() == boticelli::hal::BaseHealth::kStopped);
}
