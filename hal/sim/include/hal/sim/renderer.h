// Renderer: ray caster that draws a World as the camera sees it (YUYV) plus ground-truth depth.
#pragma once

#include <cstddef>
#include <cstdint>
#include <memory>

#include "algo/stereo/rig.h"
#include "hal/sim/textures.h"
#include "hal/sim/world.h"

namespace boticelli::hal::sim {

// Image formation after the scene radiance (all deterministic for a given seed).
struct RenderSettings {
  float gain = 1.0F;                // radiance 1.0 → 255 grey levels before clipping
  float noise_sigma_grey = 2.0F;    // sensor noise, standard deviation [grey levels of Y]
  float chroma_noise_sigma = 0.0F;  // the same for Cb and Cr, per pixel pair [chroma levels]
  // Auto-exposure: each frame's gain is gain · (1 + exposure_jitter · g), g a standard normal
  // drawn per frame (the two frames of a stereo pair differ).
  float exposure_jitter = 0.0F;
  float vignetting = 0.25F;             // relative brightness loss at the image corners [0, 1)
  bool shading = true;                  // Lambert + ambient; false = albedo only
  std::uint64_t seed = 1;               // noise seed
  Rgb background{0.05F, 0.05F, 0.06F};  // rays that hit nothing
};

// First surface hit by the ray origin + t·direction, t > 0 (direction need not be unit; t is
// in its units). False when nothing is hit. For ground truth (visibility of the target).
bool cast_ray(const World& world, const Eigen::Vector3f& origin_m, const Eigen::Vector3f& direction,
              std::size_t& surface, float& t);

class Renderer {
 public:
  // Precomputes the per-pixel rays (with the lens distortion, rig.h) and the vignetting; allocates,
  // so call at init. `world` and `textures` must outlive the renderer.
  bool init(const World& world, const TextureBank& textures, const stereo::CameraIntrinsics& camera,
            const RenderSettings& settings, char* error, std::size_t error_size);

  // Draws the view from `world_from_camera` (camera frame: x right, y down, z forward) into
  // a YUYV image (`stride_bytes` per row) and, if `depth_m` is given, the z-depth [m] along
  // the optical axis of every pixel (+inf where nothing is hit). `frame_index` selects the
  // noise. Either output may be null. Does not allocate.
  void render(const RigidTransform& world_from_camera, std::uint32_t frame_index,
              std::uint8_t* yuyv, std::size_t stride_bytes, float* depth_m) const;

  // The surface seen through pixel (u, v) [px, integer pixel centres], and its depth;
  // false when nothing is hit. For tests and ground truth.
  bool trace_pixel(const RigidTransform& world_from_camera, std::uint32_t u, std::uint32_t v,
                   std::size_t& surface, float& depth_m) const;

  std::uint32_t width_px() const { return width_; }
  std::uint32_t height_px() const { return height_; }
  const RenderSettings& settings() const { return settings_; }
  void set_settings(const RenderSettings& settings);

 private:
  struct Candidate;
  struct FrameSetup;
  static constexpr std::uint32_t kTile = 16;  // tile edge [px] for culling

  void setup_frame(const RigidTransform& world_from_camera, FrameSetup& setup) const;
  void tile_candidates(const FrameSetup& setup, std::uint32_t tile, std::uint16_t* list,
                       std::size_t& count) const;

  const World* world_ = nullptr;
  const TextureBank* textures_ = nullptr;
  RenderSettings settings_{};
  std::uint32_t width_ = 0;
  std::uint32_t height_ = 0;
  std::uint32_t tiles_x_ = 0;
  std::uint32_t tiles_y_ = 0;
  // Per pixel: undistorted normalised ray (x/z, y/z); the ray is (x, y, 1) in the camera frame.
  std::unique_ptr<float[]> rays_;
  std::unique_ptr<float[]> vignette_;  // per pixel brightness factor
  // Per tile: bounds of its pixels' normalised rays (min x, min y, max x, max y).
  std::unique_ptr<float[]> tile_bounds_;
  // Ambient + Lambert light of each flat face (box faces 0..5, plane and caps use 4 and 5),
  // per surface: the world is static, so this is computed once.
  std::unique_ptr<Eigen::Vector3f[]> face_light_;
  // The target triangle in its surface's frame (centre of the face, in-face unit axes).
  Eigen::Vector3f target_centre_local_ = Eigen::Vector3f::Zero();
  Eigen::Vector3f target_up_local_ = Eigen::Vector3f::UnitZ();
  Eigen::Vector3f target_right_local_ = Eigen::Vector3f::UnitY();
};

}  // namespace boticelli::hal::sim
