// Device tasks: camera polling and the watchdog kick (see device_tasks.h).
#include "firmware/device_tasks.h"

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
      ++frames_;
      last_frame_us_ = now_us;
      healthy_ = true;
      if (consumer_ != nullptr) consumer_->on_frame(frame);
      camera_.release();
      break;
    case hal::CameraPoll::kFault:
      ++faults_;
      if (now_us - last_frame_us_ > stall_us_) healthy_ = false;
      break;
    case hal::CameraPoll::kNoFrame:
      if (now_us - last_frame_us_ > stall_us_) healthy_ = false;
      break;
  }
}

void WatchdogTask::run(std::uint64_t) {
  if (executive_.all_healthy()) {
    watchdog_.kick();
    notifier_.watchdog();
    ++kicks_;
    led_on_ = !led_on_;
  } else {
    ++withheld_;
    led_on_ = false;
  }
  led_.write(led_on_);
}

}  // namespace boticelli::firmware
