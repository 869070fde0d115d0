// Intersection and exact shrink of star-shaped polygons (§5.4.2), with a windowed edge search.
#include "algo/mapping/polygon_ops.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>

#include "segment_geometry.h"

namespace boticelli::mapping {
namespace {

using detail::Vec2d;

Vec2d unit(const StarPolygon& p, std::size_t k) {
  const double a =
      static_cast<double>(k) * core::kTwoPi<double> / static_cast<double>(p.vertex_count());
  return {std::cos(a), std::sin(a)};
}

// The polygon's vertices in double precision, computed once per operation.
class Vertices {
 public:
  explicit Vertices(const StarPolygon& p) : n_(static_cast<std::ptrdiff_t>(p.vertex_count())) {
    for (std::size_t k = 0; k < p.vertex_count(); ++k) {
      unit_[k] = unit(p, k);
      v_[k] = static_cast<double>(p.rho_m(k)) * unit_[k];
    }
    for (std::size_t j = 0; j < p.vertex_count(); ++j) {
      const auto jj = static_cast<std::ptrdiff_t>(j);
      centre_distance_[j] =
          detail::point_segment_distance({0.0, 0.0}, edge_start(jj), edge_end(jj));
    }
  }
  [[nodiscard]] Vec2d unit_at(std::size_t k) const { return unit_[k]; }
  // Edge j joins vertex j and vertex j+1 (mod n); j may be any integer.
  [[nodiscard]] Vec2d edge_start(std::ptrdiff_t j) const { return v_[wrap(j)]; }
  [[nodiscard]] Vec2d edge_end(std::ptrdiff_t j) const { return v_[wrap(j + 1)]; }
  // Distance of edge j from the centre: every point of the edge is at least this far out.
  [[nodiscard]] double centre_distance(std::ptrdiff_t j) const { return centre_distance_[wrap(j)]; }

 private:
  // Callers stay within a window of about n around [0, n): no division needed.
  [[nodiscard]] std::size_t wrap(std::ptrdiff_t j) const {
    while (j < 0) j += n_;
    while (j >= n_) j -= n_;
    return static_cast<std::size_t>(j);
  }
  std::ptrdiff_t n_;
  std::array<Vec2d, kMaxPolygonVertices> unit_{};
  std::array<Vec2d, kMaxPolygonVertices> v_{};
  std::array<double, kMaxPolygonVertices> centre_distance_{};
};

double min_edge_distance_to_centre(const Vertices& v, std::size_t n) {
  double d = detail::kNoHit;
  for (std::size_t j = 0; j < n; ++j) {
    d = std::min(d, v.centre_distance(static_cast<std::ptrdiff_t>(j)));
  }
  return d;
}

// Per-edge form of the window below. Edge j lies in the sector between the rays j and j+1
// (the polygon is star-shaped about the centre), and all its points are at least
// centre_distance(j) = d_j from the centre. A point at distance d and angle δ ≥ 0 from a ray
// (or from a wedge of rays) is at least d·sin δ from it if δ ≤ 90°, else at least d. So edge
// j cannot come within R of a ray or wedge that is `gap` whole sectors away from it if
// d_j·sin(gap·step) ≥ R (or gap·step ≥ 90°, since d_j ≥ d_min > R). `sin_gap[g]` holds
// sin(g·step); the test keeps a relative slack so rounding never skips an edge that counts.
bool edge_out_of_reach(const Vertices& v, std::ptrdiff_t j, std::ptrdiff_t gap,
                       const std::array<double, kMaxPolygonVertices / 4 + 2>& sin_gap,
                       std::ptrdiff_t quarter, double radius) {
  if (gap <= 0) return false;
  if (gap >= quarter) return true;
  return v.centre_distance(j) * sin_gap[static_cast<std::size_t>(gap)] > radius * (1.0 + 1e-6);
}

// (j − k) mod n, in [0, n).
std::ptrdiff_t forward_offset(std::ptrdiff_t j, std::ptrdiff_t k, std::ptrdiff_t n) {
  std::ptrdiff_t f = j - k;
  while (f < 0) f += n;
  while (f >= n) f -= n;
  return f;
}

// Edges farther (in angle) than `window` from a ray or sector are at least `radius` away:
// a boundary point at distance d ≥ d_min from the centre and angle δ ≥ asin(R/d_min) from
// a wedge is at least d·sin δ ≥ R from it (δ ≤ 90°), or at least d > R (δ > 90°).
std::ptrdiff_t edge_window(const StarPolygon& p, double radius, double d_min) {
  const double half_angle = std::asin(std::min(1.0, radius / d_min));
  const double step = core::kTwoPi<double> / static_cast<double>(p.vertex_count());
  const auto w = static_cast<std::ptrdiff_t>(std::ceil(half_angle / step)) + 1;
  return std::min(w, static_cast<std::ptrdiff_t>(p.vertex_count() / 2 + 1));
}

// Clearance of the triangle (0, a, b) from the edges j ∈ [first, last] is at least R.
// The sides 0–a and 0–b are clear already (each vertex is at most the first contact of its
// ray), and no edge reaches inside the triangle (the only edge in the sector lies beyond
// both vertices, the others outside the wedge), so only the chord a–b needs checking. An
// edge whose bounding box is more than R away from the chord's is skipped at once.
// `near` lists the edges of the window that edge_out_of_reach does not rule out for this
// sector (the others are more than R from the whole wedge, hence from the chord).
bool triangle_clear(const Vertices& p, Vec2d a, Vec2d b, const std::int16_t* near,
                    std::size_t near_count, double radius) {
  const double min_x = std::min(a.x, b.x) - radius;
  const double max_x = std::max(a.x, b.x) + radius;
  const double min_y = std::min(a.y, b.y) - radius;
  const double max_y = std::max(a.y, b.y) + radius;
  for (std::size_t i = 0; i < near_count; ++i) {
    const std::ptrdiff_t j = near[i];  // may lie outside [0, n): edge_start wraps it
    const Vec2d e0 = p.edge_start(j);
    const Vec2d e1 = p.edge_end(j);
    if (std::max(e0.x, e1.x) < min_x || std::min(e0.x, e1.x) > max_x ||
        std::max(e0.y, e1.y) < min_y || std::min(e0.y, e1.y) > max_y) {
      continue;
    }
    if (detail::segments_closer_than(a, b, e0, e1, radius)) {
      return false;
    }
  }
  return true;
}

// How far below the largest clear length a pulled-in vertex may end (10 µm, the precision
// the tests check the swept disc to; tightness is checked at 5 mm).
constexpr double kBisectionTolerance_m = 1e-5;

// Stored ρ never rounds outwards.
float round_down(double v) {
  auto f = static_cast<float>(v);
  if (static_cast<double>(f) > v) {
    f = std::nextafter(f, 0.0F);
  }
  return std::max(f, 0.0F);
}

}  // namespace

bool intersect_into(StarPolygon& into, const StarPolygon& other) {
  if (into.vertex_count() != other.vertex_count()) {
    return false;
  }
  for (std::size_t k = 0; k < into.vertex_count(); ++k) {
    into.set_rho_m(k, std::min(into.rho_m(k), other.rho_m(k)));
  }
  return true;
}

bool shrink_by_radius(const StarPolygon& free_region, float radius_m, StarPolygon& out) {
  const std::size_t n = free_region.vertex_count();
  out.set_vertex_count(n);
  // A tiny slack keeps the float-stored result on the safe side of the double computation.
  const double radius = static_cast<double>(radius_m) * (1.0 + 1e-9) + 1e-9;
  // About 23 KB of stack for the largest polygon; nothing on the heap.
  const Vertices verts(free_region);
  const double d_min = min_edge_distance_to_centre(verts, n);
  if (!(d_min > radius)) {
    return false;  // out is all zero: the disc at the centre already touches the boundary
  }
  const std::ptrdiff_t w = edge_window(free_region, radius, d_min);
  const auto nn = static_cast<std::ptrdiff_t>(n);
  // sin of whole multiples of the angular step, up to 90° (the per-edge reach test).
  const double step = core::kTwoPi<double> / static_cast<double>(n);
  const auto quarter = static_cast<std::ptrdiff_t>(std::ceil(core::kTwoPi<double> / 4.0 / step));
  std::array<double, kMaxPolygonVertices / 4 + 2> sin_gap{};
  std::array<double, kMaxPolygonVertices / 4 + 2> cos_gap{};
  for (std::ptrdiff_t g = 0; g < quarter && static_cast<std::size_t>(g) < sin_gap.size(); ++g) {
    sin_gap[static_cast<std::size_t>(g)] = std::sin(static_cast<double>(g) * step);
    cos_gap[static_cast<std::size_t>(g)] = std::cos(static_cast<double>(g) * step);
  }

  // 1. Each vertex ray: first contact with the radius-neighbourhood of the boundary (the
  //    union of the edges' stadiums). The robot's centre can go that far along the ray and
  //    no farther.
  for (std::size_t k = 0; k < n; ++k) {
    const Vec2d u = verts.unit_at(k);
    const auto kk = static_cast<std::ptrdiff_t>(k);
    double t = static_cast<double>(free_region.rho_m(k));
    // Nearest edges first (gap g: edges k + g and k − 1 − g), so that t is small early and
    // the lower bound below rules out most of the others.
    for (std::ptrdiff_t g = 0; g <= w; ++g) {
      // The angular gap in whole steps, the shorter way round (small n).
      const std::ptrdiff_t gap = std::max<std::ptrdiff_t>(0, std::min(g, nn - g - 1));
      for (const std::ptrdiff_t j : {kk + g, kk - 1 - g}) {
        if (edge_out_of_reach(verts, j, gap, sin_gap, quarter, radius)) continue;
        // A point q of edge j lies at angle θ ∈ [gap·step, (gap+1)·step] from the ray and
        // |q| ≥ d_j. The ray is within R of q only for t ≥ |q| cos θ − √(R² − |q|² sin² θ),
        // which is at least d_j cos((gap+1)·step) − √(R² − d_j² sin²(gap·step)) (θ < 90°).
        // An edge whose bound is beyond the contact found so far cannot lower it.
        if (gap + 1 < quarter) {
          const double dj = verts.centre_distance(j);
          const double s = dj * sin_gap[static_cast<std::size_t>(gap)];
          const double lower = dj * cos_gap[static_cast<std::size_t>(gap + 1)] -
                               std::sqrt(std::max(0.0, radius * radius - s * s));
          if (lower > t + 1e-9) continue;
        }
        t = std::min(t, detail::ray_stadium_hit(u, verts.edge_start(j), verts.edge_end(j), radius));
      }
    }
    out.set_rho_m(k, round_down(t));
  }

  // 2. Each sector: the triangle (0, v_k, v_{k+1}) swept by the disc must stay clear of the
  //    boundary; a straight edge between two exact vertices can cut the round corner the
  //    disc makes around a reflex vertex.
  //    Shrinking a vertex only shrinks the already checked neighbouring triangle.
  std::array<std::int16_t, kMaxPolygonVertices + 8> near{};
  for (std::size_t k = 0; k < n; ++k) {
    const std::size_t k1 = (k + 1) % n;
    const auto kk = static_cast<std::ptrdiff_t>(k);
    const std::ptrdiff_t first = kk - w - 1;
    const std::ptrdiff_t last = kk + w + 1;
    const Vec2d uk = verts.unit_at(k);
    const Vec2d uk1 = verts.unit_at(k1);
    double rk = static_cast<double>(out.rho_m(k));
    double rk1 = static_cast<double>(out.rho_m(k1));
    // The window's edges that can come within R of the wedge between rays k and k+1.
    std::size_t near_count = 0;
    for (std::ptrdiff_t j = first; j <= last; ++j) {
      const std::ptrdiff_t f = forward_offset(j, kk, nn);
      const std::ptrdiff_t gap = f == 0 ? 0 : std::min(f - 1, nn - f - 1);
      if (!edge_out_of_reach(verts, j, gap, sin_gap, quarter, radius)) {
        near[near_count++] = static_cast<std::int16_t>(j);
      }
    }
    if (triangle_clear(verts, rk * uk, rk1 * uk1, near.data(), near_count, radius)) {
      continue;
    }
    // Every chord tried below lies in the triangle (0, v_k, v_k+1): only the edges that
    // come within R of that triangle can fail it.
    {
      const Vec2d a = rk * uk;
      const Vec2d b = rk1 * uk1;
      std::size_t kept = 0;
      for (std::size_t i = 0; i < near_count; ++i) {
        const std::ptrdiff_t j = near[i];
        if (detail::triangle_segment_distance({0.0, 0.0}, a, b, verts.edge_start(j),
                                              verts.edge_end(j)) < radius * (1.0 + 1e-6)) {
          near[kept++] = near[i];
        }
      }
      near_count = kept;
    }
    // Largest clear length of one vertex with the other fixed (bisection; length 0 is
    // always clear since d_min > R, and clearance only grows as a vertex moves in).
    // Most failures are the exact contact itself: both vertices sit on the R-neighbourhood
    // and the chord touches it within rounding. So the bracket [hi (1 − 2⁻²⁰), hi] is tried
    // first. The bisection stops once the bracket is below kBisectionTolerance_m or the
    // stored float's resolution (2⁻²⁴ relative); `lo` is always a length checked clear, so
    // the tolerance costs at most that much tightness, never safety.
    auto bisect = [&](bool move_k, double other) {
      const auto clear_at = [&](double len) {
        return move_k
                   ? triangle_clear(verts, len * uk, other * uk1, near.data(), near_count, radius)
                   : triangle_clear(verts, other * uk, len * uk1, near.data(), near_count, radius);
      };
      double lo = 0.0;
      double hi = move_k ? rk : rk1;
      const double tolerance = std::max(hi * 0x1p-24, kBisectionTolerance_m);
      const double near_hi = hi * (1.0 - 0x1p-20);
      if (clear_at(near_hi)) {
        lo = near_hi;
      }
      for (int it = 0; it < 60 && hi - lo > tolerance; ++it) {
        const double mid = 0.5 * (lo + hi);
        (clear_at(mid) ? lo : hi) = mid;
      }
      return lo;
    };
    // Pull in vertex k or vertex k+1, whichever keeps the larger triangle (area ∝ ρ_k ρ_k+1).
    const double new_k = bisect(true, rk1);
    const double new_k1 = bisect(false, rk);
    if (new_k * rk1 >= rk * new_k1) {
      rk = new_k;
    } else {
      rk1 = new_k1;
    }
    out.set_rho_m(k, round_down(rk));
    out.set_rho_m(k1, round_down(rk1));
  }
  return true;
}

float boundary_clearance_m(const StarPolygon& region) {
  const Vertices verts(region);
  return static_cast<float>(min_edge_distance_to_centre(verts, region.vertex_count()));
}

float sweep_clearance_m(const StarPolygon& region, core::Point2 p) {
  const Vec2d q{static_cast<double>(p.x_m), static_cast<double>(p.y_m)};
  const Vertices verts(region);
  double d = detail::kNoHit;
  for (std::size_t j = 0; j < region.vertex_count(); ++j) {
    const auto jj = static_cast<std::ptrdiff_t>(j);
    d = std::min(d, detail::segment_segment_distance({0.0, 0.0}, q, verts.edge_start(jj),
                                                     verts.edge_end(jj)));
  }
  return static_cast<float>(d);
}

}  // namespace boticelli::mapping
