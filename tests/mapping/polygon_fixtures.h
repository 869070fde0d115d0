// Test fixtures for mapping and planning: random star polygons and a 2-D world of wall segments.
#pragma once

#include <algorithm>
#include <array>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <limits>

#include "algo/core/angles.h"
#include "algo/core/geometry.h"
#include "algo/mapping/star_polygon.h"

namespace boticelli::test {

// Deterministic xorshift32 with uniform floats.
class Random {
 public:
  explicit Random(std::uint32_t seed) : state_(seed * 2654435761U + 1U) {}
  std::uint32_t next() {
    state_ ^= state_ << 13;
    state_ ^= state_ >> 17;
    state_ ^= state_ << 5;
    return state_;
  }
  float uniform(float lo, float hi) {
    return lo + (hi - lo) * static_cast<float>(next() >> 8) / 16777216.0F;
  }

 private:
  std::uint32_t state_;
};

// A jagged star polygon: smooth harmonics plus random notches and spikes, ρ in [0.6, 3] m.
inline void random_star_polygon(Random& rng, mapping::StarPolygon& out, std::size_t n = 360) {
  out.set_vertex_count(n);
  const float base = rng.uniform(1.2F, 2.2F);
  std::array<float, 4> amp{};
  std::array<float, 4> phase{};
  for (std::size_t i = 0; i < amp.size(); ++i) {
    amp[i] = rng.uniform(0.0F, 0.3F);
    phase[i] = rng.uniform(0.0F, 6.28F);
  }
  for (std::size_t k = 0; k < n; ++k) {
    const float a = out.angle_rad(k);
    float rho = base;
    for (std::size_t i = 0; i < amp.size(); ++i) {
      rho += amp[i] * std::sin(static_cast<float>(i + 2) * a + phase[i]);
    }
    out.set_rho_m(k, rho);
  }
  // Notches (obstacle corners poking in) and spikes (narrow openings).
  const int features = 6 + static_cast<int>(rng.next() % 6);
  for (int f = 0; f < features; ++f) {
    const std::size_t at = rng.next() % n;
    const std::size_t width = 1 + rng.next() % 12;
    const float depth = rng.uniform(-0.8F, 0.8F);
    for (std::size_t i = 0; i < width; ++i) {
      const std::size_t k = (at + i) % n;
      out.set_rho_m(k, out.rho_m(k) + depth);
    }
  }
  for (std::size_t k = 0; k < n; ++k) {
    out.set_rho_m(k, std::clamp(out.rho_m(k), 0.6F, 3.0F));
  }
}

// A vertex of an n-ray fan at length rho [m], and the distance from a point to a segment, in
// double precision and sharing no code with the library (the shrink tests' oracles).
struct RefVertex {
  double x;
  double y;
};

inline RefVertex ref_vertex(std::size_t n, std::size_t k, double rho) {
  const double a =
      2.0 * 3.14159265358979323846 * static_cast<double>(k % n) / static_cast<double>(n);
  return {rho * std::cos(a), rho * std::sin(a)};
}

inline double ref_point_segment_m(RefVertex q, RefVertex a, RefVertex b) {
  const double ex = b.x - a.x;
  const double ey = b.y - a.y;
  const double len2 = ex * ex + ey * ey;
  double t = len2 > 0.0 ? ((q.x - a.x) * ex + (q.y - a.y) * ey) / len2 : 0.0;
  t = std::clamp(t, 0.0, 1.0);
  return std::hypot(q.x - (a.x + t * ex), q.y - (a.y + t * ey));
}

// The shrink tests' oracle, independent of the code under test: the smallest distance [m]
// from the segment [0, p] (robot frame) to the boundary of `region`, by brute force over
// every edge, with the vertices computed here from ρ_k and the angle 2πk/n (the shrink and
// mapping::sweep_clearance_m share their vertex and segment code; this shares none).
inline double reference_sweep_clearance_m(const mapping::StarPolygon& region, core::Point2 p) {
  using V = RefVertex;
  const auto point_segment = ref_point_segment_m;
  // Sign of the turn a -> b -> c (cross product of b - a and c - a).
  const auto orient = [](V a, V b, V c) {
    const double z = (b.x - a.x) * (c.y - a.y) - (b.y - a.y) * (c.x - a.x);
    return z > 0.0 ? 1 : (z < 0.0 ? -1 : 0);
  };
  const std::size_t n = region.vertex_count();
  const V o{0.0, 0.0};
  const V q{static_cast<double>(p.x_m), static_cast<double>(p.y_m)};
  const auto vertex = [&](std::size_t k) {
    return ref_vertex(n, k, static_cast<double>(region.rho_m(k % n)));
  };
  double best = std::numeric_limits<double>::infinity();
  for (std::size_t j = 0; j < n; ++j) {
    const V a = vertex(j);
    const V b = vertex(j + 1);
    // Crossing segments (proper crossings only: a touch gives distance 0 below anyway).
    if (orient(o, q, a) * orient(o, q, b) < 0 && orient(a, b, o) * orient(a, b, q) < 0) {
      return 0.0;
    }
    best = std::min({best, point_segment(o, a, b), point_segment(q, a, b), point_segment(a, o, q),
                     point_segment(b, o, q)});
  }
  return best;
}

// A wall segment in the world frame [m].
struct Wall {
  core::Point2 a;
  core::Point2 b;
};

// Distance along the ray from `origin` at angle θ [rad] to the first wall; infinity if none.
template <std::size_t N>
float cast_ray_m(const std::array<Wall, N>& walls, std::size_t wall_count, core::Point2 origin,
                 float theta_rad) {
  const double ux = std::cos(static_cast<double>(theta_rad));
  const double uy = std::sin(static_cast<double>(theta_rad));
  double best = std::numeric_limits<double>::infinity();
  for (std::size_t i = 0; i < wall_count; ++i) {
    const double ax = static_cast<double>(walls[i].a.x_m - origin.x_m);
    const double ay = static_cast<double>(walls[i].a.y_m - origin.y_m);
    const double ex = static_cast<double>(walls[i].b.x_m - walls[i].a.x_m);
    const double ey = static_cast<double>(walls[i].b.y_m - walls[i].a.y_m);
    const double den = ux * ey - uy * ex;
    if (den == 0.0) continue;
    const double t = (ax * ey - ay * ex) / den;
    const double s = (ax * uy - ay * ux) / den;
    if (t >= 0.0 && s >= 0.0 && s <= 1.0) best = std::min(best, t);
  }
  return static_cast<float>(best);
}

// Distance from p to the nearest wall [m].
template <std::size_t N>
float wall_clearance_m(const std::array<Wall, N>& walls, std::size_t wall_count, core::Point2 p) {
  float best = std::numeric_limits<float>::infinity();
  for (std::size_t i = 0; i < wall_count; ++i) {
    const float ex = walls[i].b.x_m - walls[i].a.x_m;
    const float ey = walls[i].b.y_m - walls[i].a.y_m;
    const float len2 = ex * ex + ey * ey;
    float t =
        len2 > 0.0F ? ((p.x_m - walls[i].a.x_m) * ex + (p.y_m - walls[i].a.y_m) * ey) / len2 : 0.0F;
    t = std::clamp(t, 0.0F, 1.0F);
    best = std::min(
        best, std::hypot(p.x_m - (walls[i].a.x_m + t * ex), p.y_m - (walls[i].a.y_m + t * ey)));
  }
  return best;
}

}  // namespace boticelli::test
