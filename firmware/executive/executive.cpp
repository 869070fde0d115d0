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
  stop_requested_ = false;
  started_ = true;
  return true;
}

void Executive::run_frame() {
  clock_.sleep_until_us(next_start_us_);
  const std::uint64_t start_us = clock_.now_us();
  const std::uint64_t jitter_us =
      start_us >= next_start_us_ ? start_us - next_start_us_ : next_start_us_ - start_us;
  frame_.jitter_total_us += jitter_us;
  if (jitter_us > frame_.jitter_worst_us) {
    frame_.jitter_worst_us = static_cast<std::uint32_t>(jitter_us);
  }
  ++frame_.frames;

  std::uint64_t now_us = start_us;
  for (std::size_t i = 0; i < count_; ++i) {
    Entry& e = entries_[i];
    if (frame_index_ < e.next_due_frame) continue;
    e.next_due_frame = frame_index_ + e.period_frames;
    const std::uint64_t t0 = now_us;
    e.task->run(t0);
    now_us = clock_.now_us();
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
  run_background(now_us);
  const std::uint64_t end_us = clock_.now_us();

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

void Executive::run_background(std::uint64_t now_us) {
  if (background_ == nullptr || background_paused_) return;
  const std::uint64_t frame_end_us = next_start_us_ + config_.frame_us;
  const std::uint64_t limit_us = frame_end_us - config_.background_margin_us;
  if (now_us >= limit_us || limit_us - now_us < config_.background_min_slice_us) return;
  std::uint64_t deadline_us = limit_us;
  if (config_.background_max_slice_us != 0 &&
      now_us + config_.background_max_slice_us < deadline_us) {
    deadline_us = now_us + config_.background_max_slice_us;
  }
  SliceBudget budget(clock_, deadline_us, config_.background_units_per_slice);
  const SliceResult result = background_->run_slice(budget);
  const std::uint64_t after_us = clock_.now_us();
  ++frame_.background_slices;
  frame_.background_used_us += after_us - now_us;
  if (after_us > deadline_us) ++frame_.background_overruns;
  if (result == SliceResult::kDone) ++frame_.background_done;
}

bool Executive::all_healthy() const {
  for (std::size_t i = 0; i < count_; ++i) {
    if (task_health(i) != nullptr) return false;
  }
  return true;
}

const char* Executive::task_health(std::size_t i) const {
  const Entry& e = entries_[i];
  if (!e.task->healthy()) {
    const char* why = e.task->health_reason();
    return why[0] != '\0' ? why : "unhealthy";
  }
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
  for (std::size_t i = 0; i < count_; ++i) entries_[i].stats = TaskStats{};
  frame_ = FrameStats{};
  anchor_us_ = next_start_us_;
}

}  // namespace boticelli::firmware
