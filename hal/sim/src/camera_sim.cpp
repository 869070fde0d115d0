// CameraSim: frame timing in simulated time and rendering of each captured frame.
#include "hal/sim/camera_sim.h"

#include <cmath>
#include <cstdio>

namespace boticelli::hal::sim {

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
  next_capture_us_ = world_.now_us();
  return true;
}

CameraPoll CameraSim::poll(Frame& frame) {
  if (!streaming_) return CameraPoll::kFault;
  const std::uint64_t now = world_.now_us();
  if (now < next_capture_us_) return CameraPoll::kNoFrame;
  // Frames come on the period grid; missed ones are skipped, as a streaming camera drops them.
  const std::uint64_t late = (now - next_capture_us_) / period_us_;
  next_capture_us_ += (late + 1) * period_us_;
  last_pose_ = world_.camera_pose();
  const std::uint32_t width = renderer_.width_px();
  renderer_.render(last_pose_, sequence_, image_.get(), std::size_t{2} * width,
                   depth_enabled_ ? depth_.get() : nullptr);
  frame.data = image_.get();
  frame.width_px = width;
  frame.height_px = renderer_.height_px();
  frame.stride_bytes = 2U * width;
  frame.format = PixelFormat::kYuyv;
  frame.timestamp_us = now;
  frame.sequence = sequence_++;
  return CameraPoll::kFrame;
}

}  // namespace boticelli::hal::sim
