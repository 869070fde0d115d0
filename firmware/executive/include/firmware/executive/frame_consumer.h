// FrameConsumer: what the camera task hands each new frame to (the mission's look).
#pragma once

#include "hal/camera.h"

namespace boticelli::firmware {

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

}  // namespace boticelli::firmware
