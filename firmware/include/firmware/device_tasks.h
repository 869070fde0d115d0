// Device tasks: the executive's fixed-rate tasks that service the HAL devices (see task_table.h).
#pragma once

#include <cstdint>

#include "firmware/console.h"
#include "firmware/executive.h"
#include "firmware/safety.h"
#include "firmware/service_notify.h"
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

// Services the base; unhealthy when it stopped by itself (fault, lost link), not by the e-stop.
class BaseTask final : public Task {
 public:
  BaseTask(hal::Base& base, const Safety& safety) : base_(base), safety_(safety) {}
  void run(std::uint64_t) override { base_.update(); }
  bool healthy() const override {
    return base_.health() != hal::BaseHealth::kStopped || safety_.engaged();
  }

 private:
  hal::Base& base_;
  const Safety& safety_;
};

class PanTiltTask final : public Task {
 public:
  explicit PanTiltTask(hal::PanTilt& ptu) : ptu_(ptu) {}
  void run(std::uint64_t) override { ptu_.update(); }
  bool healthy() const override { return !ptu_.state().fault; }

 private:
  hal::PanTilt& ptu_;
};

// Receives each new camera frame inside the camera task (copy or downsample what is needed:
// the buffer goes back to the driver right after on_frame()).
class FrameConsumer {
 public:
  virtual ~FrameConsumer() = default;
  virtual void on_frame(const hal::Frame& frame) = 0;
  // False while the consumer has no use for frames: the camera task then polls only every
  // idle_poll_us (enough to keep its health), so a simulated camera renders only what is used.
  virtual bool wants_frames() const { return true; }

 protected:
  FrameConsumer() = default;
  FrameConsumer(const FrameConsumer&) = default;
  FrameConsumer& operator=(const FrameConsumer&) = default;
};

// Polls the camera; unhealthy when no frame came for stall_us (a fault the driver recovers
// from quickly, e.g. a re-opened device, does not count against the watchdog).
class CameraTask final : public Task {
 public:
  explicit CameraTask(hal::Camera& camera, std::uint64_t stall_us = 2000000,
                      std::uint64_t idle_poll_us = 1500000)
      : camera_(camera), stall_us_(stall_us), idle_poll_us_(idle_poll_us) {}
  void set_consumer(FrameConsumer* consumer) { consumer_ = consumer; }
  void run(std::uint64_t now_us) override;
  bool healthy() const override { return healthy_; }
  std::uint64_t frames() const { return frames_; }
  std::uint64_t faults() const { return faults_; }

 private:
  hal::Camera& camera_;
  std::uint64_t stall_us_;
  std::uint64_t idle_poll_us_;
  std::uint64_t last_poll_us_ = 0;
  FrameConsumer* consumer_ = nullptr;
  std::uint64_t last_frame_us_ = 0;
  bool seen_time_ = false;
  bool healthy_ = true;
  std::uint64_t frames_ = 0;
  std::uint64_t faults_ = 0;
};

class ConsoleTask final : public Task {
 public:
  explicit ConsoleTask(Console& console) : console_(console) {}
  void run(std::uint64_t now_us) override { console_.service(now_us); }
  bool healthy() const override { return console_.healthy(); }

 private:
  Console& console_;
};

// Kicks /dev/watchdog and sends WATCHDOG=1 to systemd only while every task is healthy;
// blinks the status LED while it does (steady off when it withholds the kick).
class WatchdogTask final : public Task {
 public:
  WatchdogTask(const Executive& executive, hal::Watchdog& watchdog, ServiceNotifier& notifier,
               hal::DigitalOut& led)
      : executive_(executive), watchdog_(watchdog), notifier_(notifier), led_(led) {}
  void run(std::uint64_t now_us) override;
  std::uint64_t kicks() const { return kicks_; }
  std::uint64_t withheld() const { return withheld_; }

 private:
  const Executive& executive_;
  hal::Watchdog& watchdog_;
  ServiceNotifier& notifier_;
  hal::DigitalOut& led_;
  bool led_on_ = false;
  std::uint64_t kicks_ = 0;
  std::uint64_t withheld_ = 0;
};

}  // namespace boticelli::firmware
