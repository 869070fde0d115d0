// Small ray-casting renderer for stereo tests and bench: textured rectangles, YUYV out.
#pragma once

#include <cstdint>
#include <vector>

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "algo/stereo/rig.h"

namespace boticelli::test {

enum class Surface : std::uint8_t {
  kTexture,  // grey value noise over three octaves (scale_m the coarsest): features at every range
  kCamouflage,   // woodland blotches of scale_m with sharp edges: strong vertical derivatives
  kPlain,        // uniform `colour`
  kPaper,        // white matte paper
  kTarget,       // white paper with a green equilateral triangle of side target_side_m, vertex up
  kGreenSquare,  // white paper with a green square of side target_side_m (a decoy)
  // Decoys: the target's green triangle on `colour` instead of white paper, and on paper a
  // green triangle of base target_side_m three times as tall as the target's.
  kTriangleOnPlain,
  kTallTriangle,
};

// A rectangle: centre, in-plane unit axes (right, up as seen from the front) and half sizes.
struct Patch {
  Eigen::Vector3f centre_m = Eigen::Vector3f::Zero();
  Eigen::Vector3f right = Eigen::Vector3f::UnitY();
  Eigen::Vector3f up = Eigen::Vector3f::UnitZ();
  float half_width_m = 1.0F;
  float half_height_m = 1.0F;
  Surface surface = Surface::kPlain;
  Eigen::Vector3f colour = Eigen::Vector3f(0.6F, 0.6F, 0.6F);  // linear RGB in [0, 1]
  float scale_m = 0.05F;
  std::uint32_t seed = 1;
  float target_side_m = 0.2F;
};

// A wall facing a viewer at `eye`: centred at eye + distance·forward, perpendicular to
// `forward` (horizontal), with its up axis +z.
Patch facing_wall(const Eigen::Vector3f& eye_m, const Eigen::Vector3f& forward, float distance_m,
                  float half_size_m, Surface surface, std::uint32_t seed);

class SceneRenderer {
 public:
  void add(const Patch& patch) { patches_.push_back(patch); }
  void clear() { patches_.clear(); }
  [[nodiscard]] const std::vector<Patch>& patches() const { return patches_; }
  Eigen::Vector3f background = Eigen::Vector3f(0.3F, 0.3F, 0.3F);

  // Nearest hit of the ray origin + t·dir (t > 0); false if none.
  bool intersect(const Eigen::Vector3f& origin_m, const Eigen::Vector3f& dir, float& t_m,
                 const Patch** hit = nullptr) const;
  // Linear RGB seen along a ray.
  [[nodiscard]] Eigen::Vector3f shade(const Eigen::Vector3f& origin_m,
                                      const Eigen::Vector3f& dir) const;
  // Renders the rig's full-resolution camera at `pose` into packed YUYV (2 bytes per
  // pixel, rows of 2·width bytes), BT.601 full range, with luma noise of about
  // noise_sigma grey levels drawn deterministically from noise_seed. sample_step 2 casts
  // one ray per 2x2 pixels (4x faster; the 4x4 averaging still sees 2x2 samples per
  // low-resolution pixel), 1 one ray per pixel.
  void render_yuyv(const stereo::RigModel& rig, const stereo::CameraPose& pose, std::uint8_t* yuyv,
                   std::uint32_t noise_seed, float noise_sigma,
                   std::uint32_t sample_step = 1) const;

  // The target corner (upper vertex) of a kTarget patch, in the PTU frame.
  static Eigen::Vector3f target_corner(const Patch& patch);

 private:
  std::vector<Patch> patches_;
};

}  // namespace boticelli::test
