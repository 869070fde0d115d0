// Tests of the cyclic executive on a fake clock: rates, budgets, overruns, re-anchoring, background
// slices, e-stop.
#include <cstdint>
#include <vector>

#include "fake_clock.h"
#include "firmware/app/device_tasks.h"
#include "firmware/executive/duration_histogram.h"
#include "firmware/executive/executive.h"
#include "firmware/executive/host_timing_text.h"
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

namespace {

// A task that takes no board time (the sim board's lockstep clock) but spends host time:
// `wall_us`/`cpu_us` per run, `slow_wall_us`/`slow_cpu_us` on every `slow_every`-th run.
class HostTimedTask final : public Task {
 public:
  HostTimedTask(FakeHostClock& host, std::uint64_t wall_us, std::uint64_t cpu_us)
      : host_(host), wall_us_(wall_us), cpu_us_(cpu_us) {}
  void run(std::uint64_t) override {
    ++runs;
    if (slow_every != 0 && runs % slow_every == 0) {
      host_.spend(slow_wall_us * 1000U, slow_cpu_us * 1000U);
    } else {
      host_.spend(wall_us_ * 1000U, cpu_us_ * 1000U);
    }
  }
  std::uint64_t runs = 0;
  std::uint64_t slow_every = 0;
  std::uint64_t slow_wall_us = 0;
  std::uint64_t slow_cpu_us = 0;

 private:
  FakeHostClock& host_;
  std::uint64_t wall_us_;
  std::uint64_t cpu_us_;
};

// Background work whose units each spend `unit_us` of host time (wall and CPU) and no board
// time; it never finishes.
class HostTimedWork final : public BackgroundWork {
 public:
  HostTimedWork(FakeHostClock& host, std::uint64_t unit_us) : host_(host), unit_us_(unit_us) {}
  SliceResult run_slice(SliceBudget& budget) override {
    std::uint32_t units = 0;
    while (budget.next_unit()) {
      host_.spend(unit_us_ * 1000U, unit_us_ * 1000U);
      ++units;
    }
    last_slice_units = units;
    ++slices;
    return SliceResult::kMore;
  }
  std::uint32_t last_slice_units = 0;
  std::uint64_t slices = 0;

 private:
  FakeHostClock& host_;
  std::uint64_t unit_us_;
};

}  // namespace

TEST_GROUP(ExecutiveHostTiming) {
  FakeClock clock{1000000};  // the board's: moves only in sleep_until_us (lockstep)
  FakeHostClock host;
  Executive exec{clock, &host};
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

TEST(ExecutiveHostTiming, TimesEachTaskBodyOnTheHostWhileTheBoardsClockStandsStill) {
  HostTimedTask fast(host, 40, 30);
  HostTimedTask slow(host, 300, 120);
  slow.slow_every = 10;  // one run in ten: 900 µs wall (preempted), 700 µs CPU
  slow.slow_wall_us = 900;
  slow.slow_cpu_us = 700;
  add({"fast", 10000, 200}, fast);
  add({"slow", 20000, 500}, slow);
  start();
  frames(400);
  // The board's figures are true and empty: its time did not move while the tasks ran.
  CHECK_EQUAL(0U, exec.task_stats(0).worst_us);
  CHECK_EQUAL(0U, exec.task_stats(1).overruns);
  const HostTiming& f = exec.host_task_timing(0);
  CHECK_EQUAL(400U, f.wall.count());
  CHECK_EQUAL(40000U, f.wall.max_ns());
  CHECK_EQUAL(40000U, f.wall.average_ns());
  CHECK_EQUAL(30000U, f.cpu.max_ns());
  const HostTiming& s = exec.host_task_timing(1);
  CHECK_EQUAL(200U, s.wall.count());
  CHECK_EQUAL(900000U, s.wall.max_ns());
  CHECK_EQUAL(700000U, s.cpu.max_ns());
  CHECK_EQUAL((180U * 120000U + 20U * 700000U) / 200U, s.cpu.average_ns());
  // 10% of the runs are slow: the 99th percentile is a slow run, the 50th a normal one
  // (bucket edges: at most 1/32 above the value, never below).
  CHECK(s.cpu.percentile_ns(990) >= 700000U && s.cpu.percentile_ns(990) <= 700000U);
  CHECK(s.cpu.percentile_ns(500) >= 120000U && s.cpu.percentile_ns(500) <= 120000U * 33 / 32);
  // A frame's work is its tasks and slice from its start: the worst frame ran both tasks.
  CHECK_EQUAL(400U, exec.host_frame_stats().work.wall.count());
  CHECK_EQUAL(940000U, exec.host_frame_stats().work.wall.max_ns());
  CHECK_EQUAL(730000U, exec.host_frame_stats().work.cpu.max_ns());
  exec.reset_stats();
  CHECK_EQUAL(0U, exec.host_task_timing(1).wall.count());
  CHECK_EQUAL(0U, exec.host_frame_stats().work.wall.count());
}

TEST(ExecutiveHostTiming, TimesBackgroundSlicesAndCountsThosePastTheirShareOfTheFrame) {
  // Lockstep: 32 units per slice, as the sim board runs; each unit 400 µs of host time, so
  // every slice takes 12.8 ms on the host, past the 9 ms the frame leaves it.
  HostTimedTask t(host, 100, 100);
  HostTimedWork work(host, 400);
  add({"t", 10000, 500}, t);
  exec.set_background(&work);
  config.background_units_per_slice = 32;
  start();
  frames(20);
  const HostFrameStats& f = exec.host_frame_stats();
  CHECK_EQUAL(20U, f.slice.wall.count());
  CHECK_EQUAL(32U * 400000U, f.slice.wall.max_ns());
  CHECK_EQUAL(32U * 400000U, f.slice.cpu.max_ns());
  CHECK_EQUAL(20U, f.slice_overruns);
  CHECK_EQUAL((100U + 32U * 400U - 9000U) * 1000U, f.slice_overshoot_worst_ns);
  CHECK_EQUAL(0U, exec.frame_stats().background_overruns);  // the board saw no time pass
}

TEST(ExecutiveHostTiming, EndsSlicesByTheHostsClockWhenToldSo) {
  // As on the robot: no unit count, the slice ends when the host's clock reaches the frame's
  // end minus the margin, counted from the frame's start on the host (the task's 1.5 ms too),
  // and no unit is begun that would end after that, by the longest unit so far.
  HostTimedTask t(host, 1500, 1500);
  HostTimedWork work(host, 1000);
  add({"t", 10000, 2000}, t);
  exec.set_background(&work);
  config.slices_on_host_clock = true;
  config.background_margin_us = 1000;
  start();
  frames(5);
  // 10 ms − 1 ms margin − 1.5 ms task = 7.5 ms: units of 1 ms start at 0, 1, … 6 ms into the
  // slice; one at 7 ms would end 0.5 ms past its limit.
  CHECK_EQUAL(7U, work.last_slice_units);
  CHECK_EQUAL(5U, work.slices);
  CHECK_EQUAL(0U, exec.host_frame_stats().slice_overruns);
  CHECK_EQUAL(0U, exec.host_frame_stats().slice_overshoot_worst_ns);
  // The longest-slice setting bounds it on the host clock too: 3 ms, two units.
  exec.set_background_max_slice_us(3000);
  frames(1);
  CHECK_EQUAL(2U, work.last_slice_units);
}

TEST(ExecutiveHostTiming, AUnitLongerThanASliceOverrunsOnceAndStarvesNoLaterSlice) {
  // One unit of 12 ms among units of 1 ms: the estimate is capped at half the slice, so the
  // slices after it still get work (the first halves of their time).
  class OneLongUnit final : public BackgroundWork {
   public:
    explicit OneLongUnit(FakeHostClock& h) : host_(h) {}
    SliceResult run_slice(SliceBudget& budget) override {
      last_units = 0;
      while (budget.next_unit()) {
        const std::uint64_t us = ++units == 3 ? 12000 : 1000;
        host_.spend(us * 1000U, us * 1000U);
        ++last_units;
      }
      return SliceResult::kMore;
    }
    std::uint32_t units = 0;
    std::uint32_t last_units = 0;

   private:
    FakeHostClock& host_;
  } work{host};
  exec.set_background(&work);
  config.slices_on_host_clock = true;
  start();
  frames(1);  // units 1 and 2 of 1 ms, then the 12 ms one
  CHECK_EQUAL(3U, work.last_units);
  CHECK_EQUAL(1U, exec.host_frame_stats().slice_overruns);
  frames(1);  // 9 ms slice, estimate capped at 4.5 ms: units begun at 0 … 4 ms
  CHECK_EQUAL(5U, work.last_units);
  CHECK_EQUAL(1U, exec.host_frame_stats().slice_overruns);
}

TEST(ExecutiveHostTiming, RefusesSlicesOnTheHostsClockWithoutOne) {
  Executive board_only(clock);
  TimedTask t(clock, 0);
  CHECK(board_only.add_task({"t", 10000, 500}, t, &error));
  config.slices_on_host_clock = true;
  CHECK_FALSE(board_only.start(config, &error));
  STRCMP_CONTAINS("host clock", error);
}

TEST(ExecutiveHostTiming, KeepsTheFrameStartLatencyTheBoardsClockMeasured) {
  HostTimedTask t(host, 10, 10);
  add({"t", 10000, 500}, t);
  start();
  frames(10);  // lockstep: the clock did not wait on the host's, nothing to count
  CHECK_EQUAL(0U, exec.host_frame_stats().start_latency.count());
  clock.set_wake_latency_ns(12000);
  frames(99);
  clock.set_wake_latency_ns(480000);
  frames(1);
  const DurationHistogram& l = exec.host_frame_stats().start_latency;
  CHECK_EQUAL(100U, l.count());
  CHECK_EQUAL(480000U, l.max_ns());
  CHECK(l.percentile_ns(990) >= 12000U && l.percentile_ns(990) <= 12000U * 33 / 32);
  CHECK_EQUAL(480000U, l.percentile_ns(1000));
}

TEST(ExecutiveHostTiming, RunsFramesWithHostTimingWithoutAllocating) {
  HostTimedTask a(host, 30, 20), b(host, 200, 150);
  HostTimedWork work(host, 700);
  add({"a", 10000, 500}, a);
  add({"b", 20000, 1000}, b);
  exec.set_background(&work);
  config.slices_on_host_clock = true;
  clock.set_wake_latency_ns(5000);
  start();
  CHECK_NO_ALLOCATION(frames(500));
  CHECK(work.slices > 0);
  CHECK_EQUAL(500U, exec.host_frame_stats().start_latency.count());
}

TEST(ExecutiveHostTiming, WritesOneLinePerTaskThenTheBackgroundAndTheFrames) {
  HostTimedTask t(host, 250, 200);
  HostTimedWork work(host, 1000);
  add({"estop", 10000, 200}, t);
  exec.set_background(&work);
  config.background_units_per_slice = 2;
  start();
  frames(10);
  CHECK_EQUAL(3U, host_timing_line_count(exec));
  TextBuffer<512> line;
  append_host_timing_line(line, exec, 0);
  STRCMP_EQUAL(
      "host task estop    budget_us=200 runs=10 wall_avg_us=250.0 wall_p99_us=250.0 "
      "wall_worst_us=250.0 cpu_avg_us=200.0 cpu_p99_us=200.0 cpu_worst_us=200.0",
      line.c_str());
  line.clear();
  append_host_timing_line(line, exec, 1);
  STRCMP_EQUAL(
      "host background limit_us=9000 slices=10 wall_p99_us=2000.0 wall_worst_us=2000.0 "
      "cpu_p99_us=2000.0 cpu_worst_us=2000.0 over_limit=0 overshoot_worst_us=0.0 margin_us=1000",
      line.c_str());
  line.clear();
  append_host_timing_line(line, exec, 2);
  STRCMP_EQUAL(
      "host frame frame_us=10000 frames=10 work_wall_p99_us=2250.0 work_wall_worst_us=2250.0 "
      "work_cpu_p99_us=2200.0 work_cpu_worst_us=2200.0 latencies=0 start_latency_p99_us=0.0 "
      "start_latency_worst_us=0.0",
      line.c_str());
  Executive board_only(clock);
  CHECK_EQUAL(0U, host_timing_line_count(board_only));
}

TEST_GROUP(HostDurations){};

TEST(HostDurations, KeepsShortDurationsExactlyAndLongOnesWithinAThirtySecondAbove) {
  DurationHistogram h;
  CHECK_EQUAL(0U, h.percentile_ns(990));
  for (std::uint64_t ns = 0; ns < 64; ++ns) {
    CHECK_EQUAL(ns, DurationHistogram::bucket_upper_ns(DurationHistogram::bucket(ns)));
  }
  // Every duration's bucket ends at or above it and at most 1/32 of it higher; buckets
  // never go back.
  std::size_t last = 0;
  for (std::uint64_t ns = 64; ns < DurationHistogram::kMaxNs; ns += ns / 97 + 1) {
    const std::size_t b = DurationHistogram::bucket(ns);
    const std::uint64_t upper = DurationHistogram::bucket_upper_ns(b);
    CHECK(b >= last);
    CHECK(upper >= ns);
    CHECK(upper - ns <= ns / 32);
    last = b;
  }
  CHECK_EQUAL(DurationHistogram::kBuckets - 1, DurationHistogram::bucket(UINT64_MAX));
}

TEST(HostDurations, GivesPercentilesByRankNeverBelowTheTrueValueNorAboveTheWorst) {
  DurationHistogram h;
  for (std::uint64_t us = 1; us <= 1000; ++us) h.add(us * 1000U);  // 1 µs … 1 ms
  CHECK_EQUAL(1000U, h.count());
  CHECK_EQUAL(1000000U, h.max_ns());
  CHECK_EQUAL(500500U, h.average_ns());
  const std::uint64_t p99 = h.percentile_ns(990);  // the 990th smallest: 990 µs
  CHECK(p99 >= 990000U && p99 <= 990000U + 990000U / 32);
  const std::uint64_t p50 = h.percentile_ns(500);
  CHECK(p50 >= 500000U && p50 <= 500000U + 500000U / 32);
  CHECK_EQUAL(1000000U, h.percentile_ns(1000));  // the worst exactly
  CHECK(h.percentile_ns(1) >= 1000U && h.percentile_ns(1) <= 1000U + 1000U / 32);
  h.clear();
  CHECK_EQUAL(0U, h.count());
  CHECK_EQUAL(0U, h.percentile_ns(500));
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

// The fault policy: a device fault is held and retried, not a hang; the watchdog keeps being
// kicked for the retry time, then the task gives up (and withholds it: a firmware that did
// not exit on the give-up is restarted by systemd anyway).
TEST(WatchdogTask, KeepsKickingThroughADeviceFaultForItsRetryTimeThenGivesUp) {
  TimedTask device(clock, 10);
  CHECK(exec.add_task({"device", 10000, 500}, device, &error));
  CHECK(exec.add_task({"watchdog", 100000, 200}, task, &error));
  task.set_retry_us(2000000);
  CHECK(exec.start(ExecutiveConfig{}, &error));
  for (int i = 0; i < 50; ++i) exec.run_frame();
  CHECK_EQUAL(5, watchdog.kicks);
  // Unhealthy for 1.5 s, healthy, and again for 1.5 s: each spell within the retry time.
  for (int spell = 0; spell < 2; ++spell) {
    device.healthy_flag = false;
    for (int i = 0; i < 150; ++i) exec.run_frame();
    device.healthy_flag = true;
    for (int i = 0; i < 10; ++i) exec.run_frame();
  }
  CHECK_FALSE(task.gave_up());
  CHECK_EQUAL(37, watchdog.kicks);
  CHECK_EQUAL(0U, task.withheld());
  // Unhealthy for longer: given up 2 s after it began, with the task's name and reason.
  device.healthy_flag = false;
  for (int i = 0; i < 190; ++i) exec.run_frame();
  CHECK_FALSE(task.gave_up());
  for (int i = 0; i < 20; ++i) exec.run_frame();
  CHECK(task.gave_up());
  STRCMP_EQUAL("device unhealthy for 2 s: unhealthy", task.give_up_reason());
  const int kicks = watchdog.kicks;
  device.healthy_flag = true;  // too late: a give-up stays
  for (int i = 0; i < 50; ++i) exec.run_frame();
  CHECK_EQUAL(kicks, watchdog.kicks);
  CHECK(task.withheld() >= 5U);
}

// A keep-alive the device refuses (the board resets unless one is taken within its timeout)
// makes the task unhealthy in the device's words, and healthy again once one is taken; past
// the retry time it is given up on like any device.
TEST(WatchdogTask, AKeepAliveTheDeviceRefusesMakesItUnhealthyUntilOneIsTakenAgain) {
  CHECK(exec.add_task({"watchdog", 100000, 200}, task, &error));
  task.set_retry_us(2000000);
  CHECK(exec.start(ExecutiveConfig{}, &error));
  for (int i = 0; i < 20; ++i) exec.run_frame();
  CHECK(task.healthy());
  watchdog.refuses = true;
  for (int i = 0; i < 10; ++i) exec.run_frame();
  CHECK_FALSE(task.healthy());
  CHECK_FALSE(exec.all_healthy());
  STRCMP_EQUAL("watchdog: keep-alive refused: EIO", task.health_reason());
  CHECK_EQUAL(1U, task.refused());
  for (int i = 0; i < 100; ++i) exec.run_frame();  // still tried every run
  CHECK_EQUAL(11U, task.refused());
  watchdog.refuses = false;
  for (int i = 0; i < 10; ++i) exec.run_frame();
  CHECK(task.healthy());
  STRCMP_EQUAL("", task.health_reason());
  CHECK_FALSE(task.gave_up());
  watchdog.refuses = true;
  for (int i = 0; i < 230; ++i) exec.run_frame();
  CHECK(task.gave_up());
  STRCMP_CONTAINS("watchdog unhealthy for 2 s: watchdog: keep-alive refused",
                  task.give_up_reason());
}

// A hang (a task over its budget again and again, or starved) withholds it at once.
TEST(WatchdogTask, WithholdsAtOnceWhileATaskKeepsOverrunningItsBudget) {
  TimedTask device(clock, 10);
  CHECK(exec.add_task({"device", 10000, 500}, device, &error));
  CHECK(exec.add_task({"watchdog", 100000, 200}, task, &error));
  CHECK(exec.start(ExecutiveConfig{}, &error));
  for (int i = 0; i < 50; ++i) exec.run_frame();
  CHECK_EQUAL(5, watchdog.kicks);
  device.slow_every = 1;
  device.slow_cost_us = 900;  // over its 500 µs budget in every frame
  for (int i = 0; i < 50; ++i) exec.run_frame();
  CHECK(watchdog.kicks <= 6);
  CHECK(task.withheld() >= 4U);
  CHECK_FALSE(task.gave_up());
  device.slow_every = 0;
  for (int i = 0; i < 50; ++i) exec.run_frame();
  CHECK(watchdog.kicks >= 10);
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
  CHECK_EQUAL(0U, task.withheld());  // within the retry time: held and retried, not a hang
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
