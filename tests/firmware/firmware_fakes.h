// Small device fakes for the firmware tests: inputs, output, base, PTU, camera, watchdog (state
// only, no I/O).
#pragma once

#include <unistd.h>

#include <cstdint>

#include "firmware/executive/host_clock.h"
#include "hal/hal.h"

namespace boticelli::test {

class FakeInput final : public hal::DigitalIn {
 public:
  bool read() override { return level; }
  bool activated_since_last_poll() override {
    const bool e = edge;
    edge = false;
    return e;
  }
  void press() {
    level = true;
    edge = true;
  }
  bool level = false;
  bool edge = false;
};

class FakeOutput final : public hal::DigitalOut {
 public:
  void write(bool active) override {
    level = active;
    ++writes;
  }
  bool level = false;
  int writes = 0;
};

// Records stop() with the clock's time, so tests can tell how soon the base was stopped.
class FakeBase final : public hal::Base {
 public:
  explicit FakeBase(hal::Clock* clock = nullptr) : clock_(clock) {}
  bool init() override { return true; }
  void update() override { ++updates; }
  void set_velocity(float v, float w) override {
    if (health_ == hal::BaseHealth::kReady) {
      v_m_s = v;
      omega_rad_s = w;
    }
  }
  void stop() override {
    if (health_ != hal::BaseHealth::kStopped && clock_ != nullptr) {
      stopped_at_us = clock_->now_us();
    }
    ++stops;
    health_ = hal::BaseHealth::kStopped;
    v_m_s = 0.0F;
    omega_rad_s = 0.0F;
  }
  bool resume() override {
    ++resume_calls;
    if (refuse_resume) return false;
    health_ = hal::BaseHealth::kReady;
    return true;
  }
  hal::BaseHealth health() const override { return health_; }
  hal::Odometry odometry() const override { return odometry_value; }
  // Writes one byte 'G' to `gasp_fd` (a pipe a forked test watches): the crash's last act.
  void last_gasp_stop() noexcept override {
    if (gasp_fd >= 0) (void)!::write(gasp_fd, "G", 1);
  }

  hal::Odometry odometry_value;
  int gasp_fd = -1;
  float v_m_s = 0.0F;
  float omega_rad_s = 0.0F;
  int updates = 0;
  int stops = 0;
  bool refuse_resume = false;
  int resume_calls = 0;
  std::uint64_t stopped_at_us = 0;
  hal::BaseHealth health_ = hal::BaseHealth::kReady;

 private:
  hal::Clock* clock_;
};

class FakePanTilt final : public hal::PanTilt {
 public:
  bool init() override { return true; }
  void update() override { ++updates; }
  bool move_to(float pan, float tilt) override {
    if (refuse_moves) return false;
    state_value.pan_rad = pan;
    state_value.tilt_rad = tilt;
    return true;
  }
  void halt() override { ++halts; }
  hal::PanTiltState state() const override { return state_value; }
  hal::PanTiltLimits limits() const override { return {}; }
  hal::PanTiltState state_value;
  bool refuse_moves = false;
  int updates = 0;
  int halts = 0;
};

class FakeWatchdog final : public hal::Watchdog {
 public:
  bool start(std::uint32_t) override { return true; }
  bool kick() override {
    ++kicks;
    return !refuses;
  }
  void stop() override {}
  const char* error() const override { return refuses ? "watchdog: keep-alive refused: EIO" : ""; }
  int kicks = 0;
  bool refuses = false;  // every keep-alive refused while set
};

}  // namespace boticelli::test

namespace boticelli::test {

// Manual host clocks for the executive's host timings: time moves only when a test (or the
// work it times) says so; spend() moves the wall and the thread's CPU time together.
class FakeHostClock final : public firmware::HostClock {
 public:
  std::uint64_t monotonic_ns() override { return wall_ns; }
  std::uint64_t thread_cpu_ns() override { return cpu_ns; }
  // Work that ran on the CPU for `cpu` and took `wall` (≥ cpu: preempted or blocked) [ns].
  void spend(std::uint64_t wall, std::uint64_t cpu) {
    wall_ns += wall;
    cpu_ns += cpu;
  }
  std::uint64_t wall_ns = 7000000000ULL;
  std::uint64_t cpu_ns = 3000000ULL;
};

// A camera that delivers a small grey frame every `every` polls.
class FakeCamera final : public hal::Camera {
 public:
  bool init() override { return !fail_init; }
  hal::CameraPoll poll(hal::Frame& frame) override {
    if (fault) return hal::CameraPoll::kFault;
    if (++polls % every != 0) return hal::CameraPoll::kNoFrame;
    frame.data = pixels;
    frame.width_px = 2;
    frame.height_px = 2;
    frame.stride_bytes = 4;
    frame.sequence = sequence++;
    return hal::CameraPoll::kFrame;
  }
  void release() override { ++releases; }
  std::uint32_t width_px() const override { return 2; }
  std::uint32_t height_px() const override { return 2; }
  const char* error() const override { return fail_init ? "no such device" : ""; }
  bool fail_init = false;
  bool fault = false;
  int every = 3;
  int polls = 0;
  int releases = 0;
  std::uint32_t sequence = 0;
  std::uint8_t pixels[8] = {128, 128, 128, 128, 128, 128, 128, 128};
};

}  // namespace boticelli::test
