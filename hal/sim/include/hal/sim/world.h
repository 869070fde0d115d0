// World: the static scene of the sim board (surfaces to draw, obstacles to hit, start, target).
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <cstddef>
#include <cstdint>

#include "algo/core/geometry.h"

namespace boticelli::hal::sim {

// Capacities: a world file with more elements than these is rejected, not truncated.
inline constexpr std::size_t kMaxSurfaces = 256;
inline constexpr std::size_t kMaxColliders = 256;
inline constexpr std::size_t kMaxTextures = 64;    // distinct (pattern, seed) pairs (textures.h)
inline constexpr std::size_t kMaxNameLength = 63;  // model names, longer ones are cut
inline constexpr std::size_t kMaxWorldFileBytes = 4U << 20U;
inline constexpr std::size_t kMaxHullVertices = 8;

struct Rgb {
  float r = 0.7F;
  float g = 0.7F;
  float b = 0.7F;
};

// A rigid transform: p_world = rotation * p_local + translation_m.
struct RigidTransform {
  Eigen::Matrix3f rotation = Eigen::Matrix3f::Identity();
  Eigen::Vector3f translation_m = Eigen::Vector3f::Zero();

  Eigen::Vector3f apply(const Eigen::Vector3f& p) const { return rotation * p + translation_m; }
  RigidTransform then(const RigidTransform& child) const {
    return {rotation * child.rotation, rotation * child.translation_m + translation_m};
  }
};

// SDF pose "x y z roll pitch yaw": rotations about fixed axes, roll first (R = Rz Ry Rx).
RigidTransform transform_from_pose(const float xyz_rpy[6]);

enum class Shape : std::uint8_t { kBox, kCylinder, kPlane };
enum class Pattern : std::uint8_t { kPlain, kCamouflage, kLeaves, kPaper };

// Box faces by outward normal in the box's frame: 0 +x, 1 −x, 2 +y, 3 −y, 4 +z, 5 −z.
inline constexpr int kNoFace = -1;

// One drawable surface (an SDF visual) in world coordinates.
struct Surface {
  Shape shape = Shape::kBox;
  RigidTransform world_from_local;  // plane: local z is the normal
  // Box: half extents [m]; cylinder: radius, radius, half length [m]; plane: half x, half y, 0.
  Eigen::Vector3f half_size_m = Eigen::Vector3f::Zero();
  Rgb diffuse{};
  Pattern pattern = Pattern::kPlain;
  float pattern_scale_m = 0.1F;  // camouflage blotch size / leaf size [m]
  std::uint32_t pattern_seed = 1;
  int texture = -1;            // index into the TextureBank for camouflage and leaves
  int target_face = kNoFace;   // face with the green triangle, or kNoFace
  float target_size_m = 0.0F;  // side of the triangle [m]
  char model[kMaxNameLength + 1] = {};
  int line = 0;  // line of the <visual> in the world file
};

// One obstacle the robot's cylinder can hit: a vertical prism (convex polygon on the floor
// plane) or a vertical circular cylinder, between two heights.
struct Collider {
  bool circle = false;
  float centre_x_m = 0.0F;  // circle only
  float centre_y_m = 0.0F;
  float radius_m = 0.0F;
  core::Point2 hull[kMaxHullVertices]{};  // prism only, counter-clockwise
  std::size_t hull_size = 0;
  float z_min_m = 0.0F;
  float z_max_m = 0.0F;
  char model[kMaxNameLength + 1] = {};
  int line = 0;
};

// bugprone-reserved-identifier: clang-tidy 14 reports the `__i0` loop variable the compiler
// makes up for the implicit copy assignment of the array members, not a name written here.
// NOLINTNEXTLINE(bugprone-reserved-identifier)
struct World {
  char name[kMaxNameLength + 1] = {};
  Rgb ambient{0.5F, 0.5F, 0.5F};
  Eigen::Vector3f light_direction = Eigen::Vector3f(0.0F, 0.0F, -1.0F);  // unit, travel direction
  Rgb light_diffuse{0.5F, 0.5F, 0.5F};
  core::Pose2 start{};  // the robot's start pose
  Surface surfaces[kMaxSurfaces];
  std::size_t surface_count = 0;
  Collider colliders[kMaxColliders];
  std::size_t collider_count = 0;
  // The target: the upper vertex of the green triangle, and the face's outward normal.
  Eigen::Vector3f target_point_m = Eigen::Vector3f::Zero();
  Eigen::Vector3f target_normal = Eigen::Vector3f::UnitX();
  std::size_t target_surface = 0;
};

// Reads a world file (the SDF subset of docs/worlds.md). On failure returns false and writes
// "FILE:LINE: problem" into `error`. Allocates (tinyxml2): call at init only.
bool load_world(const char* path, World& world, char* error, std::size_t error_size);

// Same from text in memory; `file_label` names it in error messages.
bool parse_world(const char* xml, std::size_t size, const char* file_label, World& world,
                 char* error, std::size_t error_size);

// The upper vertex and the in-face axes of a target triangle on a box face, in world
// coordinates: `right` and `up` are unit vectors in the face, `centre_m` the face centre.
struct TargetFace {
  Eigen::Vector3f centre_m;
  Eigen::Vector3f normal;
  Eigen::Vector3f right;
  Eigen::Vector3f up;
};
TargetFace target_face_frame(const Surface& surface);

}  // namespace boticelli::hal::sim
