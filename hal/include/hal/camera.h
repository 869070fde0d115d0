// Camera: non-blocking frame source (V4L2 on Linux boards, the ray caster on the sim board).
#pragma once

#include <cstdint>

#include "hal/noncopyable.h"

namespace boticelli::hal {

enum class PixelFormat : std::uint8_t { kYuyv };

// A borrowed frame: valid from a successful poll() until release() or the next poll().
struct Frame {
  const std::uint8_t* data = nullptr;
  std::uint32_t width_px = 0;
  std::uint32_t height_px = 0;
  std::uint32_t stride_bytes = 0;  // bytes per row (≥ 2 * width for YUYV)
  PixelFormat format = PixelFormat::kYuyv;
  std::uint64_t timestamp_us = 0;  // capture time on the board's Clock
  std::uint32_t sequence = 0;      // increases by one per captured frame
};

enum class CameraPoll : std::uint8_t {
  kNoFrame,  // nothing new yet; try again next frame
  kFrame,    // `frame` holds a new image; call release() when done with it
  kFault,    // the device failed; the driver recovers by itself (see error())
};

class Camera : private NonCopyable {
 public:
  virtual ~Camera() = default;
  // Opens and starts streaming; false with error() set when the device cannot be used.
  virtual bool init() = 0;
  // Returns at once: a new frame, none yet, or a fault.
  virtual CameraPoll poll(Frame& frame) = 0;
  // Hands the last polled frame's buffer back to the driver.
  virtual void release() = 0;
  // Negotiated size [px]; 0 before init().
  virtual std::uint32_t width_px() const = 0;
  virtual std::uint32_t height_px() const = 0;
  // Human-readable last error, "" when healthy.
  virtual const char* error() const { return ""; }
};

}  // namespace boticelli::hal
