// Device tasks: camera polling, the watchdog kick, status LED and service status (see
// device_tasks.h).
#include "firmware/app/device_tasks.h"

#include <algorithm>

namespace boticelli::firmware {

void CameraTask::run(std::uint64_t now_us) {
  if (!seen_time_) {
    seen_time_ = true;
    last_frame_us_ = now_us;
    last_poll_us_ = now_us - idle_poll_us_;
  }
  // Nobody wants a frame: poll seldom (a stalled camera is still noticed).
  if (consumer_ != nullptr && !consumer_->wants_frames() &&
      now_us - last_poll_us_ < idle_poll_us_) {
    return;
  }
  last_poll_us_ = now_us;
  hal::Frame frame;
  switch (camera_.poll(frame)) {
    case hal::CameraPoll::kFrame:
      if (frame.width_px != camera_.width_px() || frame.height_px != camera_.height_px()) {
        // Not the negotiated format: unusable, like no frame at all.
        ++wrong_frames_;
        camera_.release();
        last_bad_ = "frames of the wrong size";
        if (now_us - last_frame_us_ > stall_us_) mark_stalled(last_bad_);
        break;
      }
      if (have_sequence_ && frame.sequence == last_sequence_) {
        // The same buffer again (a frozen driver): not a new image, so not used, and it
        // does not keep the camera healthy.
        ++stale_frames_;
        camera_.release();
        last_bad_ = "the same frame again";
        if (now_us - last_frame_us_ > stall_us_) mark_stalled(last_bad_);
        break;
      }
      have_sequence_ = true;
      last_sequence_ = frame.sequence;
      last_bad_ = nullptr;
      ++frames_;
      last_frame_us_ = now_us;
      healthy_ = true;
      if (consumer_ != nullptr) consumer_->on_frame(frame);
      camera_.release();
      break;
    case hal::CameraPoll::kFault:
      ++faults_;
      if (now_us - last_frame_us_ > stall_us_) mark_stalled(nullptr);
      break;
    case hal::CameraPoll::kNoFrame:
      if (now_us - last_frame_us_ > stall_us_) mark_stalled(nullptr);
      break;
  }
}

void CameraTask::mark_stalled(const char* what) {
  healthy_ = false;
  // The first words stay put while the stall lasts (the console logs a reason when it
  // changes), so the time is the stall limit, not the growing age of the last frame.
  reason_.clear();
  reason_.appendf("no new frame for %.1f s", static_cast<double>(stall_us_) * 1e-6);
  // The driver's own error, else what was wrong with the last frames it did deliver.
  const char* why = what != nullptr ? what : camera_.error();
  if (why[0] == '\0' && last_bad_ != nullptr) why = last_bad_;
  if (why[0] != '\0') reason_.appendf(": %s", why);
}

void PanTiltTask::run(std::uint64_t now_us) {
  ptu_.update();
  const hal::PanTiltState s = ptu_.state();
  if (!s.moving || s.pan_rad != last_pan_rad_ || s.tilt_rad != last_tilt_rad_ || !seen_) {
    seen_ = true;
    last_pan_rad_ = s.pan_rad;
    last_tilt_rad_ = s.tilt_rad;
    progress_us_ = now_us;
    stuck_ = false;
    return;
  }
  stuck_ = now_us - progress_us_ > stuck_us_;
}

bool PanTiltTask::healthy() const {
  return !stuck_ && !ptu_.state().fault;
}

const char* PanTiltTask::health_reason() const {
  if (stuck_) return "PTU: a move is not progressing";
  const char* why = ptu_.error();
  return why[0] != '\0' ? why : "unit fault";
}

const char* led_pattern_name(LedPattern pattern) {
  switch (pattern) {
    case LedPattern::kFault:
      return "fault";
    case LedPattern::kEstop:
      return "estop";
    case LedPattern::kTargetFound:
      return "target";
    case LedPattern::kOk:
      return "ok";
  }
  return "?";
}

void BaseTask::run(std::uint64_t now_us) {
  base_.update();
  const bool stopped = base_.health() == hal::BaseHealth::kStopped;
  if (!stopped) {
    if (running_since_us_ == 0) running_since_us_ = now_us != 0 ? now_us : 1;
    if (now_us - running_since_us_ >= kStableUs) {
      interval_us_ = kRetryIntervalUs;  // well again: the next fault starts at a second
      quick_restops_ = 0;
      resumed_ = false;
    }
  } else if (running_since_us_ != 0) {
    running_since_us_ = 0;
    // Restarted by our retry and stopped again before it ran for kStableUs: past a few such
    // restarts (an intermittent fault that ends soon), back off.
    if (resumed_ && ++quick_restops_ > kGraceRestarts) {
      interval_us_ = std::min(2 * interval_us_, kMaxRetryIntervalUs);
    }
    resumed_ = false;
  }
  if (!stopped || safety_.holds()) {
    retry_at_us_ = 0;  // running, starting, or the operator's to restart
    return;
  }
  if (retry_at_us_ == 0) {
    retry_at_us_ = now_us + interval_us_;  // the first try a while after the stop
    return;
  }
  if (now_us < retry_at_us_) return;
  // Refused while the fault lasts (a lost heartbeat, bus-off); else the start-up sequence runs
  // and the base is ready again with no velocity commanded.
  resumed_ = base_.resume() && base_.health() != hal::BaseHealth::kStopped;
  ++retries_;
  retry_at_us_ = now_us + interval_us_;
}

void WatchdogTask::run(std::uint64_t now_us) {
  const bool healthy = executive_.all_healthy();
  // A device fault is held and retried for the retry time, then given up on (the firmware
  // exits and systemd restarts it with --resume); only a hang withholds the watchdog before.
  for (std::size_t i = 0; i < executive_.task_count() && i < unhealthy_since_us_.size(); ++i) {
    const char* why = executive_.task_health(i);
    std::uint64_t& since = unhealthy_since_us_[i];
    if (why == nullptr) {
      since = 0;
      continue;
    }
    if (since == 0) since = now_us != 0 ? now_us : 1;
    if (!gave_up_ && now_us - since >= retry_us_) {
      gave_up_ = true;
      give_up_reason_.clear();
      give_up_reason_.appendf("%s unhealthy for %.0f s: %s", executive_.spec(i).name,
                              static_cast<double>(now_us - since) * 1e-6, why);
    }
  }
  if (executive_.all_running() && !gave_up_) {
    if (watchdog_.kick()) {
      refusing_since_us_ = 0;
    } else {
      ++refused_;
      if (refusing_since_us_ == 0) refusing_since_us_ = now_us != 0 ? now_us : 1;
    }
    notifier_.watchdog();
    ++kicks_;
  } else {
    ++withheld_;
  }
  if (!healthy) {
    pattern_ = LedPattern::kFault;
  } else if (safety_ != nullptr && safety_->holds()) {
    pattern_ = LedPattern::kEstop;
  } else if (view_ != nullptr && view_->target().status == TargetStatus::kConfirmed) {
    pattern_ = LedPattern::kTargetFound;
  } else {
    pattern_ = LedPattern::kOk;
  }
  led_.write(((static_cast<std::uint32_t>(led_pattern_bits(pattern_)) >> step_) & 1U) != 0U);
  if (step_ == 0) report_status(healthy);
  step_ = (step_ + 1) % kStepsPerSecond;
}

void WatchdogTask::report_status(bool healthy) {
  TextBuffer<160> text;
  text.appendf("STATUS=state=%s cycle=%llu healthy=%d estop=%s target=%s",
               view_ != nullptr ? view_->state_name() : "running",
               static_cast<unsigned long long>(view_ != nullptr ? view_->cycles() : 0U),
               healthy ? 1 : 0,
               stop_cause_name(safety_ != nullptr ? safety_->cause() : StopCause::kNone),
               target_status_name(view_ != nullptr ? view_->target().status : TargetStatus::kNone));
  if (text.view() == status_.view()) return;
  if (!notifier_.send(text.c_str())) return;  // tried again next second
  status_.clear();
  status_.append(text.view());
}

}  // namespace boticelli::firmware
