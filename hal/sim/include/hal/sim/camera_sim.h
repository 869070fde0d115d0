// CameraSim: the sim board's camera — renders the world from the true camera pose at a frame rate.
#pragma once

#include <cstdint>
#include <memory>

#include "hal/camera.h"
#include "hal/sim/renderer.h"
#include "hal/sim/sim_world.h"

namespace boticelli::hal::sim {

// Injected faults (FaultDevice::kCamera): off = the device is gone (kFault) until the fault
// ends, stuck = the same frame again (same sequence number, a new timestamp), garbage =
// frames with the error flag (dropped, as the V4L2 driver does), wrong = frames of half the
// negotiated size, slow = a tenth of the frame rate, delayed = each frame delivered 0.5 s
// after its capture (with its capture time), intermittent = gone in its failing slots.
class CameraSim final : public Camera {
 public:
  CameraSim(SimWorld& world, Renderer& renderer) : world_(world), renderer_(renderer) {}
  // Sizes the frame (and ground-truth depth) buffers for the renderer's image; allocates, so
  // the board calls it during its init. `fps` is the capture rate in simulated time.
  bool setup(float fps, char* error, std::size_t error_size);

  bool init() override;
  // A frame is captured (rendered from the pose at that instant) once per frame period.
  CameraPoll poll(Frame& frame) override;
  void release() override {}
  std::uint32_t width_px() const override { return streaming_ ? renderer_.width_px() : 0; }
  std::uint32_t height_px() const override { return streaming_ ? renderer_.height_px() : 0; }
  const char* error() const override { return error_; }

  // ---- sim-only ----
  // Also render the ground-truth z-depth [m] of every pixel of each frame (off by default).
  void set_depth_enabled(bool enabled) { depth_enabled_ = enabled; }
  // Depth of the last frame (when enabled), row-major, width x height; +inf = nothing hit.
  const float* depth_m() const { return depth_.get(); }
  // The camera pose of the last frame.
  const RigidTransform& last_pose() const { return last_pose_; }

 private:
  SimWorld& world_;
  Renderer& renderer_;
  std::unique_ptr<std::uint8_t[]> image_;
  std::unique_ptr<float[]> depth_;
  std::uint64_t period_us_ = 33333;
  std::uint64_t next_capture_us_ = 0;
  std::uint32_t sequence_ = 0;
  bool streaming_ = false;
  bool depth_enabled_ = false;
  static constexpr std::uint64_t kDelayUs = 500000;
  // Renders the frame captured now into image_ (and depth_).
  void capture();
  CameraPoll deliver(Frame& frame, std::uint64_t timestamp_us, std::uint32_t sequence,
                     bool half_size);

  RigidTransform last_pose_{};
  const char* error_ = "";
  bool has_frame_ = false;  // image_ holds a rendered frame (for a stuck camera)
  bool delayed_pending_ = false;
  std::uint64_t delayed_capture_us_ = 0;
  std::uint32_t delayed_sequence_ = 0;
};

}  // namespace boticelli::hal::sim
