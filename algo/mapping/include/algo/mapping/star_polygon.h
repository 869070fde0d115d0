// StarPolygon: a polygon star-shaped about the robot, one vertex per evenly spaced pan angle
// (§5.4.2).
#pragma once

#include <algorithm>
#include <array>
#include <cmath>
#include <cstddef>

#include "algo/core/angles.h"
#include "algo/core/geometry.h"

namespace boticelli::mapping {

// Most vertices a polygon can hold; the count in use is set at run time (default 360).
inline constexpr std::size_t kMaxPolygonVertices = 720;
inline constexpr std::size_t kDefaultPolygonVertices = 360;

// Vertex k lies at angle θ_k = k·2π/n [rad] (robot frame, counter-clockwise from the
// robot's heading) and distance ρ_k [m] from the robot centre; consecutive vertices
// (k, k+1 mod n) are joined by straight edges. The region is the union of the triangles
// (centre, vertex k, vertex k+1), so it is star-shaped about the centre by construction.
class StarPolygon {
 public:
  StarPolygon() = default;
  explicit StarPolygon(std::size_t vertex_count) { set_vertex_count(vertex_count); }

  // Sets n (clamped to [3, kMaxPolygonVertices]) and every ρ to 0.
  void set_vertex_count(std::size_t vertex_count);
  [[nodiscard]] std::size_t vertex_count() const { return count_; }

  [[nodiscard]] float angle_step_rad() const { return angle_step_rad(count_); }
  // The vertex count set_vertex_count() makes of vertex_count, and the angle between the
  // vertex rays of a polygon with vertex_count vertices [rad]: for code that needs a
  // polygon's fan but not its 2.9 KB of ρ.
  [[nodiscard]] static std::size_t clamped_vertex_count(std::size_t vertex_count) {
    return std::clamp<std::size_t>(vertex_count, 3, kMaxPolygonVertices);
  }
  [[nodiscard]] static float angle_step_rad(std::size_t vertex_count) {
    return core::kTwoPi<float> / static_cast<float>(vertex_count);
  }
  [[nodiscard]] float angle_rad(std::size_t k) const {
    return static_cast<float>(k) * angle_step_rad();
  }
  [[nodiscard]] float rho_m(std::size_t k) const { return rho_m_[k]; }
  void set_rho_m(std::size_t k, float rho_m) { rho_m_[k] = rho_m; }
  void fill(float rho_m);

  // Vertex k in the robot frame [m].
  [[nodiscard]] core::Point2 vertex(std::size_t k) const;

  // Exact distance [m] from the centre to the boundary along direction θ [rad] (any value).
  [[nodiscard]] float radius_at_m(float theta_rad) const;
  // True if p (robot frame) lies in the closed region.
  [[nodiscard]] bool contains(core::Point2 p) const;
  // Area [m²] (sum of the n triangles).
  [[nodiscard]] float area_m2() const;
  [[nodiscard]] float min_rho_m() const;
  [[nodiscard]] float max_rho_m() const;

 private:
  std::array<float, kMaxPolygonVertices> rho_m_{};
  std::size_t count_ = kDefaultPolygonVertices;
};

}  // namespace boticelli::mapping
