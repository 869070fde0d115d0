// Intersection and exact shrink of star-shaped polygons (§5.4.2), with a windowed edge search.
#include "algo/mapping/polygon_ops.h"

#include <algorithm>
#include <array>
#include <cmath>

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
  }
  [[nodiscard]] Vec2d unit_at(std::size_t k) const { return unit_[k]; }
  // Edge j joins vertex j and vertex j+1 (mod n); j may be any integer.
  [[nodiscard]] Vec2d edge_start(std::ptrdiff_t j) const { return v_[wrap(j)]; }
  [[nodiscard]] Vec2d edge_end(std::ptrdiff_t j) const { return v_[wrap(j + 1)]; }

 private:
  [[nodiscard]] std::size_t wrap(std::ptrdiff_t j) const {
    return static_cast<std::size_t>(((j % n_) + n_) % n_);
  }
  std::ptrdiff_t n_;
  std::array<Vec2d, kMaxPolygonVertices> unit_{};
  std::array<Vec2d, kMaxPolygonVertices> v_{};
};

double min_edge_distance_to_centre(const Vertices& v, std::size_t n) {
  double d = detail::kNoHit;
  for (std::size_t j = 0; j < n; ++j) {
    const auto jj = static_cast<std::ptrdiff_t>(j);
    d = std::min(d, detail::point_segment_distance({0.0, 0.0}, v.edge_start(jj), v.edge_end(jj)));
  }
  return d;
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
bool triangle_clear(const Vertices& p, Vec2d a, Vec2d b, std::ptrdiff_t first, std::ptrdiff_t last,
                    double radius) {
  const double min_x = std::min(a.x, b.x) - radius;
  const double max_x = std::max(a.x, b.x) + radius;
  const double min_y = std::min(a.y, b.y) - radius;
  const double max_y = std::max(a.y, b.y) + radius;
  for (std::ptrdiff_t j = first; j <= last; ++j) {
    const Vec2d e0 = p.edge_start(j);
    const Vec2d e1 = p.edge_end(j);
    if (std::max(e0.x, e1.x) < min_x || std::min(e0.x, e1.x) > max_x ||
        std::max(e0.y, e1.y) < min_y || std::min(e0.y, e1.y) > max_y) {
      continue;
    }
    if (detail::segment_segment_distance(a, b, e0, e1) < radius) {
      return false;
    }
  }
  return true;
}

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

  // 1. Each vertex ray: first contact with the radius-neighbourhood of the boundary (the
  //    union of the edges' stadiums). The robot's centre can go that far along the ray and
  //    no farther.
  for (std::size_t k = 0; k < n; ++k) {
    const Vec2d u = verts.unit_at(k);
    const auto kk = static_cast<std::ptrdiff_t>(k);
    double t = static_cast<double>(free_region.rho_m(k));
    for (std::ptrdiff_t j = kk - w - 1; j <= kk + w; ++j) {
      t = std::min(t, detail::ray_stadium_hit(u, verts.edge_start(j), verts.edge_end(j), radius));
    }
    out.set_rho_m(k, round_down(t));
  }

  // 2. Each sector: the triangle (0, v_k, v_{k+1}) swept by the disc must stay clear of the
  //    boundary; a straight edge between two exact vertices can cut the round corner the
  //    disc makes around a reflex vertex.
  //    Shrinking a vertex only shrinks the already checked neighbouring triangle.
  for (std::size_t k = 0; k < n; ++k) {
    const std::size_t k1 = (k + 1) % n;
    const auto kk = static_cast<std::ptrdiff_t>(k);
    const std::ptrdiff_t first = kk - w - 1;
    const std::ptrdiff_t last = kk + w + 1;
    const Vec2d uk = verts.unit_at(k);
    const Vec2d uk1 = verts.unit_at(k1);
    double rk = static_cast<double>(out.rho_m(k));
    double rk1 = static_cast<double>(out.rho_m(k1));
    if (triangle_clear(verts, rk * uk, rk1 * uk1, first, last, radius)) {
      continue;
    }
    // Largest clear length of one vertex with the other fixed (bisection; length 0 is
    // always clear since d_min > R, and clearance only grows as a vertex moves in).
    auto bisect = [&](bool move_k, double other) {
      double lo = 0.0;
      double hi = move_k ? rk : rk1;
      for (int it = 0; it < 40; ++it) {
        const double mid = 0.5 * (lo + hi);
        const bool clear = move_k
                               ? triangle_clear(verts, mid * uk, other * uk1, first, last, radius)
                               : triangle_clear(verts, other * uk, mid * uk1, first, last, radius);
        (clear ? lo : hi) = mid;
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
