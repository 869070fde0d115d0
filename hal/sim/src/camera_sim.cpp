// CameraSim: frame timing in simulated time and rendering of each captured frame.
#include "hal/sim/camera_sim.h"

#include <cmath>
#include <cstdio>
#include <ctime>

namespace boticelli::hal::sim {
namespace {

std::uint64_t thread_cpu_ns() {
  timespec ts{};
  if (::clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts) != 0) return 0;
  return static_cast<std::uint64_t>(ts.tv_sec) * 1000000000U +
         static_cast<std::uint64_t>(ts.tv_nsec);
}

std::uint64_t wall_ns() {
  timespec ts{};
  if (::clock_gettime(CLOCK_MONOTONIC, &ts) != 0) return 0;
  return static_cast<std::uint64_t>(ts.tv_sec) * 1000000000U +
         static_cast<std::uint64_t>(ts.tv_nsec);
}

}  // namespace

bool CameraSim::setup(float fps, char* error, std::size_t error_size) {
  if (!(fps >= 1.0F && fps <= 1000.0F) || renderer_.width_px() == 0) {
    std::snprintf(error, error_size, "camera: %g fps or an uninitialised renderer",
                  static_cast<double>(fps));
    return false;
  }
  period_us_ = static_cast<std::uint64_t>(std::llround(1e6 / static_cast<double>(fps)));
  sequence_ = 0;  // a new run: the same seed gives the same frames
  const std::size_t pixels = static_cast<std::size_t>(renderer_.width_px()) * renderer_.height_px();
  image_.reset(new std::uint8_t[2 * pixels]());
  depth_.reset(new float[pixels]());
  return true;
}

bool CameraSim::init() {
  if (!image_) {
    error_ = "camera not set up by the board";
    return false;
  }
  streaming_ = true;
  error_ = "";
  has_frame_ = false;
  delayed_pending_ = false;
  next_capture_us_ = world_.now_us();
  return true;
}

void CameraSim::capture() {
  last_pose_ = world_.camera_pose();
  const std::uint32_t width = renderer_.width_px();
  // Rendering is the simulator's work, not the driver's (a V4L2 dequeue hands over a buffer):
  // its CPU and wall time are booked so that host timings can leave them out.
  const std::uint64_t wall_start_ns = wall_ns();
  const std::uint64_t cpu_start_ns = thread_cpu_ns();
  renderer_.render(last_pose_, sequence_, image_.get(), std::size_t{2} * width,
                   depth_enabled_ ? depth_.get() : nullptr);
  const std::uint64_t cpu_end_ns = thread_cpu_ns();
  const std::uint64_t wall_end_ns = wall_ns();
  if (cpu_end_ns > cpu_start_ns) world_.add_simulator_cpu_ns(cpu_end_ns - cpu_start_ns);
  if (wall_end_ns > wall_start_ns) world_.add_simulator_wall_ns(wall_end_ns - wall_start_ns);
  has_frame_ = true;
}

CameraPoll CameraSim::deliver(Frame& frame, std::uint64_t timestamp_us, std::uint32_t sequence,
                              bool half_size) {
  const std::uint32_t width = renderer_.width_px();
  frame.data = image_.get();
  frame.width_px = half_size ? width / 2U : width;
  frame.height_px = half_size ? renderer_.height_px() / 2U : renderer_.height_px();
  frame.stride_bytes = 2U * frame.width_px;
  frame.format = PixelFormat::kYuyv;
  frame.timestamp_us = timestamp_us;
  frame.sequence = sequence;
  return CameraPoll::kFrame;
}

CameraPoll CameraSim::poll(Frame& frame) {
  if (!streaming_) return CameraPoll::kFault;
  const std::uint64_t now = world_.now_us();
  FaultType fault = FaultType::kOff;
  const bool failing = world_.faults().failing(FaultDevice::kCamera, fault);
  if (failing && (fault == FaultType::kOff || fault == FaultType::kIntermittent)) {
    error_ = "camera: device gone (ENODEV), re-opening";
    delayed_pending_ = false;
    return CameraPoll::kFault;
  }
  error_ = "";
  if (delayed_pending_) {
    if (now < delayed_capture_us_ + kDelayUs) return CameraPoll::kNoFrame;
    delayed_pending_ = false;
    return deliver(frame, delayed_capture_us_, delayed_sequence_, false);
  }
  // Back from a slow spell: the next frame comes at the normal rate again.
  if (!(failing && fault == FaultType::kSlow) && next_capture_us_ > now + period_us_) {
    next_capture_us_ = now;
  }
  if (now < next_capture_us_) return CameraPoll::kNoFrame;
  // Frames come on the period grid; missed ones are skipped, as a streaming camera drops them.
  const std::uint64_t period = failing && fault == FaultType::kSlow ? 10U * period_us_ : period_us_;
  const std::uint64_t late = (now - next_capture_us_) / period;
  next_capture_us_ += (late + 1) * period;
  if (failing && fault == FaultType::kGarbage) {
    ++sequence_;  // an error-flagged buffer: the driver drops and re-queues it
    return CameraPoll::kNoFrame;
  }
  if (failing && fault == FaultType::kStuck && has_frame_ && sequence_ > 0) {
    return deliver(frame, now, sequence_ - 1U, false);  // the same buffer again
  }
  capture();
  if (failing && fault == FaultType::kDelayed) {
    delayed_pending_ = true;
    delayed_capture_us_ = now;
    delayed_sequence_ = sequence_++;
    return CameraPoll::kNoFrame;
  }
  return deliver(frame, now, sequence_++, failing && fault == FaultType::kWrong);
}

}  // namespace boticelli::hal::sim
