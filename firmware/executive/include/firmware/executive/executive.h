// Executive: the cyclic executive — fixed-rate tasks in minor frames plus a budgeted background
// slot.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <span>

#include "firmware/executive/duration_histogram.h"
#include "firmware/executive/host_clock.h"
#include "hal/clock.h"

namespace boticelli::firmware {

// One row of a task table: what runs, how often and how long it may take.
struct TaskSpec {
  const char* name;
  std::uint32_t period_us;  // a whole multiple of the minor frame
  std::uint32_t budget_us;  // longest allowed execution time per run
};

// A fixed-rate task. run() never blocks; it is timed by the executive.
class Task {
 public:
  virtual ~Task() = default;
  virtual void run(std::uint64_t now_us) = 0;
  // False while the task's device or job is faulted (the watchdog then stops being kicked).
  virtual bool healthy() const { return true; }
  // Why healthy() is false, in the device's words (e.g. "left axis: no heartbeat"); ""
  // when there is nothing to say. Read by the console (status, stats, LOG lines).
  virtual const char* health_reason() const { return ""; }

 protected:
  Task() = default;
  Task(const Task&) = default;
  Task& operator=(const Task&) = default;
};

// A slice ended by the host's clock (ExecutiveConfig::slices_on_host_clock): its deadline on
// the monotonic clock, and the longest unit seen so far [ns of thread CPU], which the
// executive keeps across slices. A unit is begun only when that long a unit would end before
// the deadline; the estimate is capped at `longest_cap_ns` so that one unit longer than a
// slice cannot starve the work.
struct HostSlice {
  HostClock* clock = nullptr;
  std::uint64_t deadline_ns = 0;
  std::uint64_t* longest_unit_ns = nullptr;
  std::uint64_t longest_cap_ns = 0;
};

// What a background slice may use: the time until deadline_us on the executive's clock and
// at most max_units units of work (0 = no unit limit). Work asks next_unit() before each
// small, bounded unit of work and returns when it says no. With a HostSlice the deadline is
// on the host's clock instead.
class SliceBudget {
 public:
  SliceBudget(hal::Clock& clock, std::uint64_t deadline_us, std::uint32_t max_units,
              const HostSlice& host = {})
      : clock_(&clock), host_(host), deadline_us_(deadline_us), max_units_(max_units) {}
  // True (and counts a unit) when another unit of work fits in the slice.
  bool next_unit() {
    if (max_units_ != 0 && units_ >= max_units_) return false;
    if (host_.clock != nullptr) {
      const std::uint64_t cpu_ns = host_.clock->thread_cpu_ns();
      end_unit(cpu_ns);
      std::uint64_t expected_ns = host_.longest_unit_ns != nullptr ? *host_.longest_unit_ns : 0;
      if (expected_ns > host_.longest_cap_ns) expected_ns = host_.longest_cap_ns;
      if (host_.clock->monotonic_ns() + expected_ns >= host_.deadline_ns) return false;
      unit_start_cpu_ns_ = cpu_ns;
      in_unit_ = true;
    } else if (clock_->now_us() >= deadline_us_) {
      return false;
    }
    ++units_;
    return true;
  }
  // The slice is over (the work returned): its last unit is measured (host slices only).
  void end_slice() {
    if (host_.clock != nullptr) end_unit(host_.clock->thread_cpu_ns());
  }
  std::uint64_t deadline_us() const { return deadline_us_; }
  std::uint32_t units_used() const { return units_; }

 private:
  void end_unit(std::uint64_t cpu_ns) {
    if (!in_unit_) return;
    in_unit_ = false;
    const std::uint64_t took_ns = cpu_ns > unit_start_cpu_ns_ ? cpu_ns - unit_start_cpu_ns_ : 0;
    if (host_.longest_unit_ns != nullptr && took_ns > *host_.longest_unit_ns) {
      *host_.longest_unit_ns = took_ns;
    }
  }

  hal::Clock* clock_;
  HostSlice host_;
  std::uint64_t deadline_us_;
  std::uint32_t max_units_;
  std::uint32_t units_ = 0;
  std::uint64_t unit_start_cpu_ns_ = 0;
  bool in_unit_ = false;
};

enum class SliceResult : std::uint8_t {
  kMore,  // the job is not finished; run_slice() is called again in a later slice
  kDone,  // one job (e.g. a mission cycle) finished in this slice
};

// Resumable long work (ALN training, map extraction, planning) run in the frames' spare time,
// a slice per frame. Words: a *slice* is one frame's spare time, a *unit* one bounded piece of
// work within it (SliceBudget::next_unit), a *step* the robot's straight move (the thesis's).
// run_slice() keeps its own progress between calls and must return when the budget says so.
class BackgroundWork {
 public:
  virtual ~BackgroundWork() = default;
  virtual SliceResult run_slice(SliceBudget& budget) = 0;

 protected:
  BackgroundWork() = default;
  BackgroundWork(const BackgroundWork&) = default;
  BackgroundWork& operator=(const BackgroundWork&) = default;
};

// Execution time statistics of one task [µs].
struct TaskStats {
  std::uint64_t runs = 0;
  std::uint64_t overruns = 0;  // runs longer than the budget
  std::uint64_t total_us = 0;
  std::uint32_t worst_us = 0;
  std::uint32_t last_us = 0;
  std::uint32_t consecutive_overruns = 0;
  std::uint64_t average_us() const { return runs == 0 ? 0 : total_us / runs; }
};

// Frame and background statistics.
struct FrameStats {
  std::uint64_t frames = 0;
  std::uint64_t overruns = 0;         // frames whose work ended after the next frame's start
  std::uint64_t missed_frames = 0;    // frame starts skipped by re-anchoring after overruns
  std::uint64_t jitter_total_us = 0;  // sum of |actual − scheduled| frame start
  std::uint32_t jitter_worst_us = 0;
  std::uint64_t background_slices = 0;
  std::uint64_t background_used_us = 0;   // time spent inside BackgroundWork::step
  std::uint64_t background_overruns = 0;  // slices that returned after their deadline
  std::uint64_t background_done = 0;      // jobs that reported kDone
  std::uint64_t elapsed_us = 0;           // time covered by the frames run so far
  std::uint64_t jitter_average_us() const { return frames == 0 ? 0 : jitter_total_us / frames; }
  // Background time as a share of all elapsed time, in per mille.
  std::uint32_t background_per_mille() const {
    return elapsed_us == 0 ? 0U
                           : static_cast<std::uint32_t>(background_used_us * 1000U / elapsed_us);
  }
};

// Durations of one kind of work on the host's clocks [ns] (Executive with a HostClock): what
// the work took, whatever the board's clock says (on the sim board its time stands still
// while the host computes).
struct HostTiming {
  DurationHistogram wall;  // monotonic: what a deadline sees (preemption and blocking included)
  DurationHistogram cpu;   // the thread's CPU time: what an execution-time budget means
  void clear() {
    wall.clear();
    cpu.clear();
  }
};

// The frames and the background slot on the host's clocks.
struct HostFrameStats {
  HostTiming work;   // each frame's tasks and background slice, from its start to its end
  HostTiming slice;  // each background slice
  // Slices whose host wall time passed what their frame left them (the frame's end minus
  // the margin, or the longest-slice setting): on a lockstep sim board a slice is bounded by
  // units, not time, so these count how far the units overshoot on this host.
  std::uint64_t slice_overruns = 0;
  // The furthest a slice ran past that limit [ns]: a unit begun just before it ends after it,
  // which the frame's margin is there to absorb (past the margin, the next frame starts late).
  std::uint64_t slice_overshoot_worst_ns = 0;
  // Frame start latency [ns] (hal::Clock::last_wake_latency_ns): how late the executive
  // woke for each frame on the host's monotonic clock, as cyclictest measures; frames whose
  // clock did not wait on the host (lockstep sim) are not counted.
  DurationHistogram start_latency;
  void clear() {
    work.clear();
    slice.clear();
    slice_overruns = 0;
    slice_overshoot_worst_ns = 0;
    start_latency.clear();
  }
};

struct ExecutiveConfig {
  std::uint32_t frame_us = 10000;                // minor frame
  std::uint32_t background_margin_us = 1000;     // left free before the next frame starts
  std::uint32_t background_min_slice_us = 200;   // a slice shorter than this is not started
  std::uint32_t background_max_slice_us = 0;     // 0 = up to the margin
  std::uint32_t background_units_per_slice = 0;  // 0 = limited by time only
  std::uint32_t unhealthy_after_overruns =
      3;  // consecutive budget overruns that make a task unhealthy
  // Background slices end by the host's monotonic clock (needs a HostClock): the frame's
  // share measured from the frame's start on the host, as on a board whose clock is the
  // host's, and no unit begun that the longest unit so far says would not end in time
  // (HostSlice). For timing a sim board as the robot would run (its work per frame then
  // depends on the host's speed); with background_units_per_slice 0.
  bool slices_on_host_clock = false;
};

// Runs the tasks of a table in minor frames on a hal::Clock. Everything is set up by
// add_task()/start(); run_frame() then never allocates. Tasks run in table order each frame
// they are due (put the e-stop first); the background slot gets what is left of the frame
// minus the margin. After a frame overrun the schedule is re-anchored at the overrun's end
// (missed frames are skipped and counted, never run in a burst). Statistics are kept on the
// board's clock (the schedule's) and, given a HostClock, on the host's clocks too.
class Executive {
 public:
  static constexpr std::size_t kMaxTasks = 12;

  explicit Executive(hal::Clock& clock, HostClock* host = nullptr) : clock_(clock), host_(host) {}
  Executive(const Executive&) = delete;
  Executive& operator=(const Executive&) = delete;

  // Adds a task; false with a reason when the table is full or the spec is invalid.
  bool add_task(const TaskSpec& spec, Task& task, const char** error);
  void set_background(BackgroundWork* work) { background_ = work; }
  // Validates every period against the frame and anchors the schedule at now.
  bool start(const ExecutiveConfig& config, const char** error);

  // One minor frame: due tasks, background slice, then sleep until the next frame start.
  void run_frame();
  // Frames until request_stop() (from a task, a signal flag polled by a task, the console).
  void run() {
    while (!stop_requested_) run_frame();
  }
  void request_stop() { stop_requested_ = true; }
  bool stop_requested() const { return stop_requested_; }

  void set_background_paused(bool paused) { background_paused_ = paused; }
  bool background_paused() const { return background_paused_; }
  void set_background_max_slice_us(std::uint32_t us) { config_.background_max_slice_us = us; }

  // Every task reports healthy, none is over its consecutive-overrun limit, and each has
  // run within two of its periods.
  bool all_healthy() const;
  // nullptr while task i is healthy by all_healthy()'s three rules, else why not: the task's
  // own reason ("unhealthy" when it gives none), "overrunning its budget" or "starved".
  const char* task_health(std::size_t i) const;
  // The executive itself works: no task over its consecutive-overrun limit or starved (a
  // task's own health, its device's, is not asked). What the watchdog guards.
  bool all_running() const;
  // The overrun and starvation rules of task_health() alone: nullptr, or why not.
  const char* running_health(std::size_t i) const;

  std::size_t task_count() const { return count_; }
  const TaskSpec& spec(std::size_t i) const { return entries_[i].spec; }
  const TaskStats& task_stats(std::size_t i) const { return entries_[i].stats; }
  const FrameStats& frame_stats() const { return frame_; }
  // Host timings (all empty without a HostClock, but for the frame start latency, which the
  // board's clock measures).
  [[nodiscard]] bool host_timed() const { return host_ != nullptr; }
  const HostTiming& host_task_timing(std::size_t i) const { return entries_[i].host; }
  const HostFrameStats& host_frame_stats() const { return host_frame_; }
  const ExecutiveConfig& config() const { return config_; }
  // Index of the task with this name, or task_count() when there is none.
  std::size_t find(const char* name) const;
  void reset_stats();

 private:
  struct Entry {
    TaskSpec spec{"", 0, 0};
    Task* task = nullptr;
    std::uint32_t period_frames = 1;
    std::uint64_t next_due_frame = 0;
    std::uint64_t last_run_us = 0;
    TaskStats stats;
    HostTiming host;
  };
  // A reading of the host's clocks [ns] (zeros without one).
  struct HostMark {
    std::uint64_t wall_ns = 0;
    std::uint64_t cpu_ns = 0;
  };
  HostMark host_mark() const {
    return host_ == nullptr ? HostMark{} : HostMark{host_->monotonic_ns(), host_->thread_cpu_ns()};
  }
  static void add_timing(HostTiming& timing, const HostMark& from, const HostMark& to);

  void run_background(std::uint64_t frame_start_us, std::uint64_t now_us,
                      const HostMark& frame_start);

  hal::Clock& clock_;
  HostClock* host_;
  ExecutiveConfig config_;
  std::array<Entry, kMaxTasks> entries_{};
  std::size_t count_ = 0;
  BackgroundWork* background_ = nullptr;
  bool background_paused_ = false;
  bool started_ = false;
  bool stop_requested_ = false;
  std::uint64_t frame_index_ = 0;
  std::uint64_t next_start_us_ = 0;    // scheduled start of the frame to run next
  std::uint64_t anchor_us_ = 0;        // start of the first frame (stats)
  std::uint64_t longest_unit_ns_ = 0;  // host slices: the longest background unit [ns CPU]
  FrameStats frame_;
  HostFrameStats host_frame_;
};

// For static_assert on a constexpr table: every period a positive multiple of the frame,
// every budget positive and shorter than one frame.
constexpr bool task_table_valid(std::span<const TaskSpec> table, std::uint32_t frame_us) {
  for (const TaskSpec& t : table) {
    if (t.period_us == 0 || t.period_us % frame_us != 0 || t.budget_us == 0 ||
        t.budget_us >= t.period_us || t.budget_us >= frame_us) {
      return false;
    }
  }
  return true;
}

}  // namespace boticelli::firmware
