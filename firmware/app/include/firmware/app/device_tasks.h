// Device tasks: the executive's fixed-rate tasks that service the HAL devices (see task_table.h).
#pragma once

#include <array>
#include <cstdint>

#include "firmware/console/console.h"
#include "firmware/executive/executive.h"
#include "firmware/executive/frame_consumer.h"
#include "firmware/telemetry/mission_view.h"
#include "firmware/safety/safety.h"
#include "firmware/app/service_notify.h"
#include "firmware/common/text_buffer.h"
#include "hal/hal.h"

namespace boticelli::firmware {

// First in every frame: e-stop button and bumper → base stop.
class EstopTask final : public Task {
 public:
  explicit EstopTask(Safety& safety) : safety_(safety) {}
  void run(std::uint64_t) override { safety_.poll(); }

 private:
  Safety& safety_;
};

// Services the base; unhealthy when it stopped by itself (fault, lost link), not by the e-stop
// latch (engaged, or reset and waiting for `resume`). A base that stopped by itself is tried
// again (Base::resume, the drivers' start-up sequence) every retry interval while the latch
// does not hold it: the fault policy (docs/reliability.md) holds the robot stopped and
// retries the device; only the mission commands motion after that, and it looks first.
// The base's retry after it stopped by itself: resume() a second after the stop and every
// second while it is refused (the fault lasts). Past kGraceRestarts resumes that were
// accepted but followed by another stop within kStableUs (a jammed wheel, an intermittent bus
// that does not end: the base is restarted into the same fault), each such stop doubles the
// wait, up to kMaxRetryIntervalUs; a base that runs kStableUs without stopping is well again
// and the wait is back to a second.
class BaseTask final : public Task {
 public:
  static constexpr std::uint64_t kRetryIntervalUs = 1000000;
  static constexpr std::uint64_t kMaxRetryIntervalUs = 8000000;
  static constexpr std::uint64_t kStableUs = 10000000;
  static constexpr int kGraceRestarts = 3;
  BaseTask(hal::Base& base, const Safety& safety) : base_(base), safety_(safety) {}
  void run(std::uint64_t now_us) override;
  std::uint64_t retries() const { return retries_; }
  // The wait before the next retry once the base stops (grows with restarts into a fault).
  std::uint64_t retry_interval_us() const { return interval_us_; }
  bool healthy() const override {
    return base_.health() != hal::BaseHealth::kStopped || safety_.holds();
  }
  const char* health_reason() const override {
    const char* why = base_.error();
    return why[0] != '\0' ? why : "stopped by itself";
  }

 private:
  hal::Base& base_;
  const Safety& safety_;
  std::uint64_t retry_at_us_ = 0;  // 0: not stopped by itself
  std::uint64_t retries_ = 0;
  std::uint64_t interval_us_ = kRetryIntervalUs;
  std::uint64_t running_since_us_ = 0;  // 0: stopped
  bool resumed_ = false;                // the last retry was accepted (the base restarted)
  int quick_restops_ = 0;               // restarts stopped again within kStableUs
};

// Services the PTU; unhealthy while the unit reports a fault, or while a move has not
// changed the reported position for stuck_us (a move that never completes).
class PanTiltTask final : public Task {
 public:
  explicit PanTiltTask(hal::PanTilt& ptu, std::uint64_t stuck_us = 2000000)
      : ptu_(ptu), stuck_us_(stuck_us) {}
  void run(std::uint64_t now_us) override;
  bool healthy() const override;
  const char* health_reason() const override;

 private:
  hal::PanTilt& ptu_;
  std::uint64_t stuck_us_;
  std::uint64_t progress_us_ = 0;
  float last_pan_rad_ = 0.0F;
  float last_tilt_rad_ = 0.0F;
  bool seen_ = false;
  bool stuck_ = false;
};

// Polls the camera; unhealthy when no new frame came for stall_us (a fault the driver
// recovers from quickly, e.g. a re-opened device, does not count against the watchdog). A
// frame whose sequence number did not advance is the same image again (a frozen driver): it
// is neither used nor counted as a new frame.
class CameraTask final : public Task {
 public:
  explicit CameraTask(hal::Camera& camera, std::uint64_t stall_us = 2000000,
                      std::uint64_t idle_poll_us = 1500000)
      : camera_(camera), stall_us_(stall_us), idle_poll_us_(idle_poll_us) {}
  void set_consumer(FrameConsumer* consumer) { consumer_ = consumer; }
  void run(std::uint64_t now_us) override;
  bool healthy() const override { return healthy_; }
  // "no frame for N.N s", with the driver's last error when it gave one.
  const char* health_reason() const override { return reason_.c_str(); }
  std::uint64_t frames() const { return frames_; }
  std::uint64_t faults() const { return faults_; }
  // Frames whose sequence number did not advance (the driver handed the same image again).
  std::uint64_t stale_frames() const { return stale_frames_; }

 private:
  hal::Camera& camera_;
  std::uint64_t stall_us_;
  std::uint64_t idle_poll_us_;
  std::uint64_t last_poll_us_ = 0;
  FrameConsumer* consumer_ = nullptr;
  std::uint64_t last_frame_us_ = 0;
  bool seen_time_ = false;
  // Unhealthy, with the reason: `what` (or the driver's error when nullptr).
  void mark_stalled(const char* what);

  bool healthy_ = true;
  TextBuffer<128> reason_;
  std::uint64_t frames_ = 0;
  std::uint64_t faults_ = 0;
  std::uint64_t stale_frames_ = 0;
  std::uint64_t wrong_frames_ = 0;
  std::uint32_t last_sequence_ = 0;
  bool have_sequence_ = false;
  const char* last_bad_ = nullptr;  // what was wrong with the last unusable frame
};

class ConsoleTask final : public Task {
 public:
  explicit ConsoleTask(Console& console) : console_(console) {}
  void run(std::uint64_t now_us) override { console_.service(now_us); }
  bool healthy() const override { return console_.healthy(); }
  const char* health_reason() const override { return "console line fault"; }

 private:
  Console& console_;
};

// What the status LED shows, most urgent first (docs/flashing.md): each pattern is ten
// 100 ms steps, bit i = step i, repeated every second.
enum class LedPattern : std::uint8_t {
  kFault,        // a task unhealthy (watchdog withheld): double flash, 100 on 100 off 100 on
  kEstop,        // e-stop latched or waiting for resume: fast blink, 5 Hz
  kTargetFound,  // the target confirmed by two views: steady on
  kOk,           // running, healthy: slow blink, 1 Hz
};
constexpr std::uint16_t led_pattern_bits(LedPattern pattern) {
  switch (pattern) {
    case LedPattern::kFault:
      return 0b0000000101;
    case LedPattern::kEstop:
      return 0b0101010101;
    case LedPattern::kTargetFound:
      return 0b1111111111;
    case LedPattern::kOk:
      return 0b0000011111;
  }
  return 0;
}
const char* led_pattern_name(LedPattern pattern);

// Kicks /dev/watchdog and sends WATCHDOG=1 to systemd while the executive runs (no task
// overrunning or starved: a hang) and no task has been unhealthy for longer than the device
// retry time; a device fault within that time is the fault policy's to hold and retry, not a
// hang. Past it the task gives up (gave_up(): the firmware exits for a restart). A keep-alive
// the device refuses makes this task unhealthy until one is taken again (the board resets if
// none is within its timeout; the mission holds the robot stopped meanwhile), and like any
// device fault it is given up on after the retry time;
// drives the status LED with the pattern of the robot's condition; once a second, when it
// changed, reports the state to systemd as "STATUS=state=... cycle=N healthy=0|1 estop=...
// target=..." (what `systemctl status` shows). Runs every 100 ms (kTaskTable).
class WatchdogTask final : public Task {
 public:
  WatchdogTask(const Executive& executive, hal::Watchdog& watchdog, ServiceNotifier& notifier,
               hal::DigitalOut& led)
      : executive_(executive), watchdog_(watchdog), notifier_(notifier), led_(led) {}
  // Where the e-stop and the mission's state come from (optional: without them only health).
  void set_status_sources(const Safety* safety, const MissionView* view) {
    safety_ = safety;
    view_ = view;
  }
  void run(std::uint64_t now_us) override;
  bool healthy() const override { return refusing_since_us_ == 0; }
  const char* health_reason() const override {
    return refusing_since_us_ != 0 ? watchdog_.error() : "";
  }
  // How long a task may stay unhealthy before the firmware gives up on it [µs].
  void set_retry_us(std::uint64_t us) { retry_us_ = us; }
  // A task was unhealthy for longer than the retry time; give_up_reason() says which and why
  // ("camera unhealthy for 30 s: no new frame ..."). Stays set.
  bool gave_up() const { return gave_up_; }
  const char* give_up_reason() const { return give_up_reason_.c_str(); }
  std::uint64_t kicks() const { return kicks_; }
  std::uint64_t withheld() const { return withheld_; }
  // Keep-alives the device refused since the start.
  std::uint64_t refused() const { return refused_; }
  LedPattern pattern() const { return pattern_; }
  // The last STATUS= text sent (without the "STATUS=" prefix).
  const char* status_text() const {
    return status_.size() > kStatusPrefix ? status_.c_str() + kStatusPrefix : "";
  }

 private:
  static constexpr std::size_t kStatusPrefix = 7;  // "STATUS="
  static constexpr std::uint32_t kStepsPerSecond = 10;
  void report_status(bool healthy);

  const Executive& executive_;
  hal::Watchdog& watchdog_;
  ServiceNotifier& notifier_;
  hal::DigitalOut& led_;
  const Safety* safety_ = nullptr;
  const MissionView* view_ = nullptr;
  LedPattern pattern_ = LedPattern::kOk;
  std::uint32_t step_ = 0;
  TextBuffer<160> status_;
  std::uint64_t kicks_ = 0;
  std::uint64_t withheld_ = 0;
  std::uint64_t refused_ = 0;
  std::uint64_t refusing_since_us_ = 0;  // 0: the last keep-alive was taken
  std::uint64_t retry_us_ = 30000000;
  std::array<std::uint64_t, Executive::kMaxTasks> unhealthy_since_us_{};  // 0: healthy
  bool gave_up_ = false;
  TextBuffer<200> give_up_reason_;
};

}  // namespace boticelli::firmware
