// Intersection, exact robot-radius shrink and point exclusion of star-shaped polygons (§5.4.2).
#include "algo/mapping/polygon_ops.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <limits>

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
    // Unit vectors by rotation, anchored to cos/sin every 32 steps (rounding stays ~1e-15).
    const double step = core::kTwoPi<double> / static_cast<double>(p.vertex_count());
    const double cs = std::cos(step);
    const double sn = std::sin(step);
    for (std::size_t k = 0; k < p.vertex_count(); ++k) {
      if (k % 32 == 0) {
        unit_[k] = unit(p, k);
      } else {
        const Vec2d u = unit_[k - 1];
        unit_[k] = {u.x * cs - u.y * sn, u.x * sn + u.y * cs};
      }
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
  std::array<Vec2d, kMaxPolygonVertices> unit_;  // the first n_ set by the constructor
  std::array<Vec2d, kMaxPolygonVertices> v_;
  std::array<double, kMaxPolygonVertices> centre_distance_;
};

double min_edge_distance_to_centre(const Vertices& v, std::size_t n) {
  double d = detail::kNoHit;
  for (std::size_t j = 0; j < n; ++j) {
    d = std::min(d, v.centre_distance(static_cast<std::ptrdiff_t>(j)));
  }
  return d;
}

// Edges farther (in angle) than `window` from a ray or sector are at least `radius` away
// (the fallback search of a sector with too many failing edges to list):
// a boundary point at distance d ≥ d_min from the centre and angle δ ≥ asin(R/d_min) from
// a wedge is at least d·sin δ ≥ R from it (δ ≤ 90°), or at least d > R (δ > 90°).
std::ptrdiff_t edge_window(const StarPolygon& p, double radius, double d_min) {
  const double half_angle = std::asin(std::min(1.0, radius / d_min));
  const double step = core::kTwoPi<double> / static_cast<double>(p.vertex_count());
  const auto w = static_cast<std::ptrdiff_t>(std::ceil(half_angle / step)) + 1;
  return std::min(w, static_cast<std::ptrdiff_t>(p.vertex_count() / 2 + 1));
}

// Clearance of the triangle (0, a, b) from the listed edges is at least R.
// The sides 0–a and 0–b are clear already (each vertex is at most the first contact of its
// ray), and no edge reaches inside the triangle (the only edge in the sector lies beyond
// both vertices, the others outside the wedge), so only the chord a–b needs checking. An
// edge whose bounding box is more than R away from the chord's is skipped at once.
// `near` lists the edges that can come within R of the part of the wedge the chord lies in
// (the others are farther from it, hence from the chord).
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

// The largest t in [0, t_max] for which the segment [b, t·u] (|u| = 1) stays at least R
// from c, given that [b, 0] does: as t grows the segment turns about b, and it first
// touches the disc where it is tangent to it (the moving end itself meets the disc only
// beyond the ray's first contact, which t_max does not exceed). Each of the two tangents
// from b counts if it meets the ray at t ≥ 0 with its tangent point on the segment.
double tangent_limit(Vec2d b, Vec2d u, Vec2d c, double radius, double t_max) {
  const Vec2d d = c - b;
  const double l2 = detail::dot(d, d);
  const double r2 = radius * radius;
  if (!(l2 > r2)) {
    return 0.0;  // not expected: b is clear of every disc
  }
  const double l = std::sqrt(l2);
  const double sin_b = radius / l;
  const double cos_b = std::sqrt(l2 - r2) / l;
  double best = t_max;
  for (const double sign : {1.0, -1.0}) {
    // d turned by ±β (sin β = R / |d|): the tangent's direction, of length |d|; the
    // tangent point is b + cos β · dir.
    const Vec2d dir{d.x * cos_b - sign * d.y * sin_b, sign * d.x * sin_b + d.y * cos_b};
    const double den = detail::cross(u, dir);
    if (den == 0.0) continue;
    const double t = detail::cross(b, dir) / den;
    if (!(t >= 0.0 && t < best)) continue;
    const double s_end = detail::dot(t * u - b, dir) / l2;  // the segment's end, in |dir|
    if (cos_b <= s_end) best = t;
  }
  return best;
}

// How far below the largest clear length a pulled-in vertex may end (10 µm, the precision
// the tests check the swept disc to; tightness is checked at 5 mm).
constexpr double kBisectionTolerance_m = 1e-5;
// How far a chord may reach into the R-neighbourhood and still count as touching it
// (1 µm: rounding, not geometry; the stored ρ are floats, 0.24 µm apart at 3 m).
constexpr double kChordTolerance_m = 1e-6;
// How much longer than its edge each inner side counts, at each end, relative to R (step 1).
constexpr double kSideExtension = 1e-6;

// Stored ρ never rounds outwards.
float round_down(double v) {
  auto f = static_cast<float>(v);
  if (static_cast<double>(f) > v) {
    f = std::nextafter(f, 0.0F);
  }
  return std::max(f, 0.0F);
}

// The working state the steps of shrink_by_radius share, fixed once it is set up: the polygon
// and its vertices, the radius, and tables of the angular step.
struct ShrinkSetup {
  ShrinkSetup(const StarPolygon& region, const Vertices& vertices, double r, double d_min)
      : free_region(region),
        verts(vertices),
        n(region.vertex_count()),
        nn(static_cast<std::ptrdiff_t>(n)),
        radius(r),
        w(edge_window(region, r, d_min)),
        beyond(r * (1.0 + 1e-6)),
        chord_radius(r - kChordTolerance_m) {
    // sin and cos of whole multiples of the angular step below 90° (`quarter` of them).
    const double step = core::kTwoPi<double> / static_cast<double>(n);
    while (static_cast<double>(quarter) * step < 0.5 * core::kPi<double> - 1e-12) ++quarter;
    for (std::ptrdiff_t g = 0; g < quarter; ++g) {  // the unit vector of ray g
      sin_gap[static_cast<std::size_t>(g)] = verts.unit_at(static_cast<std::size_t>(g)).y;
      cos_gap[static_cast<std::size_t>(g)] = verts.unit_at(static_cast<std::size_t>(g)).x;
    }
  }
  // Indices here stay within n of [0, n): one correction wraps them.
  __attribute__((always_inline)) std::size_t wrap(std::ptrdiff_t k) const {
    if (k < 0) {
      k += nn;
    } else if (k >= nn) {
      k -= nn;
    }
    return static_cast<std::size_t>(k);
  }

  const StarPolygon& free_region;
  const Vertices& verts;
  std::size_t n;
  std::ptrdiff_t nn;
  double radius;
  std::ptrdiff_t w;  // edge_window(free_region, radius, d_min)
  double beyond;     // R and a hair: how far a disc or an edge counts as reaching
  // A chord on the R-neighbourhood touches it within rounding (on a circle every chord lies
  // on an edge's inner side): contacts up to kChordTolerance_m deep count as touching.
  double chord_radius;
  std::ptrdiff_t quarter = 0;
  std::array<double, kMaxPolygonVertices / 4 + 2> sin_gap{};
  std::array<double, kMaxPolygonVertices / 4 + 2> cos_gap{};
};

// What step 1 finds along the vertex rays, and about the edges and vertices, for step 2.
struct RayContacts {
  std::array<double, kMaxPolygonVertices> t;  // the first n set by find_ray_contacts
  // Per edge: the rays between which its inner side lies (unwrapped indices).
  std::array<std::int32_t, kMaxPolygonVertices> side_first;
  std::array<std::int32_t, kMaxPolygonVertices> side_last;
  // Per edge: the rays that cross both its inner sides (empty if first > last).
  std::array<std::int32_t, kMaxPolygonVertices> side_cross_first;
  std::array<std::int32_t, kMaxPolygonVertices> side_cross_last;
  // Per vertex: true if the boundary turns right there (a reflex corner of the free region).
  std::array<std::uint8_t, kMaxPolygonVertices> reflex;
};

//    (a) The inner side of edge j: the segment [v_j, v_j+1] moved R along the edge's
//        inward normal. Rays j and j+1 face its line (they pass through the edge's ends
//        on the outer side); walking away from them, the point where a ray meets the
//        line moves monotonically along it, so each walk stops once it has passed the
//        side's end or no longer faces the line.
void meet_inner_side(const ShrinkSetup& setup, std::size_t j, RayContacts& contacts) {
  const Vertices& verts = setup.verts;
  const double radius = setup.radius;
  const std::ptrdiff_t nn = setup.nn;
  std::array<double, kMaxPolygonVertices>& t = contacts.t;
  const auto jj = static_cast<std::ptrdiff_t>(j);
  const Vec2d a = verts.edge_start(jj);
  const Vec2d e = verts.edge_end(jj) - a;
  const double len2 = detail::dot(e, e);
  if (!(len2 > 0.0)) return;  // a point: its disc is all there is
  const double len = std::sqrt(len2);
  const Vec2d outward{e.y / len, -e.x / len};
  const double offset = detail::dot(outward, a) - radius;  // > 0: the line's distance − R
  const Vec2d p0 = a - radius * outward;
  // Returns false once the ray no longer faces the line; else its contact t and the
  // contact's place s along the side (0 at its start, 1 at its end), and the place s'
  // where it meets the side at distance R' = R − kChordTolerance_m from the edge (the
  // one step 2 checks chords against).
  const double inv_len2 = 1.0 / len2;
  const double p0_along = detail::dot(p0, e);
  const auto meet = [&](std::size_t k, double& tk, double& s, double& s_tol) {
    const Vec2d u = verts.unit_at(k);
    const double facing = detail::dot(outward, u);
    if (!(facing > 0.0)) return false;
    const double inv_facing = 1.0 / facing;  // the one division per ray
    const double ue = detail::dot(u, e);
    tk = offset * inv_facing;
    s = (tk * ue - p0_along) * inv_len2;
    s_tol = s + kChordTolerance_m * ue * inv_facing * inv_len2;
    return true;
  };
  // Each side counts kSideExtension R longer at both ends. Where the boundary runs
  // straight, two neighbouring sides meet end to end, and a ray through the joint could
  // otherwise slip between them in rounding; where it turns right by less than the
  // reflex threshold (so its disc is skipped), their ends are less than 2R sin(1e-6 / 2)
  // apart. The extension lies within R·1e-12 of the stadium, so it can only stop a
  // ray a little early, never late.
  // Each walk ends at the first ray beyond both sides (or no longer facing their line),
  // so both lie within the sectors between the two rays where the walks end.
  const double ext = kSideExtension * radius / len;
  // The rays that cross both sides (at R and at R') are [cross_first, cross_last].
  std::ptrdiff_t cross_first = jj + 1;
  std::ptrdiff_t cross_last = jj;
  std::ptrdiff_t g = 0;
  for (; g < nn; ++g) {  // rays j, j − 1, ...: s falls
    const std::size_t k = setup.wrap(jj - g);
    double tk = 0.0;
    double s = 0.0;
    double s_tol = 0.0;
    if (!meet(k, tk, s, s_tol) || (s < -ext && s_tol < -ext)) break;
    if (s >= -ext && s <= 1.0 + ext) {
      t[k] = std::min(t[k], tk);
      if (s_tol >= -ext && s_tol <= 1.0 + ext) {
        cross_first = jj - g;
        cross_last = std::max(cross_last, jj - g);
      }
    }
  }
  contacts.side_first[j] = static_cast<std::int32_t>(jj - g);
  for (g = 0; g < nn; ++g) {  // rays j + 1, j + 2, ...: s rises
    const std::size_t k = setup.wrap(jj + 1 + g);
    double tk = 0.0;
    double s = 0.0;
    double s_tol = 0.0;
    if (!meet(k, tk, s, s_tol) || (s > 1.0 + ext && s_tol > 1.0 + ext)) break;
    if (s >= -ext && s <= 1.0 + ext) {
      t[k] = std::min(t[k], tk);
      if (s_tol >= -ext && s_tol <= 1.0 + ext) {
        cross_first = std::min(cross_first, jj + 1 + g);
        cross_last = jj + 1 + g;
      }
    }
  }
  contacts.side_last[j] = static_cast<std::int32_t>(jj + 1 + g);
  contacts.side_cross_first[j] = static_cast<std::int32_t>(cross_first);
  contacts.side_cross_last[j] = static_cast<std::int32_t>(cross_last);
}

//    (b) The disc of radius R about vertex i, at distance ρ_i from the centre: the ray
//        g steps away meets it iff ρ_i sin(g·step) < R, at ρ_i cos(g·step) −
//        √(R² − ρ_i² sin²(g·step)) (g·step < 90°, and ρ_i > R).
//        Only the discs of reflex vertices can be met first. At a vertex where the
//        boundary turns left or goes straight, the free region's corner is convex and
//        holds the direction to the centre (the polygon is star-shaped). A point
//        p = v_i + R·w of the disc outside both neighbouring stadiums has w·e_i ≤ 0 and
//        w·e_i−1 ≥ 0: w lies in the corner's polar cone, so w·v_i ≥ 0. But a ray from the
//        centre enters the disc on its near half (w·v_i < 0), and any other point of the
//        disc is inside a neighbouring stadium, which the ray entered earlier through
//        another disc or side. A right turn by less than 1e-6 rad counts as straight:
//        its disc reaches past the two sides' lines by only R(1 − cos(δ/2)) < R·1e-12,
//        and the extended sides (a) close the gap between their ends.
void meet_reflex_discs(const ShrinkSetup& setup, RayContacts& contacts) {
  const Vertices& verts = setup.verts;
  const double radius = setup.radius;
  const auto& sin_gap = setup.sin_gap;
  const auto& cos_gap = setup.cos_gap;
  std::array<double, kMaxPolygonVertices>& t = contacts.t;
  std::array<std::uint8_t, kMaxPolygonVertices>& reflex = contacts.reflex;
  const double r2 = radius * radius;
  for (std::size_t i = 0; i < setup.n; ++i) {
    const auto ii = static_cast<std::ptrdiff_t>(i);
    const Vec2d e_in = verts.edge_end(ii - 1) - verts.edge_start(ii - 1);
    const Vec2d e_out = verts.edge_end(ii) - verts.edge_start(ii);
    reflex[i] = detail::cross(e_in, e_out) <
                        -1e-6 * std::sqrt(detail::dot(e_in, e_in) * detail::dot(e_out, e_out))
                    ? 1
                    : 0;
    if (reflex[i] == 0) continue;
    const double rho = static_cast<double>(setup.free_region.rho_m(i));
    for (std::ptrdiff_t g = 0; g < setup.quarter; ++g) {
      const double s = rho * sin_gap[static_cast<std::size_t>(g)];
      if (!(s < radius)) break;
      const double base = rho * cos_gap[static_cast<std::size_t>(g)];
      const double h2 = r2 - s * s;
      for (const std::ptrdiff_t k : {ii + g, ii - g}) {
        double& tk = t[setup.wrap(k)];
        const double lead = base - tk;  // the hit base − √h2 is below tk iff lead < √h2
        if (lead < 0.0 || lead * lead < h2) tk = std::min(tk, base - std::sqrt(h2));
      }
    }
  }
}

// 1. Each vertex ray: first contact with the radius-neighbourhood of the boundary, the
//    union of the edges' stadiums. The robot's centre can go that far along the ray and
//    no farther. A stadium is two discs and two straight sides; the discs are the
//    vertices' (shared by neighbouring edges), and of the sides only the inner one (the
//    edge moved R towards the centre) can be met first: the centre lies on the inner
//    side of every edge's line (the polygon is star-shaped about it), more than R away.
//    So each ray's contact is the nearest of the vertex discs and inner sides it meets,
//    and each disc or side is visited only for the rays that can meet it.
void find_ray_contacts(const ShrinkSetup& setup, RayContacts& contacts) {
  for (std::size_t k = 0; k < setup.n; ++k) {
    contacts.t[k] = static_cast<double>(setup.free_region.rho_m(k));
  }
  for (std::size_t j = 0; j < setup.n; ++j) {
    meet_inner_side(setup, j, contacts);
  }
  meet_reflex_discs(setup, contacts);
}

// Each vertex at its ray's first contact, rounded towards the centre.
void place_vertices_at_contacts(const ShrinkSetup& setup, const RayContacts& contacts,
                                StarPolygon& out) {
  for (std::size_t k = 0; k < setup.n; ++k) {
    out.set_rho_m(k, round_down(contacts.t[k]));
  }
}

// Per sector: the line its chord lies on (unit normal away from the centre, and offset).
struct ChordLines {
  std::array<Vec2d, kMaxPolygonVertices> normal;  // the first n set by find_chord_lines
  std::array<double, kMaxPolygonVertices> offset;
};

void find_chord_lines(const ShrinkSetup& setup, const StarPolygon& out, ChordLines& lines) {
  const Vertices& verts = setup.verts;
  const std::size_t n = setup.n;
  std::array<Vec2d, kMaxPolygonVertices>& chord_normal = lines.normal;
  std::array<double, kMaxPolygonVertices>& chord_offset = lines.offset;
  for (std::size_t k = 0; k < n; ++k) {
    const std::size_t k1 = k + 1 == n ? 0 : k + 1;
    const Vec2d a = static_cast<double>(out.rho_m(k)) * verts.unit_at(k);
    const Vec2d b = static_cast<double>(out.rho_m(k1)) * verts.unit_at(k1);
    const Vec2d c = b - a;
    const double len = detail::norm(c);
    chord_normal[k] = len > 0.0 ? Vec2d{c.y / len, -c.x / len} : Vec2d{0.0, 0.0};
    chord_offset[k] = detail::dot(chord_normal[k], a);
  }
}

// The edges each chord comes too close to. Every edge that can come within R of any
// chord inside the sector's triangle comes within R of its first chord: its stadium
// cannot lie inside the triangle (the only edge in the wedge lies beyond both vertices)
// and cannot cross the triangle's clear sides, so it crosses that chord. So these lists
// are all the pull-ins below need; a sector with more than fit is searched again.
constexpr std::size_t kMaxFailing = 6;
struct FailingEdges {
  std::array<std::array<std::int16_t, kMaxFailing>, kMaxPolygonVertices> failing;
  std::array<std::uint8_t, kMaxPolygonVertices> fails{};  // count, kMaxFailing + 1: too many
};

// Records edge jj as failing sector k's chord (once; a count past kMaxFailing: too many).
__attribute__((always_inline)) inline void record(const ShrinkSetup& setup, FailingEdges& f,
                                                  std::size_t k, std::ptrdiff_t jj) {
  auto& failing = f.failing;
  auto& fails = f.fails;
  const auto j = static_cast<std::int16_t>(setup.wrap(jj));
  for (std::size_t i = 0; i < std::min<std::size_t>(fails[k], kMaxFailing); ++i) {
    if (failing[k][i] == j) return;  // found twice
  }
  if (fails[k] < kMaxFailing) failing[k][fails[k]] = j;
  ++fails[k];
}

// Edge jj against the chord of sector kk: recorded if closer than R (less the tolerance).
// An edge whose two ends lie R or more beyond the chord's line is clear of it at once
// (every point of its stadium lies on the far side).
__attribute__((always_inline)) inline void try_sector(const ShrinkSetup& setup,
                                                      const StarPolygon& out,
                                                      const ChordLines& lines, FailingEdges& f,
                                                      std::ptrdiff_t kk, std::ptrdiff_t jj) {
  const Vertices& verts = setup.verts;
  const std::size_t n = setup.n;
  const double chord_radius = setup.chord_radius;
  const std::size_t k = setup.wrap(kk);
  if (f.fails[k] > kMaxFailing) return;
  const Vec2d e0 = verts.edge_start(jj);
  const Vec2d e1 = verts.edge_end(jj);
  const Vec2d cn = lines.normal[k];
  if (detail::dot(cn, e0) - lines.offset[k] >= chord_radius &&
      detail::dot(cn, e1) - lines.offset[k] >= chord_radius) {
    return;
  }
  const std::size_t k1 = k + 1 == n ? 0 : k + 1;
  const Vec2d a = static_cast<double>(out.rho_m(k)) * verts.unit_at(k);
  const Vec2d b = static_cast<double>(out.rho_m(k1)) * verts.unit_at(k1);
  if (detail::segments_closer_than(a, b, e0, e1, chord_radius)) record(setup, f, k, jj);
}

// Each edge against the sectors its inner sides (at R and at R') lie in, as step 1 (a)
// found them.
void try_edges_at_their_inner_sides(const ShrinkSetup& setup, const RayContacts& contacts,
                                    const StarPolygon& out, const ChordLines& lines,
                                    FailingEdges& f) {
  for (std::size_t j = 0; j < setup.n; ++j) {
    const auto jj = static_cast<std::ptrdiff_t>(j);
    const std::ptrdiff_t first = contacts.side_first[j];
    const std::ptrdiff_t last = contacts.side_last[j] - 1;
    // A sector whose two rays both cross the sides is skipped: on each ray the R' side
    // lies beyond the contact (the R side is one of the components the contact is the
    // nearest of, and the R' side lies farther out), so it joins two points beyond the
    // chord's ends, and the part of the wedge beyond the chord is convex.
    const std::ptrdiff_t skip_first = contacts.side_cross_first[j];
    const std::ptrdiff_t skip_last = contacts.side_cross_last[j] - 1;
    for (std::ptrdiff_t kk = first; kk <= last && kk - first < setup.nn; ++kk) {
      if (kk >= skip_first && kk <= skip_last) continue;
      try_sector(setup, out, lines, f, kk, jj);
    }
  }
}

// The two edges at each reflex vertex against every sector its disc reaches.
void try_edges_at_reflex_discs(const ShrinkSetup& setup, const RayContacts& contacts,
                               const StarPolygon& out, const ChordLines& lines, FailingEdges& f) {
  const Vertices& verts = setup.verts;
  const std::size_t n = setup.n;
  const std::ptrdiff_t nn = setup.nn;
  const std::ptrdiff_t quarter = setup.quarter;
  const auto& sin_gap = setup.sin_gap;
  const double beyond = setup.beyond;
  const double chord_radius = setup.chord_radius;
  const std::array<Vec2d, kMaxPolygonVertices>& chord_normal = lines.normal;
  const std::array<double, kMaxPolygonVertices>& chord_offset = lines.offset;
  for (std::size_t i = 0; i < n; ++i) {
    if (contacts.reflex[i] == 0) continue;
    const auto ii = static_cast<std::ptrdiff_t>(i);
    const double rho = static_cast<double>(setup.free_region.rho_m(i));
    std::ptrdiff_t reach = 0;
    while (reach + 1 < quarter && rho * sin_gap[static_cast<std::size_t>(reach + 1)] < beyond) {
      ++reach;
    }
    // The disc against the chords it reaches; a chord that comes within R' of the vertex
    // comes within R' of both its edges.
    const Vec2d vi = verts.edge_start(ii);
    for (std::ptrdiff_t kk = ii - 1 - reach; kk <= ii + reach && kk - (ii - 1 - reach) < nn; ++kk) {
      const std::size_t k = setup.wrap(kk);
      if (f.fails[k] > kMaxFailing) continue;
      if (detail::dot(chord_normal[k], vi) - chord_offset[k] >= chord_radius) continue;
      const std::size_t k1 = k + 1 == n ? 0 : k + 1;
      const Vec2d a = static_cast<double>(out.rho_m(k)) * verts.unit_at(k);
      const Vec2d b = static_cast<double>(out.rho_m(k1)) * verts.unit_at(k1);
      if (detail::point_segment_distance2(vi, a, b) < chord_radius * chord_radius) {
        record(setup, f, k, ii - 1);
        record(setup, f, k, ii);
      }
    }
  }
}

// 2. Each sector: the triangle (0, v_k, v_{k+1}) swept by the disc must stay clear of the
//    boundary; a straight edge between two exact vertices can cut the round corner the
//    disc makes around a reflex vertex. Its sides are clear (step 1), so only the chord
//    can come within R of an edge. First the candidate edges (below) are tried against
//    each chord; the sectors that fail are pulled in after that.
void find_edges_too_close_to_chords(const ShrinkSetup& setup, const RayContacts& contacts,
                                    const StarPolygon& out, FailingEdges& f) {
  ChordLines lines;
  find_chord_lines(setup, out, lines);
  //    Which edges to try against which chords. If a point x of the triangle lies within
  //    R' (R less the tolerance) of the boundary, then along the ray from the centre to x
  //    the first contact with the R'-neighbourhood lies in the triangle too (the triangle
  //    is star-shaped about the centre), below the chord, on an inner side or a reflex
  //    vertex's disc (step 1 (b): no other disc is ever met first). So the chord comes
  //    within R' of that side's edge, or of that vertex's edges (which end at its centre).
  //    The candidates are thus: each edge against the sectors its inner sides (at R and
  //    at R') lie in, as step 1 (a) found them, and the two edges at each reflex vertex
  //    against every sector its disc reaches (ρ_i sin(gap·step) < R, gap whole sectors
  //    away).
  try_edges_at_their_inner_sides(setup, contacts, out, lines, f);
  try_edges_at_reflex_discs(setup, contacts, out, lines, f);
}

// Edge indices, the first so many used (an index may lie outside [0, n): edge_start wraps it).
using EdgeList = std::array<std::int16_t, kMaxPolygonVertices + 8>;

// The edges sector k's triangle is checked against while it is pulled in (rk, rk1: its
// vertices' lengths): the failing edges step 2 listed, or every edge that can come near if
// they were too many to list. Returns how many.
std::size_t edges_near_sector(const ShrinkSetup& setup, const FailingEdges& f, std::size_t k,
                              double rk, double rk1, EdgeList& near) {
  const Vertices& verts = setup.verts;
  const auto& sin_gap = setup.sin_gap;
  const auto& cos_gap = setup.cos_gap;
  const double beyond = setup.beyond;
  const auto kk = static_cast<std::ptrdiff_t>(k);
  std::size_t near_count = 0;
  if (f.fails[k] <= kMaxFailing) {
    for (std::size_t i = 0; i < f.fails[k]; ++i) near[near_count++] = f.failing[k][i];
  } else {
    // Too many to list: every edge the bound lets through for this triangle (all its
    // chords lie in the wedge within m_k of the centre).
    const double mk = std::max(rk, rk1);
    const auto consider = [&](std::ptrdiff_t j, std::ptrdiff_t gap) {
      const double dj = verts.centre_distance(j);
      const double cg = cos_gap[static_cast<std::size_t>(gap)];
      const double sg = sin_gap[static_cast<std::size_t>(gap)];
      const double bound2 =
          dj * cg <= mk ? (dj * sg) * (dj * sg) : dj * dj + mk * mk - 2.0 * dj * mk * cg;
      if (bound2 < beyond * beyond) near[near_count++] = static_cast<std::int16_t>(j);
    };
    consider(kk, 0);
    consider(kk + 1, 0);
    consider(kk - 1, 0);
    for (std::ptrdiff_t gap = 1; gap <= setup.w && gap < setup.quarter && 2 * gap + 1 < setup.nn;
         ++gap) {
      consider(kk + 1 + gap, gap);
      consider(kk - 1 - gap, gap);
    }
  }
  return near_count;
}

// One sector's triangle (0, rk·uk, rk1·uk1) being pulled in: the edges it is checked
// against and the corners (vertex indices) whose discs its chord cuts.
struct SectorPull {
  const Vertices& verts;
  Vec2d uk;
  Vec2d uk1;
  double rk;
  double rk1;
  double radius;
  double chord_radius;
  const std::int16_t* near;
  std::size_t near_count;
  const std::int16_t* corners;
  std::size_t corner_count;

  // Whether the triangle is clear with one vertex (k if move_k, else k+1) at length len.
  [[nodiscard]] bool clear_at(bool move_k, double len) const {
    return move_k ? triangle_clear(verts, len * uk, rk1 * uk1, near, near_count, chord_radius)
                  : triangle_clear(verts, rk * uk, len * uk1, near, near_count, chord_radius);
  }
  // The tangent limit of one vertex, the other staying where it is.
  [[nodiscard]] double tangent(bool move_k) const {
    const Vec2d fixed = move_k ? rk1 * uk1 : rk * uk;
    const Vec2d moving = move_k ? uk : uk1;
    double hi = move_k ? rk : rk1;
    for (std::size_t i = 0; i < corner_count; ++i) {
      hi = tangent_limit(fixed, moving, verts.edge_start(corners[i]), radius, hi);
    }
    return hi;
  }
  // The largest length (to the tolerance) below hi at which the triangle is clear.
  [[nodiscard]] double bisect(bool move_k, double hi) const {
    double lo = 0.0;
    const double tolerance = std::max(hi * 0x1p-24, kBisectionTolerance_m);
    for (int it = 0; it < 60 && hi - lo > tolerance; ++it) {
      const double mid = 0.5 * (lo + hi);
      (clear_at(move_k, mid) ? lo : hi) = mid;
    }
    return lo;
  }
};

// The edges the present chord comes too close to (none if a neighbour's pull-in
// already cleared it). Returns how many.
std::size_t edges_close_to_chord(const SectorPull& p, EdgeList& close) {
  std::size_t close_count = 0;
  for (std::size_t i = 0; i < p.near_count; ++i) {
    if (!triangle_clear(p.verts, p.rk * p.uk, p.rk1 * p.uk1, &p.near[i], 1, p.chord_radius)) {
      close[close_count++] = p.near[i];
    }
  }
  return close_count;
}

// Vertex indices, the first so many used.
using CornerList = std::array<std::int16_t, 2 * (kMaxPolygonVertices + 8)>;

// The close edges' ends (vertex indices) that the chord itself comes within R' of:
// the discs whose round corners it cuts. Returns how many.
std::size_t corners_cut_by_chord(const ShrinkSetup& setup, const SectorPull& p,
                                 const EdgeList& close, std::size_t close_count,
                                 CornerList& corners) {
  std::size_t corner_count = 0;
  const Vec2d a = p.rk * p.uk;
  const Vec2d b = p.rk1 * p.uk1;
  for (std::size_t i = 0; i < close_count; ++i) {
    for (const std::ptrdiff_t v : {std::ptrdiff_t{close[i]}, std::ptrdiff_t{close[i]} + 1}) {
      const auto vi = static_cast<std::int16_t>(setup.wrap(v));
      bool seen = false;
      for (std::size_t q = 0; q < corner_count && !seen; ++q) seen = corners[q] == vi;
      if (!seen && detail::point_segment_distance2(setup.verts.edge_start(vi), a, b) <
                       p.chord_radius * p.chord_radius) {
        corners[corner_count++] = vi;
      }
    }
  }
  return corner_count;
}

// Largest clear length of one vertex with the other fixed. Length 0 is always clear
// (d_min > R), and clearance only grows as a vertex moves in. Mostly the chord cuts the
// round corner the disc makes about a reflex vertex: then the limit is where the chord,
// turning about the fixed vertex, becomes tangent to the disc of one of those corners
// (tangent_limit), and one check confirms it against all the sector's edges.
// Otherwise (a straight side, or several edges at once) a bisection below that limit
// finds it; it stops once the bracket is below kBisectionTolerance_m or the stored
// float's resolution (2⁻²⁴ relative). The length kept is always one checked clear, so
// the tolerance costs at most that much tightness, never safety.
// Pull in vertex k or vertex k+1, whichever keeps the larger triangle (area ∝ ρ_k ρ_k+1):
// the better tangent limit is checked first, and if it holds, the other (whose triangle
// is no larger even if it held) need not be. new_k, new_k1: the lengths kept.
void pull_in_one_vertex(const SectorPull& p, double& new_k, double& new_k1) {
  const double rk = p.rk;
  const double rk1 = p.rk1;
  const double tangent_k = p.tangent(true);
  const double tangent_k1 = p.tangent(false);
  const bool k_first = tangent_k * rk1 >= rk * tangent_k1;
  new_k = rk;
  new_k1 = rk1;
  if (p.clear_at(k_first, k_first ? tangent_k : tangent_k1)) {
    (k_first ? new_k : new_k1) = k_first ? tangent_k : tangent_k1;
  } else {
    const double other_tangent = k_first ? tangent_k1 : tangent_k;
    const double a = p.bisect(k_first, k_first ? tangent_k : tangent_k1);
    const double b =
        p.clear_at(!k_first, other_tangent) ? other_tangent : p.bisect(!k_first, other_tangent);
    const double cand_k = k_first ? a : b;
    const double cand_k1 = k_first ? b : a;
    if (cand_k * rk1 >= rk * cand_k1) {
      new_k = cand_k;
    } else {
      new_k1 = cand_k1;
    }
  }
}

// Sector k, whose chord failed in step 2: pulls in vertex k or k+1 until its triangle is
// clear, if a neighbour's pull-in has not cleared it already.
void pull_in_sector(const ShrinkSetup& setup, const FailingEdges& f, std::size_t k,
                    StarPolygon& out) {
  const std::size_t k1 = (k + 1) % setup.n;
  const double rk = static_cast<double>(out.rho_m(k));
  const double rk1 = static_cast<double>(out.rho_m(k1));
  EdgeList near;
  const std::size_t near_count = edges_near_sector(setup, f, k, rk, rk1, near);
  SectorPull p{.verts = setup.verts,
               .uk = setup.verts.unit_at(k),
               .uk1 = setup.verts.unit_at(k1),
               .rk = rk,
               .rk1 = rk1,
               .radius = setup.radius,
               .chord_radius = setup.chord_radius,
               .near = near.data(),
               .near_count = near_count,
               .corners = nullptr,
               .corner_count = 0};
  EdgeList close;
  const std::size_t close_count = edges_close_to_chord(p, close);
  if (close_count == 0) {
    return;
  }
  CornerList corners;
  p.corner_count = corners_cut_by_chord(setup, p, close, close_count, corners);
  p.corners = corners.data();
  double new_k = rk;
  double new_k1 = rk1;
  pull_in_one_vertex(p, new_k, new_k1);
  out.set_rho_m(k, round_down(new_k));
  out.set_rho_m(k1, round_down(new_k1));
}

// Every sector that failed step 2, in turn, pulled in from where the earlier pull-ins left its
// vertices. Pulling a vertex in only shrinks the neighbouring triangles, which stay clear.
void pull_in_failing_sectors(const ShrinkSetup& setup, const FailingEdges& f, StarPolygon& out) {
  for (std::size_t k = 0; k < setup.n; ++k) {
    if (f.fails[k] == 0) continue;
    pull_in_sector(setup, f, k, out);
  }
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
  // About 80 KB of stack (arrays sized for kMaxPolygonVertices); nothing on the heap.
  const Vertices verts(free_region);
  const double d_min = min_edge_distance_to_centre(verts, n);
  if (!(d_min > radius)) {
    return false;  // out is all zero: the disc at the centre already touches the boundary
  }
  const ShrinkSetup setup(free_region, verts, radius, d_min);
  RayContacts contacts;
  find_ray_contacts(setup, contacts);  // step 1
  place_vertices_at_contacts(setup, contacts, out);
  FailingEdges failing;
  find_edges_too_close_to_chords(setup, contacts, out, failing);  // step 2
  pull_in_failing_sectors(setup, failing, out);
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

namespace {
// The vertices exclude_points cuts for point q, and to what: the sector [θ_k, θ_k+1] holding
// it, both vertices cut to just below its distance d. A point on (or within rounding of)
// one of its rays also lies in the sector beyond that ray: then vertices k − 1 .. k + 2 are
// cut, which covers both sectors whichever of the two rays it is. at_centre: d is not > 0.
struct PointCut {
  bool at_centre = false;
  float cut = 0.0F;       // a micrometre inside d, clear of float rounding
  std::size_t first = 0;  // first vertex cut (mod n)
  std::size_t count = 0;  // 2 or 4
};

PointCut point_cut(core::Point2 q, std::size_t n, float step) {
  PointCut c;
  const float d = std::hypot(q.x_m, q.y_m);
  if (!(d > 0.0F)) {
    c.at_centre = true;
    return c;
  }
  float theta = std::atan2(q.y_m, q.x_m);
  if (theta < 0.0F) {
    theta += core::kTwoPi<float>;
  }
  auto k = static_cast<std::size_t>(theta / step);
  k = std::min(k, n - 1);
  c.cut = d * (1.0F - 1e-6F);
  const float offset = theta - static_cast<float>(k) * step;
  const bool near_ray = offset < 1e-5F || step - offset < 1e-5F;
  c.first = near_ray ? k + n - 1 : k;
  c.count = near_ray ? 4 : 2;
  return c;
}
}  // namespace

std::size_t nearest_vertex(const StarPolygon& p, float alpha_rad) {
  return nearest_vertex(p.vertex_count(), alpha_rad);
}

std::size_t nearest_vertex(std::size_t vertex_count, float alpha_rad) {
  const std::size_t n = StarPolygon::clamped_vertex_count(vertex_count);
  const float a = core::wrap_two_pi(alpha_rad);
  auto k = static_cast<std::size_t>(std::lround(a / StarPolygon::angle_step_rad(n)));
  return k % n;
}

void exclude_points(std::span<const core::Point2> points, StarPolygon& free) {
  const std::size_t n = free.vertex_count();
  const float step = free.angle_step_rad();
  for (const core::Point2& q : points) {
    const PointCut c = point_cut(q, n, step);
    if (c.at_centre) {
      free.fill(0.0F);  // an obstacle at the centre: nowhere is free
      return;
    }
    for (std::size_t i = 0; i < c.count; ++i) {
      const std::size_t v = (c.first + i) % n;
      free.set_rho_m(v, std::min(free.rho_m(v), c.cut));
    }
  }
}

std::size_t keep_points_that_cut(std::span<core::Point2> points, std::size_t vertex_count) {
  const std::size_t n = StarPolygon::clamped_vertex_count(vertex_count);
  const float step = StarPolygon::angle_step_rad(n);
  constexpr auto kNone = std::numeric_limits<std::uint32_t>::max();
  std::array<std::uint32_t, kMaxPolygonVertices> cutter;  // per vertex: the point cutting nearest
  std::array<float, kMaxPolygonVertices> cut;
  std::array<std::uint32_t, kMaxPolygonVertices> nearest;  // per vertex ray: the nearest point
  std::array<float, kMaxPolygonVertices> near;
  cutter.fill(kNone);
  nearest.fill(kNone);
  cut.fill(std::numeric_limits<float>::infinity());
  near.fill(std::numeric_limits<float>::infinity());
  std::uint32_t centre = kNone;
  for (std::size_t i = 0; i < points.size(); ++i) {
    const auto index = static_cast<std::uint32_t>(i);
    const PointCut c = point_cut(points[i], n, step);
    if (c.at_centre) {
      if (centre == kNone) centre = index;
      continue;
    }
    for (std::size_t j = 0; j < c.count; ++j) {
      const std::size_t v = (c.first + j) % n;
      if (c.cut < cut[v]) {
        cut[v] = c.cut;
        cutter[v] = index;
      }
    }
    const core::Point2 q = points[i];
    const std::size_t v = nearest_vertex(n, std::atan2(q.y_m, q.x_m));
    const float d = std::hypot(q.x_m, q.y_m);
    if (d < near[v]) {
      near[v] = d;
      nearest[v] = index;
    }
  }
  // The points some vertex names, in their own order.
  std::size_t kept = 0;
  const auto keep = [&](std::uint32_t index) { return index != kNone; };
  std::array<std::uint32_t, 2 * kMaxPolygonVertices + 1> keepers;
  std::size_t keeper_count = 0;
  for (std::size_t v = 0; v < n; ++v) {
    if (keep(cutter[v])) keepers[keeper_count++] = cutter[v];
    if (keep(nearest[v])) keepers[keeper_count++] = nearest[v];
  }
  if (keep(centre)) keepers[keeper_count++] = centre;
  std::sort(keepers.begin(), keepers.begin() + static_cast<std::ptrdiff_t>(keeper_count));
  for (std::size_t k = 0; k < keeper_count; ++k) {
    if (k > 0 && keepers[k] == keepers[k - 1]) continue;
    points[kept++] = points[keepers[k]];  // keepers ascend, so nothing is overwritten unread
  }
  return kept;
}

void exclude_discs(std::span<const core::Point2> points, float radius_m, StarPolygon& free) {
  exclude_points(points, free);
  const std::size_t n = free.vertex_count();
  if (n == 0 || !(radius_m > 0.0F)) return;
  const float step = free.angle_step_rad();
  const auto count = static_cast<std::ptrdiff_t>(n);
  for (const core::Point2& q : points) {
    const float d = std::hypot(q.x_m, q.y_m);
    if (!(d > radius_m)) continue;
    float theta = std::atan2(q.y_m, q.x_m);
    if (theta < 0.0F) theta += core::kTwoPi<float>;
    const float half = std::asin(radius_m / d);  // the disc's half-angle seen from the centre
    // Each sector [k, k + 1] the disc reaches into: its nearest point there is d - radius
    // where the sector holds the bearing, else where the sector's ray nearer the bearing
    // enters the disc. Both vertices are cut to that, so the sector's triangle (inside the
    // circle of its larger vertex) holds no point of the disc.
    const auto first = static_cast<std::ptrdiff_t>(std::floor((theta - half) / step));
    const auto last = static_cast<std::ptrdiff_t>(std::floor((theta + half) / step));
    for (std::ptrdiff_t i = first; i <= last; ++i) {
      const float a0 = static_cast<float>(i) * step;
      float nearest = d - radius_m;
      if (!(theta >= a0 && theta <= a0 + step)) {
        const float off = theta < a0 ? a0 - theta : a0 + step - theta;
        const float across = d * std::sin(off);
        const float inside = radius_m * radius_m - across * across;
        if (!(inside >= 0.0F)) continue;  // rounding at the disc's tangent
        nearest = d * std::cos(off) - std::sqrt(inside);
      }
      const float cut = std::max(nearest, 0.0F) * (1.0F - 1e-6F);
      for (const std::ptrdiff_t j : {i, i + 1}) {
        const auto v = static_cast<std::size_t>(((j % count) + count) % count);
        free.set_rho_m(v, std::min(free.rho_m(v), cut));
      }
    }
  }
}

void open_spikes(StarPolygon& free, std::size_t half_width) {
  const std::size_t n = free.vertex_count();
  if (half_width == 0 || n < 3) {
    return;
  }
  const std::size_t h = std::min(half_width, (n - 1) / 2);
  std::array<float, kMaxPolygonVertices> eroded{};
  for (std::size_t k = 0; k < n; ++k) {
    float m = free.rho_m(k);
    for (std::size_t d = 1; d <= h; ++d) {
      m = std::min({m, free.rho_m((k + d) % n), free.rho_m((k + n - d) % n)});
    }
    eroded[k] = m;
  }
  for (std::size_t k = 0; k < n; ++k) {
    float m = eroded[k];
    for (std::size_t d = 1; d <= h; ++d) {
      m = std::max({m, eroded[(k + d) % n], eroded[(k + n - d) % n]});
    }
    free.set_rho_m(k, m);
  }
}

}  // namespace boticelli::mapping
