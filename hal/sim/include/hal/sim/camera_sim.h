// CameraSim: the sim board's camera — renders the world from the true camera pose at a frame rate.
#pragma once

#include <cstdint>
#include <memory>

#include "hal/camera.h"
#include "hal/sim/renderer.h"
#include "hal/sim/sim_world.h"

namespace boticelli::hal::sim {

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
  RigidTransform last_pose_{};
  const char* error_ = "";
};

}  // namespace boticelli::hal::sim
