// Cyclic executive: task timing, background slices, re-anchoring after overruns (see executive.h).
#include "firmware/executive/executive.h"

#include <cstring>

namespace boticelli::firmware {

bool Executive::add_task(const TaskSpec& spec, Task& task, const char** error) {
  if (started_) {
    *error = "tasks cannot be added after start";
    return false;
  }
  if (count_ == kMaxTasks) {
    *error = "task table is full";
    return false;
  }
  if (spec.name == nullptr || spec.name[0] == '\0' || spec.period_us == 0 || spec.budget_us == 0) {
    *error = "task needs a name, a period and a budget";
    return false;
  }
  Entry& e = entries_[count_++];
  e = Entry{};
  e.spec = spec;
  e.task = &task;
  return true;
}

bool Executive::start(const ExecutiveConfig& config, const char** error) {
  if (config.frame_us == 0 || config.background_margin_us >= config.frame_us) {
    *error = "the minor frame must be longer than the background margin";
    return false;
  }
  for (std::size_t i = 0; i < count_; ++i) {
    const TaskSpec& s = entries_[i].spec;
    if (s.period_us % config.frame_us != 0) {
      *error = "a task period is not a multiple of the minor frame";
      return false;
    }
    if (s.budget_us >= config.frame_us) {
      *error = "a task budget does not fit in one minor frame";
      return false;
    }
  }
  if (config.slices_on_host_clock && host_ == nullptr) {
    *error = "slices on the host's clock need a host clock";
    return false;
  }
  config_ = config;
  for (std::size_t i = 0; i < count_; ++i) {
    Entry& e = entries_[i];
    e.period_frames = e.spec.period_us / config.frame_us;
    // Spread slow tasks over the frames of their period instead of bunching them in frame 0.
    e.next_due_frame = i % e.period_frames;
  }
  frame_index_ = 0;
  next_start_us_ = clock_.now_us();
  anchor_us_ = next_start_us_;
  for (std::size_t i = 0; i < count_; ++i) entries_[i].last_run_us = next_start_us_;
  frame_ = FrameStats{};
  host_frame_.clear();
  longest_unit_ns_ = 0;
  stop_requested_ = false;
  started_ = true;
  return true;
}

void Executive::add_timing(HostTiming& timing, const HostMark& from, const HostMark& to) {
  timing.wall.add(to.wall_ns >= from.wall_ns ? to.wall_ns - from.wall_ns : 0);
  timing.cpu.add(to.cpu_ns >= from.cpu_ns ? to.cpu_ns - from.cpu_ns : 0);
}

void Executive::run_frame() {
  clock_.sleep_until_us(next_start_us_);
  const HostMark frame_start = host_mark();
  const std::uint64_t start_us = clock_.now_us();
  if (const std::int64_t late_ns = clock_.last_wake_latency_ns(); late_ns >= 0) {
    host_frame_.start_latency.add(static_cast<std::uint64_t>(late_ns));
  }
  const std::uint64_t jitter_us =
      start_us >= next_start_us_ ? start_us - next_start_us_ : next_start_us_ - start_us;
  frame_.jitter_total_us += jitter_us;
  if (jitter_us > frame_.jitter_worst_us) {
    frame_.jitter_worst_us = static_cast<std::uint32_t>(jitter_us);
  }
  ++frame_.frames;

  std::uint64_t now_us = start_us;
  HostMark mark = frame_start;
  for (std::size_t i = 0; i < count_; ++i) {
    Entry& e = entries_[i];
    if (frame_index_ < e.next_due_frame) continue;
    e.next_due_frame = frame_index_ + e.period_frames;
    const std::uint64_t t0 = now_us;
    e.task->run(t0);
    now_us = clock_.now_us();
    if (host_ != nullptr) {
      const HostMark after = host_mark();
      add_timing(e.host, mark, after);
      mark = after;
    }
    const std::uint64_t took = now_us - t0;
    const std::uint32_t took_us =
        took > 0xFFFFFFFFU ? 0xFFFFFFFFU : static_cast<std::uint32_t>(took);
    TaskStats& st = e.stats;
    ++st.runs;
    st.total_us += took_us;
    st.last_us = took_us;
    if (took_us > st.worst_us) st.worst_us = took_us;
    if (took_us > e.spec.budget_us) {
      ++st.overruns;
      ++st.consecutive_overruns;
    } else {
      st.consecutive_overruns = 0;
    }
    e.last_run_us = t0;
  }

  const std::uint64_t next_us = next_start_us_ + config_.frame_us;
  run_background(start_us, now_us, frame_start);
  const std::uint64_t end_us = clock_.now_us();
  if (host_ != nullptr) add_timing(host_frame_.work, frame_start, host_mark());

  ++frame_index_;
  if (end_us > next_us) {
    // Overrun: start the next frame now and keep the period from there (re-anchor) rather
    // than running the missed frames back to back.
    ++frame_.overruns;
    frame_.missed_frames += (end_us - next_us) / config_.frame_us;
    next_start_us_ = end_us;
  } else {
    next_start_us_ = next_us;
  }
  frame_.elapsed_us = next_start_us_ - anchor_us_;
}

void Executive::run_background(std::uint64_t frame_start_us, std::uint64_t now_us,
                               const HostMark& frame_start) {
  if (background_ == nullptr || background_paused_) return;
  const std::uint64_t frame_end_us = next_start_us_ + config_.frame_us;
  const std::uint64_t limit_us = frame_end_us - config_.background_margin_us;
  if (now_us >= limit_us || limit_us - now_us < config_.background_min_slice_us) return;
  std::uint64_t deadline_us = limit_us;
  if (config_.background_max_slice_us != 0 &&
      now_us + config_.background_max_slice_us < deadline_us) {
    deadline_us = now_us + config_.background_max_slice_us;
  }
  // The same limits on the host's monotonic clock: what the frame leaves from its start on
  // the host (on a lockstep sim board the tasks took no board time but did take host time).
  const HostMark slice_start = host_mark();
  std::uint64_t host_deadline_ns = 0;
  if (host_ != nullptr) {
    const std::uint64_t limit_from_start_us =
        limit_us > frame_start_us ? limit_us - frame_start_us : 0;
    host_deadline_ns = frame_start.wall_ns + limit_from_start_us * 1000U;
    if (config_.background_max_slice_us != 0) {
      const std::uint64_t longest_ns =
          slice_start.wall_ns + std::uint64_t{config_.background_max_slice_us} * 1000U;
      if (longest_ns < host_deadline_ns) host_deadline_ns = longest_ns;
    }
    if (config_.slices_on_host_clock &&
        (slice_start.wall_ns >= host_deadline_ns ||
         host_deadline_ns - slice_start.wall_ns <
             std::uint64_t{config_.background_min_slice_us} * 1000U)) {
      return;
    }
  }
  HostSlice host_slice;
  if (config_.slices_on_host_clock) {
    host_slice.clock = host_;
    host_slice.deadline_ns = host_deadline_ns;
    host_slice.longest_unit_ns = &longest_unit_ns_;
    host_slice.longest_cap_ns = (host_deadline_ns - slice_start.wall_ns) / 2U;
  }
  SliceBudget budget(clock_, deadline_us, config_.background_units_per_slice, host_slice);
  const SliceResult result = background_->run_slice(budget);
  budget.end_slice();
  const std::uint64_t after_us = clock_.now_us();
  ++frame_.background_slices;
  frame_.background_used_us += after_us - now_us;
  if (after_us > deadline_us) ++frame_.background_overruns;
  if (result == SliceResult::kDone) ++frame_.background_done;
  if (host_ != nullptr) {
    const HostMark slice_end = host_mark();
    add_timing(host_frame_.slice, slice_start, slice_end);
    if (slice_end.wall_ns > host_deadline_ns) {
      ++host_frame_.slice_overruns;
      const std::uint64_t overshoot_ns = slice_end.wall_ns - host_deadline_ns;
      if (overshoot_ns > host_frame_.slice_overshoot_worst_ns) {
        host_frame_.slice_overshoot_worst_ns = overshoot_ns;
      }
    }
  }
}

bool Executive::all_healthy() const {
  for (std::size_t i = 0; i < count_; ++i) {
    if (task_health(i) != nullptr) return false;
  }
  return true;
}

bool Executive::all_running() const {
  for (std::size_t i = 0; i < count_; ++i) {
    if (running_health(i) != nullptr) return false;
  }
  return true;
}

const char* Executive::task_health(std::size_t i) const {
  const Entry& e = entries_[i];
  if (!e.task->healthy()) {
    const char* why = e.task->health_reason();
    return why[0] != '\0' ? why : "unhealthy";
  }
  return running_health(i);
}

const char* Executive::running_health(std::size_t i) const {
  const Entry& e = entries_[i];
  if (e.stats.consecutive_overruns >= config_.unhealthy_after_overruns) {
    return "overrunning its budget";
  }
  // Starved: not run for more than two periods (plus one frame of re-anchoring slack).
  const std::uint64_t now_us = next_start_us_;
  const std::uint64_t allowed_us = 2ULL * e.spec.period_us + config_.frame_us;
  if (now_us > e.last_run_us && now_us - e.last_run_us > allowed_us) return "starved";
  return nullptr;
}

std::size_t Executive::find(const char* name) const {
  for (std::size_t i = 0; i < count_; ++i) {
    if (std::strcmp(entries_[i].spec.name, name) == 0) return i;
  }
  return count_;
}

void Executive::reset_stats() {
  for (std::size_t i = 0; i < count_; ++i) {
    entries_[i].stats = TaskStats{};
    entries_[i].host.clear();
  }
  frame_ = FrameStats{};
  host_frame_.clear();
  anchor_us_ = next_start_us_;
}

}  // namespace boticelli::firmware
