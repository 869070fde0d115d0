// Tests of the cyclic executive on a fake clock: rates, budgets, overruns, re-anchoring, background
// slices, e-stop.
#include <cstdint>
#include <vector>

#include "fake_clock.h"
#include "firmware/app/device_tasks.h"
#include "firmware/executive/executive.h"
#include "firmware/telemetry/mission_view.h"
#include "firmware/safety/safety.h"
#include "firmware/executive/task_table.h"
#include "firmware_fakes.h"

#include "alloc_guard.h"
#include "CppUTest/TestHarness.h"

using boticelli::fakes::FakeClock;
using namespace boticelli::firmware;
using namespace boticelli::test;

namespace {

// A task that takes `cost_us` of fake time per run (longer on chosen runs).
class TimedTask final : public Task {
 public:
  explicit TimedTask(FakeClock& clock, std::uint64_t cost_us = 0)
      : clock_(clock), cost_us_(cost_us) {}
  void run(std::uint64_t now_us) override {
    ++runs;
    last_start_us = now_us;
    std::uint64_t cost = cost_us_;
    if (slow_every != 0 && runs % slow_every == 0) cost = slow_cost_us;
    clock_.advance_us(cost);
  }
  bool healthy() const override { return healthy_flag; }
  std::uint64_t runs = 0;
  std::uint64_t last_start_us = 0;
  std::uint64_t slow_every = 0;
  std::uint64_t slow_cost_us = 0;
  bool healthy_flag = true;

 private:
  FakeClock& clock_;
  std::uint64_t cost_us_;
};

// Resumable job of `units` units, each costing `unit_us` of fake time.
class CountingWork final : public BackgroundWork {
 public:
  CountingWork(FakeClock& clock, std::uint64_t units, std::uint64_t unit_us)
      : clock_(clock), units_(units), unit_us_(unit_us) {}
  SliceResult run_slice(SliceBudget& budget) override {
    ++slices;
    while (done_units < units_ && budget.next_unit()) {
      clock_.advance_us(unit_us_);
      ++done_units;
      ++total_units;
    }
    if (done_units == units_) {
      done_units = 0;  // next job
      ++jobs;
      return SliceResult::kDone;
    }
    return SliceResult::kMore;
  }
  std::uint64_t done_units = 0;
  std::uint64_t total_units = 0;
  std::uint64_t slices = 0;
  std::uint64_t jobs = 0;

 private:
  FakeClock& clock_;
  std::uint64_t units_;
  std::uint64_t unit_us_;
};

// Records when each frame's first task started.
class StartRecorder final : public Task {
 public:
  void run(std::uint64_t now_us) override {
    if (count < starts.size()) starts[count] = now_us;
    ++count;
  }
  std::array<std::uint64_t, 64> starts{};
  std::size_t count = 0;
};

}  // namespace

TEST_GROUP(Executive) {
  FakeClock clock{1000000};
  Executive exec{clock};
  const char* error = "";
  ExecutiveConfig config;

  void add(const TaskSpec& spec, Task& task) {
    CHECK_TRUE_TEXT(exec.add_task(spec, task, &error), error);
  }
  void start() {
    CHECK_TRUE_TEXT(exec.start(config, &error), error);
  }
  void frames(int n) {
    for (int i = 0; i < n; ++i) exec.run_frame();
  }
};

TEST(Executive, RunsEachTaskAtTheRateOfItsPeriod) {
  TimedTask fast(clock, 100), medium(clock, 100), slow(clock, 100);
  add({"fast", 10000, 500}, fast);
  add({"medium", 20000, 500}, medium);
  add({"slow", 100000, 500}, slow);
  start();
  frames(200);
  CHECK_EQUAL(200U, fast.runs);
  CHECK_EQUAL(100U, medium.runs);
  CHECK_EQUAL(20U, slow.runs);
  CHECK_EQUAL(200U, exec.frame_stats().frames);
  CHECK_EQUAL(0U, exec.frame_stats().overruns);
}

TEST(Executive, StartsFramesOnTheMinorFrameGrid) {
  StartRecorder rec;
  TimedTask work(clock, 3000);
  add({"rec", 10000, 500}, rec);
  add({"work", 10000, 5000}, work);
  start();
  frames(20);
  for (std::size_t i = 0; i < 20; ++i) CHECK_EQUAL(1000000U + i * 10000U, rec.starts[i]);
  CHECK_EQUAL(0U, exec.frame_stats().jitter_worst_us);
}

TEST(Executive, KeepsWorstAverageAndOverrunsPerTask) {
  TimedTask t(clock, 200);
  t.slow_every = 4;
  t.slow_cost_us = 900;  // over the 500 µs budget, inside the frame
  add({"t", 10000, 500}, t);
  start();
  frames(40);
  const TaskStats& s = exec.task_stats(0);
  CHECK_EQUAL(40U, s.runs);
  CHECK_EQUAL(10U, s.overruns);
  CHECK_EQUAL(900U, s.worst_us);
  CHECK_EQUAL((30U * 200U + 10U * 900U) / 40U, s.average_us());
  CHECK_EQUAL(0U, exec.frame_stats().overruns);
}

TEST(Executive, ReanchorsAfterAFrameOverrunInsteadOfRunningMissedFramesInABurst) {
  StartRecorder rec;
  TimedTask hog(clock, 100);
  hog.slow_every = 5;
  hog.slow_cost_us = 35000;  // the 5th frame runs 3.5 frames long
  add({"rec", 10000, 500}, rec);
  add({"hog", 10000, 5000}, hog);
  start();
  frames(8);
  // Frames 0..4 on the grid; frame 4 ends at its start + 35 ms; the next frame starts there
  // and the grid continues from it: no frames squeezed in to catch up.
  for (std::size_t i = 0; i < 5; ++i) CHECK_EQUAL(1000000U + i * 10000U, rec.starts[i]);
  const std::uint64_t overrun_end = rec.starts[4] + 35000U;  // the hog's run; rec costs 0
  CHECK_EQUAL(overrun_end, rec.starts[5]);
  CHECK_EQUAL(overrun_end + 10000U, rec.starts[6]);
  CHECK_EQUAL(overrun_end + 20000U, rec.starts[7]);
  CHECK_EQUAL(1U, exec.frame_stats().overruns);
  CHECK_EQUAL(2U, exec.frame_stats().missed_frames);
  CHECK_EQUAL(1U, exec.task_stats(1).overruns);
}

TEST(Executive, ReportsFrameStartJitter) {
  // A clock whose sleep returns late by 250 µs once: the jitter shows it.
  class LateClock final : public boticelli::hal::Clock {
   public:
    std::uint64_t now_us() override { return t; }
    void sleep_until_us(std::uint64_t d) override {
      ++sleeps;
      if (d > t) t = d;
      if (sleeps == 3) t += 250;
    }
    std::uint64_t t = 0;
    int sleeps = 0;
  } late;
  Executive e(late);
  TimedTask none(clock, 0);
  CHECK(e.add_task({"t", 10000, 500}, none, &error));
  CHECK(e.start(config, &error));
  for (int i = 0; i < 10; ++i) e.run_frame();
  CHECK_EQUAL(250U, e.frame_stats().jitter_worst_us);
  CHECK_EQUAL(25U, e.frame_stats().jitter_average_us());
}

TEST(Executive, EndsEveryBackgroundSliceBeforeTheFrameMargin) {
  TimedTask t(clock, 2000);
  CountingWork work(clock, 1000000, 100);  // never finishes within the test
  add({"t", 10000, 3000}, t);
  exec.set_background(&work);
  config.background_margin_us = 1000;
  start();
  frames(100);
  // Each frame: 2 ms of task, then background until 1 ms before the next frame.
  CHECK_EQUAL(0U, exec.frame_stats().overruns);
  CHECK_EQUAL(0U, exec.frame_stats().background_overruns);
  CHECK_EQUAL(100U, exec.frame_stats().background_slices);
  CHECK_EQUAL(100U * 70U, work.total_units);
  CHECK_EQUAL(700U, exec.frame_stats().background_per_mille());
}

TEST(Executive, ResumesBackgroundWorkAcrossSlicesUntilItIsDone) {
  CountingWork work(clock, 250, 100);  // 25 ms of work per job
  TimedTask t(clock, 1000);
  add({"t", 10000, 2000}, t);
  exec.set_background(&work);
  config.background_margin_us = 1000;
  start();
  frames(3);  // 8 ms per slice: 80 + 80 + 80 units
  CHECK_EQUAL(0U, work.jobs);
  CHECK_EQUAL(240U, work.done_units);
  frames(1);
  CHECK_EQUAL(1U, work.jobs);
  CHECK_EQUAL(1U, exec.frame_stats().background_done);
  frames(16);
  CHECK_EQUAL(250U * work.jobs + work.done_units, work.total_units);
  CHECK_EQUAL(work.jobs, exec.frame_stats().background_done);
  CHECK_EQUAL(0U, exec.frame_stats().overruns);
}

TEST(Executive, HonoursTheLongestSliceParameter) {
  CountingWork work(clock, 1000000, 100);
  TimedTask t(clock, 0);
  add({"t", 10000, 500}, t);
  exec.set_background(&work);
  config.background_max_slice_us = 2000;
  start();
  frames(10);
  CHECK_EQUAL(10U * 20U, work.total_units);
}

TEST(Executive, LimitsUnitsPerSliceOnALockstepClockThatStandsStillWhileWorking) {
  // The sim board's clock moves only in sleep_until_us: the unit limit bounds each slice.
  CountingWork work(clock, 12, 0);
  TimedTask t(clock, 0);
  add({"t", 10000, 500}, t);
  exec.set_background(&work);
  config.background_units_per_slice = 5;
  start();
  frames(2);
  CHECK_EQUAL(10U, work.total_units);
  frames(1);
  CHECK_EQUAL(1U, work.jobs);
}

TEST(Executive, GivesNoSlicesToPausedBackgroundWork) {
  CountingWork work(clock, 10, 100);
  TimedTask t(clock, 0);
  add({"t", 10000, 500}, t);
  exec.set_background(&work);
  start();
  exec.set_background_paused(true);
  frames(10);
  CHECK_EQUAL(0U, work.slices);
  exec.set_background_paused(false);
  frames(1);
  CHECK_EQUAL(1U, work.slices);
}

TEST(Executive, CountsABackgroundSliceThatRunsPastItsDeadline) {
  class Greedy final : public BackgroundWork {
   public:
    explicit Greedy(FakeClock& c) : clock(c) {}
    SliceResult run_slice(SliceBudget&) override {
      clock.advance_us(9500);  // ignores the budget
      return SliceResult::kMore;
    }
    FakeClock& clock;
  } greedy(clock);
  TimedTask t(clock, 1000);
  add({"t", 10000, 2000}, t);
  exec.set_background(&greedy);
  start();
  frames(3);
  CHECK_EQUAL(3U, exec.frame_stats().background_overruns);
  CHECK_EQUAL(3U, exec.frame_stats().overruns);
}

TEST(Executive, IsUnhealthyWhileATaskReportsAFaultOrKeepsOverrunning) {
  TimedTask t(clock, 100);
  add({"t", 10000, 500}, t);
  start();
  frames(5);
  CHECK_TRUE(exec.all_healthy());
  t.healthy_flag = false;
  CHECK_FALSE(exec.all_healthy());
  t.healthy_flag = true;
  t.slow_every = 1;
  t.slow_cost_us = 600;
  frames(2);
  CHECK_TRUE(exec.all_healthy());  // two overruns in a row are tolerated
  frames(1);
  CHECK_FALSE(exec.all_healthy());
  t.slow_every = 0;
  frames(1);
  CHECK_TRUE(exec.all_healthy());
}

TEST(Executive, RefusesATableThatDoesNotFitTheFrame) {
  TimedTask t(clock, 0);
  add({"odd", 15000, 500}, t);
  CHECK_FALSE(exec.start(config, &error));
  STRCMP_CONTAINS("multiple of the minor frame", error);
  Executive e2(clock);
  CHECK(e2.add_task({"fat", 10000, 10000}, t, &error));
  CHECK_FALSE(e2.start(config, &error));
  CHECK_FALSE(e2.add_task({"", 10000, 100}, t, &error));
}

TEST(Executive, TheFirmwareTaskTableFitsItsMinorFrameWithRoomForBackground) {
  std::uint32_t per_frame_worst_us = 0;
  for (const TaskSpec& s : kTaskTable) per_frame_worst_us += s.budget_us;
  CHECK(per_frame_worst_us + ExecutiveConfig{}.background_margin_us < kDefaultMinorFrameUs);
  STRCMP_EQUAL("estop", kTaskTable[0].name);  // e-stop first in every frame
  CHECK_EQUAL(kDefaultMinorFrameUs, task_spec(TaskId::kEstop).period_us);
}

TEST(Executive, RunsFramesWithoutAllocatingAfterStart) {
  TimedTask a(clock, 300), b(clock, 700);
  CountingWork work(clock, 333, 50);
  add({"a", 10000, 500}, a);
  add({"b", 20000, 1000}, b);
  exec.set_background(&work);
  start();
  CHECK_NO_ALLOCATION(frames(500));
  CHECK(work.jobs > 0);
}

TEST_GROUP(EstopInTheExecutive) {
  FakeClock clock{0};
  FakeInput button, bumper;
  FakeBase base{&clock};
  Safety safety{button, bumper, base};
  EstopTask estop_task{safety};
  Executive exec{clock};
  const char* error = "";
};

TEST(EstopInTheExecutive, StopsTheBaseWithinOneFrameWhileTheBackgroundUsesEveryFrame) {
  // Background work that always wants more time, uses every slice fully and presses the
  // button in the middle of its slice at chosen times.
  class PressingHog final : public BackgroundWork {
   public:
    PressingHog(FakeClock& c, FakeInput& b) : clock(c), button(b) {}
    SliceResult run_slice(SliceBudget& budget) override {
      while (budget.next_unit()) {
        clock.advance_us(37);
        ++units;
        if (press_at_us != 0 && clock.peek_us() >= press_at_us) {
          button.press();
          pressed_at_us = clock.peek_us();
          press_at_us = 0;
        }
      }
      return SliceResult::kMore;
    }
    FakeClock& clock;
    FakeInput& button;
    std::uint64_t press_at_us = 0;
    std::uint64_t pressed_at_us = 0;
    std::uint64_t units = 0;
  } hog(clock, button);
  TimedTask other(clock, 1500);
  CHECK(exec.add_task(kTaskTable[0], estop_task, &error));
  CHECK(exec.add_task({"other", 10000, 2000}, other, &error));
  exec.set_background(&hog);
  CHECK(exec.start(ExecutiveConfig{}, &error));
  for (std::uint64_t press_us : {23456U, 51001U, 99999U}) {
    hog.press_at_us = press_us;
    while (hog.press_at_us != 0) exec.run_frame();
    exec.run_frame();
    CHECK(base.health() == boticelli::hal::BaseHealth::kStopped);
    CHECK(base.stopped_at_us - hog.pressed_at_us <= ExecutiveConfig{}.frame_us);
    button.level = false;
    CHECK(safety.clear() == nullptr);
    CHECK(safety.resume() == nullptr);
  }
  CHECK(hog.units > 1000U);
}

TEST_GROUP(WatchdogTask) {
  FakeClock clock{0};
  Executive exec{clock};
  FakeWatchdog watchdog;
  FakeOutput led;
  ServiceNotifier notifier;  // NOTIFY_SOCKET unset in tests: sends are no-ops
  WatchdogTask task{exec, watchdog, notifier, led};
  const char* error = "";
};

TEST(WatchdogTask, KicksOnlyWhileEveryTaskIsHealthy) {
  TimedTask device(clock, 10);
  CHECK(exec.add_task({"device", 10000, 500}, device, &error));
  CHECK(exec.add_task({"watchdog", 100000, 200}, task, &error));
  CHECK(exec.start(ExecutiveConfig{}, &error));
  for (int i = 0; i < 50; ++i) exec.run_frame();
  CHECK_EQUAL(5, watchdog.kicks);
  device.healthy_flag = false;
  for (int i = 0; i < 50; ++i) exec.run_frame();
  CHECK_EQUAL(5, watchdog.kicks);
  CHECK_EQUAL(5U, task.withheld());
  CHECK_FALSE(led.level);
  device.healthy_flag = true;
  for (int i = 0; i < 50; ++i) exec.run_frame();
  CHECK_EQUAL(10, watchdog.kicks);
}

namespace {
class StateView final : public MissionView {
 public:
  const char* state_name() const override { return "drive"; }
  boticelli::core::Pose2 pose() const override { return {}; }
  float pan_rad() const override { return 0.0F; }
  std::uint64_t cycles() const override { return 7; }
  TargetEstimate target() const override { return {status, 2, 1.0F, 2.0F, 0.3F}; }
  TargetStatus status = TargetStatus::kNone;
};
}  // namespace

// The LED levels of the next second (ten watchdog runs, 100 frames), bit i = run i.
static unsigned led_second(Executive& exec, const FakeOutput& led) {
  unsigned bits = 0;
  for (unsigned run = 0; run < 10; ++run) {
    for (int f = 0; f < 10; ++f) exec.run_frame();
    if (led.level) bits |= 1U << run;
  }
  return bits;
}

TEST(WatchdogTask, ShowsOkEstopFaultAndTargetFoundAsDistinctLedPatterns) {
  FakeInput button, bumper;
  FakeBase base;
  Safety safety{button, bumper, base};
  StateView view;
  task.set_status_sources(&safety, &view);
  TimedTask device(clock, 10);
  CHECK(exec.add_task({"device", 10000, 500}, device, &error));
  CHECK(exec.add_task({"watchdog", 100000, 200}, task, &error));
  CHECK(exec.start(ExecutiveConfig{}, &error));
  // The patterns differ from each other, and each is what the LED shows.
  const LedPattern all[] = {LedPattern::kOk, LedPattern::kEstop, LedPattern::kFault,
                            LedPattern::kTargetFound};
  for (const LedPattern a : all) {
    for (const LedPattern b : all) {
      if (a != b) CHECK(led_pattern_bits(a) != led_pattern_bits(b));
    }
  }
  CHECK_EQUAL(led_pattern_bits(LedPattern::kOk), led_second(exec, led));
  CHECK(task.pattern() == LedPattern::kOk);
  STRCMP_EQUAL("state=drive cycle=7 healthy=1 estop=none target=none", task.status_text());
  view.status = TargetStatus::kSeen;  // one view is not yet the target found
  CHECK_EQUAL(led_pattern_bits(LedPattern::kOk), led_second(exec, led));
  view.status = TargetStatus::kConfirmed;
  CHECK_EQUAL(led_pattern_bits(LedPattern::kTargetFound), led_second(exec, led));
  STRCMP_EQUAL("state=drive cycle=7 healthy=1 estop=none target=confirmed", task.status_text());
  safety.engage(StopCause::kConsole);  // the e-stop outranks the target
  CHECK_EQUAL(led_pattern_bits(LedPattern::kEstop), led_second(exec, led));
  STRCMP_EQUAL("state=drive cycle=7 healthy=1 estop=console target=confirmed", task.status_text());
  device.healthy_flag = false;  // and a fault outranks everything
  CHECK_EQUAL(led_pattern_bits(LedPattern::kFault), led_second(exec, led));
  STRCMP_EQUAL("state=drive cycle=7 healthy=0 estop=console target=confirmed", task.status_text());
  CHECK_EQUAL(10U, task.withheld());
}

TEST_GROUP(CameraTask) {
  FakeCamera camera;
  CameraTask task{camera, 2000000};
};

TEST(CameraTask, HandsEachFrameBackAndTurnsUnhealthyOnlyAfterAStall) {
  class Counter final : public FrameConsumer {
   public:
    void on_frame(const boticelli::hal::Frame& f) override {
      last_sequence = f.sequence;
      ++frames;
    }
    std::uint32_t last_sequence = 0;
    int frames = 0;
  } consumer;
  task.set_consumer(&consumer);
  std::uint64_t t = 0;
  for (int i = 0; i < 30; ++i, t += 10000) task.run(t);
  CHECK_EQUAL(10, consumer.frames);
  CHECK_EQUAL(10, camera.releases);
  CHECK(task.healthy());
  camera.fault = true;  // the driver re-opens the device meanwhile
  for (; t < 290000 + 1900000; t += 10000) task.run(t);
  CHECK(task.healthy());
  for (; t < 290000 + 2200000; t += 10000) task.run(t);
  CHECK_FALSE(task.healthy());
  camera.fault = false;
  for (int i = 0; i < 3; ++i, t += 10000) task.run(t);
  CHECK(task.healthy());
}

TEST(Executive, CountsATaskStarvedByALongStallAsUnhealthyUntilItRunsAgain) {
  TimedTask fast(clock, 100);
  TimedTask slow(clock, 100);
  fast.slow_every = 30;
  fast.slow_cost_us = 450000;  // one 450 ms stall in frame 30
  add({"fast", 10000, 500}, fast);
  add({"slow", 100000, 500}, slow);
  start();
  frames(29);
  CHECK_TRUE(exec.all_healthy());
  frames(1);  // the stall: "slow" last ran more than two periods ago
  CHECK_FALSE(exec.all_healthy());
  std::uint64_t slow_runs = slow.runs;
  while (slow.runs == slow_runs) exec.run_frame();
  fast.slow_every = 0;
  exec.run_frame();
  CHECK_TRUE(exec.all_healthy());
}
