// Tests of the star polygon, its intersection and its exact shrink against brute force.
#include <algorithm>
#include <cmath>
#include <cstddef>
#include <limits>
#include <span>
#include <vector>

#include "algo/mapping/polygon_ops.h"
#include "algo/mapping/star_polygon.h"
#include "polygon_fixtures.h"

#include "CppUTest/TestHarness.h"

using boticelli::core::Point2;
using boticelli::mapping::StarPolygon;
using boticelli::test::Random;

namespace {

// A random point of the polygon: random direction, random fraction of the radius there.
Point2 random_point_inside(Random& rng, const StarPolygon& p) {
  const float a = rng.uniform(0.0F, 6.2831853F);
  const float d = std::sqrt(rng.uniform(0.0F, 1.0F)) * p.radius_at_m(a);
  return {d * std::cos(a), d * std::sin(a)};
}

// The swept disc's clearance by the tests' own oracle (polygon_fixtures.h), which shares no
// code with the shrink it checks.
float clearance_m(const StarPolygon& free, Point2 p) {
  return static_cast<float>(boticelli::test::reference_sweep_clearance_m(free, p));
}

using Vertex = boticelli::test::RefVertex;
using boticelli::test::ref_point_segment_m;
using boticelli::test::ref_vertex;

}  // namespace

TEST_GROUP(StarPolygon){};

TEST(StarPolygon, RadiusBetweenVerticesFollowsTheStraightEdge) {
  StarPolygon p(4);
  p.fill(1.0F);  // a square with corners on the axes
  DOUBLES_EQUAL(1.0, p.radius_at_m(0.0F), 1e-6);
  DOUBLES_EQUAL(std::sqrt(0.5), p.radius_at_m(0.78539816F), 1e-5);
  DOUBLES_EQUAL(2.0, p.area_m2(), 1e-5);
  CHECK_TRUE(p.contains({0.49F, 0.49F}));
  CHECK_FALSE(p.contains({0.51F, 0.51F}));
}

TEST(StarPolygon, IntersectionLiesInsideBothAndKeepsTheSmallerVertex) {
  Random rng(7);
  for (int trial = 0; trial < 20; ++trial) {
    StarPolygon a;
    StarPolygon b;
    boticelli::test::random_star_polygon(rng, a);
    boticelli::test::random_star_polygon(rng, b);
    StarPolygon c = a;
    CHECK_TRUE(boticelli::mapping::intersect_into(c, b));
    for (std::size_t k = 0; k < c.vertex_count(); ++k) {
      DOUBLES_EQUAL(std::fmin(a.rho_m(k), b.rho_m(k)), c.rho_m(k), 0.0);
    }
    for (int i = 0; i < 2000; ++i) {
      const Point2 q = random_point_inside(rng, c);
      // Inside both (a hair of float slack on the boundary).
      const float d = std::hypot(q.x_m, q.y_m);
      const float ang = std::atan2(q.y_m, q.x_m);
      CHECK_TRUE(d <= a.radius_at_m(ang) + 1e-5F);
      CHECK_TRUE(d <= b.radius_at_m(ang) + 1e-5F);
    }
  }
}

TEST(StarPolygon, IntersectionRefusesPolygonsOfDifferentResolution) {
  StarPolygon a(360);
  StarPolygon b(180);
  a.fill(1.0F);
  CHECK_FALSE(boticelli::mapping::intersect_into(a, b));
  DOUBLES_EQUAL(1.0, a.rho_m(0), 0.0);
}

TEST_GROUP(Shrink){};

TEST(Shrink, ACircleShrinksToTheCircleOfTheRadiusMinusTheRobotRadius) {
  StarPolygon circle(360);
  circle.fill(2.0F);
  StarPolygon out;
  CHECK_TRUE(boticelli::mapping::shrink_by_radius(circle, 0.25F, out));
  // The chords of a 360-gon lie at most ρ(1 − cos 0.5°) ≈ 0.08 mm inside the circle.
  for (std::size_t k = 0; k < out.vertex_count(); ++k) {
    DOUBLES_EQUAL(1.75, out.rho_m(k), 2e-4);
  }
}

TEST(Shrink, TheRobotDiscNeverLeavesTheFreeRegionOnAnyStraightPathToAPointInside) {
  Random rng(11);
  constexpr float kRadius = 0.2F;
  for (int trial = 0; trial < 5; ++trial) {
    StarPolygon free;
    boticelli::test::random_star_polygon(rng, free);
    StarPolygon nav;
    CHECK_TRUE(boticelli::mapping::shrink_by_radius(free, kRadius, nav));
    float worst = 1e9F;
    // Every vertex, every edge midpoint and random interior points: the swept disc's
    // clearance from the boundary of the unshrunk region (brute force over all edges).
    for (std::size_t k = 0; k < nav.vertex_count(); ++k) {
      const Point2 v = nav.vertex(k);
      const Point2 w = nav.vertex((k + 1) % nav.vertex_count());
      worst = std::fmin(worst, clearance_m(free, v));
      worst = std::fmin(worst, clearance_m(free, {0.5F * (v.x_m + w.x_m), 0.5F * (v.y_m + w.y_m)}));
    }
    for (int i = 0; i < 150; ++i) {
      worst = std::fmin(worst, clearance_m(free, random_point_inside(rng, nav)));
    }
    CHECK_TRUE(worst >= kRadius - 1e-5F);
  }
}

TEST(Shrink, StaysSafeForFewAndForTheMostVertices) {
  // The shrink's edge search works in angular gaps between a ray and an edge; with few
  // vertices its window wraps round the polygon, with the most it is narrow.
  Random rng(23);
  constexpr float kRadius = 0.2F;
  for (const std::size_t n : {std::size_t{3}, std::size_t{4}, std::size_t{5}, std::size_t{7},
                              std::size_t{12}, std::size_t{33}, std::size_t{720}}) {
    StarPolygon free;
    boticelli::test::random_star_polygon(rng, free, n);
    StarPolygon nav;
    if (!boticelli::mapping::shrink_by_radius(free, kRadius, nav)) {
      continue;  // the disc at the centre touches the boundary: nothing to check
    }
    float worst = 1e9F;
    for (std::size_t k = 0; k < nav.vertex_count(); ++k) {
      worst = std::fmin(worst, clearance_m(free, nav.vertex(k)));
    }
    for (int i = 0; i < 100; ++i) {
      worst = std::fmin(worst, clearance_m(free, random_point_inside(rng, nav)));
    }
    CHECK_TRUE(worst >= kRadius - 1e-5F);
  }
}

TEST(Shrink, IsTightAlongTheVertexRaysAndLosesAlmostNoArea) {
  // Exact, not merely safe: along almost every vertex ray the disc touches the boundary
  // 5 mm beyond the shrunk vertex. Where the free distance jumps between two rays the
  // straight edge would cut the disc's round path around the corner, so one vertex is
  // pulled in, the one that keeps the larger triangle; the area lost to that is compared
  // with the largest polygon of this form (each vertex at its exact limit on its ray, found
  // by bisection with the independent oracle). Measured on these eight rooms: 0.13-0.48%
  // lost, 0.31% in all; keeping the smaller triangle instead loses 0.30-1.15%, 0.74% in all.
  Random rng(5);
  constexpr float kRadius = 0.2F;
  auto clear = [](const StarPolygon& free, float a, float d) {
    return clearance_m(free, {d * std::cos(a), d * std::sin(a)}) >= kRadius;
  };
  double area = 0.0;
  double limit_area = 0.0;
  for (int trial = 0; trial < 8; ++trial) {
    StarPolygon free;
    boticelli::test::random_star_polygon(rng, free);
    StarPolygon nav;
    CHECK_TRUE(boticelli::mapping::shrink_by_radius(free, kRadius, nav));
    StarPolygon limit = nav;
    std::size_t tight = 0;
    for (std::size_t k = 0; k < nav.vertex_count(); ++k) {
      const float a = nav.angle_rad(k);
      if (!clear(free, a, nav.rho_m(k) + 0.005F)) {
        ++tight;
        continue;
      }
      float lo = nav.rho_m(k);
      float hi = free.rho_m(k);
      for (int it = 0; it < 24; ++it) {
        const float mid = 0.5F * (lo + hi);
        (clear(free, a, mid) ? lo : hi) = mid;
      }
      limit.set_rho_m(k, lo);
    }
    CHECK_TRUE(tight >= nav.vertex_count() * 94 / 100);
    CHECK_TRUE(nav.area_m2() >= 0.994F * limit.area_m2());
    area += static_cast<double>(nav.area_m2());
    limit_area += static_cast<double>(limit.area_m2());
  }
  CHECK_TRUE(area >= 0.995 * limit_area);
}

TEST(Shrink, ADiscAlreadyTouchingAnObstacleLeavesNowhereToGo) {
  StarPolygon free(360);
  free.fill(2.0F);
  free.set_rho_m(90, 0.15F);
  StarPolygon nav;
  CHECK_FALSE(boticelli::mapping::shrink_by_radius(free, 0.2F, nav));
  DOUBLES_EQUAL(0.0, nav.max_rho_m(), 0.0);
}

TEST(Shrink, StaysSafeAndTightWhenJaggedWallsComeCloseToTheRobot) {
  // Walls 0.3-1 m away and a 0.25 m robot: every disc and side reaches across dozens of
  // rays, most corners are reflex, and the shrink's candidate pruning is tested hardest.
  Random rng(77);
  constexpr float kRadius = 0.25F;
  int checked = 0;
  for (int trial = 0; trial < 12; ++trial) {
    StarPolygon free;
    boticelli::test::random_star_polygon(rng, free);
    for (std::size_t k = 0; k < free.vertex_count(); ++k) {
      free.set_rho_m(k, 0.3F + (free.rho_m(k) - 0.6F) * 0.3F);
    }
    StarPolygon nav;
    if (!boticelli::mapping::shrink_by_radius(free, kRadius, nav)) {
      continue;
    }
    ++checked;
    float worst = 1e9F;
    std::size_t tight = 0;
    for (std::size_t k = 0; k < nav.vertex_count(); ++k) {
      const Point2 v = nav.vertex(k);
      const Point2 w = nav.vertex((k + 1) % nav.vertex_count());
      worst = std::fmin(worst, clearance_m(free, v));
      worst = std::fmin(worst, clearance_m(free, {0.5F * (v.x_m + w.x_m), 0.5F * (v.y_m + w.y_m)}));
      const float a = nav.angle_rad(k);
      const float beyond = nav.rho_m(k) + 0.005F;
      if (clearance_m(free, {beyond * std::cos(a), beyond * std::sin(a)}) < kRadius) {
        ++tight;
      }
    }
    for (int i = 0; i < 300; ++i) {
      worst = std::fmin(worst, clearance_m(free, random_point_inside(rng, nav)));
    }
    CHECK_TRUE(worst >= kRadius - 1e-5F);
    CHECK_TRUE(tight >= nav.vertex_count() * 90 / 100);
  }
  CHECK_TRUE(checked >= 6);
}

TEST(Shrink, ARegularPolygonShrinksWithoutPullingInAnyVertex) {
  // Every corner of a circle's 360-gon turns left: no disc is met first and every chord
  // lies on an edge's inner side, so each vertex sits at the exact contact.
  StarPolygon circle(360);
  circle.fill(1.0F);
  StarPolygon out;
  CHECK_TRUE(boticelli::mapping::shrink_by_radius(circle, 0.3F, out));
  const double inner_side = 1.0 * std::cos(0.5 * 3.14159265358979 / 180.0) - 0.3;
  for (std::size_t k = 0; k < 360; ++k) {
    DOUBLES_EQUAL(inner_side / std::cos(0.5 * 3.14159265358979 / 180.0), out.rho_m(k), 1e-6);
  }
}

TEST(Shrink, AroundALoneCornerThePulledInChordsTouchTheCornersDiscAndDoNotCutIt) {
  // A circular room with one corner poking in (a reflex corner of the free region), on fans
  // coarse enough that every chord near the corner either clears its disc or is pulled in:
  // a pull-in turns the chord about its other vertex until it is tangent to the disc. So no
  // chord comes nearer the corner than R (not merely within the chord check's 1 um), and one
  // touches it (no vertex is pulled in farther than needed). The corner also sits at the seam.
  for (const std::size_t n : {std::size_t{36}, std::size_t{90}}) {
    for (const float corner : {1.0F, 1.5F}) {
      for (const float radius : {0.1F, 0.2F, 0.3F}) {
        for (const std::size_t m : {n / 4, n - 1, std::size_t{0}}) {
          StarPolygon free(n);
          free.fill(2.0F);
          free.set_rho_m(m, corner);
          StarPolygon nav;
          CHECK_TRUE(boticelli::mapping::shrink_by_radius(free, radius, nav));
          const Vertex c = ref_vertex(n, m, static_cast<double>(corner));
          double nearest = 1e9;
          for (std::size_t k = 0; k < n; ++k) {
            const Vertex a = ref_vertex(n, k, static_cast<double>(nav.rho_m(k)));
            const Vertex b = ref_vertex(n, k + 1, static_cast<double>(nav.rho_m((k + 1) % n)));
            nearest = std::fmin(nearest, ref_point_segment_m(c, a, b));
          }
          CHECK_TRUE(nearest >= static_cast<double>(radius) - 1e-8);
          CHECK_TRUE(nearest <= static_cast<double>(radius) + 1e-7);
        }
      }
    }
  }
}

namespace {

// The first length t >= 0 at which the ray t·u (|u| = 1) comes within r of the segment [a, b]:
// where it enters the segment's stadium, the union of the discs about its ends and the band
// along it (entered through one of its two long sides; its short sides lie inside the discs).
double ref_stadium_entry_m(Vertex u, Vertex a, Vertex b, double r) {
  double best = std::numeric_limits<double>::infinity();
  for (const Vertex c : {a, b}) {
    const double along = u.x * c.x + u.y * c.y;
    const double h2 = r * r - (c.x * c.x + c.y * c.y - along * along);
    if (h2 >= 0.0 && along - std::sqrt(h2) >= 0.0) best = std::fmin(best, along - std::sqrt(h2));
  }
  const double ex = b.x - a.x;
  const double ey = b.y - a.y;
  const double len = std::hypot(ex, ey);
  const double nx = ey / len;
  const double ny = -ex / len;
  const double facing = nx * u.x + ny * u.y;
  if (facing == 0.0) return best;
  for (const double side : {-r, r}) {
    const double t = (nx * a.x + ny * a.y + side) / facing;
    const double s = ((t * u.x - a.x) * ex + (t * u.y - a.y) * ey) / (len * len);
    if (t >= 0.0 && s >= 0.0 && s <= 1.0) best = std::fmin(best, t);
  }
  return best;
}

// Distance between the segments [a, b] and [c, d]: 0 if they cross, else the nearest of the four
// ends to the other segment.
double ref_segment_segment_m(Vertex a, Vertex b, Vertex c, Vertex d) {
  const auto turn = [](Vertex p, Vertex q, Vertex w) {
    return (q.x - p.x) * (w.y - p.y) - (q.y - p.y) * (w.x - p.x);
  };
  if (turn(a, b, c) * turn(a, b, d) < 0.0 && turn(c, d, a) * turn(c, d, b) < 0.0) return 0.0;
  return std::fmin(std::fmin(ref_point_segment_m(a, c, d), ref_point_segment_m(b, c, d)),
                   std::fmin(ref_point_segment_m(c, a, b), ref_point_segment_m(d, a, b)));
}

// What the shrink's documented rule gives, worked out by brute force and sharing no code with
// it. Step 1: each vertex at its ray's first contact with the radius-neighbourhood of the
// boundary, the nearest entry into any edge's stadium. Step 2, sectors k = 0, 1, ..., n − 1 in
// turn, from where the earlier sectors left their vertices: a chord nearer an edge than R (less
// the 1 um chords may touch) has one vertex pulled in, the other fixed, to the largest length at
// which the chord clears every edge by R (bisection: clearance only grows as a vertex moves in);
// the one of the two whose pull-in keeps the larger triangle (ρ_k·ρ_k+1). `margin`: the smallest
// relative difference between those two triangles over the pull-ins (how clearly the rule chose).
std::vector<double> ref_shrink(const StarPolygon& free, double r, double& margin) {
  const std::size_t n = free.vertex_count();
  std::vector<Vertex> v(n);
  for (std::size_t k = 0; k < n; ++k) v[k] = ref_vertex(n, k, static_cast<double>(free.rho_m(k)));
  std::vector<double> rho(n);
  for (std::size_t k = 0; k < n; ++k) {
    rho[k] = static_cast<double>(free.rho_m(k));
    for (std::size_t j = 0; j < n; ++j) {
      rho[k] =
          std::fmin(rho[k], ref_stadium_entry_m(ref_vertex(n, k, 1.0), v[j], v[(j + 1) % n], r));
    }
  }
  // The chord's clearance with vertex k at length a and vertex k + 1 at length b.
  const auto chord_clearance = [&](std::size_t k, double a, double b) {
    double d = std::numeric_limits<double>::infinity();
    for (std::size_t j = 0; j < n; ++j) {
      d = std::fmin(d, ref_segment_segment_m(ref_vertex(n, k, a), ref_vertex(n, k + 1, b), v[j],
                                             v[(j + 1) % n]));
    }
    return d;
  };
  margin = std::numeric_limits<double>::infinity();
  for (std::size_t k = 0; k < n; ++k) {
    const std::size_t k1 = (k + 1) % n;
    if (chord_clearance(k, rho[k], rho[k1]) >= r - 1e-6) continue;
    // Clear means at least R less 1 nm: a vertex at its ray's contact is R from that edge
    // only to rounding.
    const auto limit = [&](bool move_k) {
      double lo = 0.0;
      double hi = move_k ? rho[k] : rho[k1];
      for (int it = 0; it < 60; ++it) {
        const double mid = 0.5 * (lo + hi);
        const double d =
            move_k ? chord_clearance(k, mid, rho[k1]) : chord_clearance(k, rho[k], mid);
        (d >= r - 1e-9 ? lo : hi) = mid;
      }
      return lo;
    };
    const double pulled_k = limit(true);
    const double pulled_k1 = limit(false);
    margin =
        std::fmin(margin, std::fabs(pulled_k * rho[k1] - rho[k] * pulled_k1) / (rho[k] * rho[k1]));
    if (pulled_k * rho[k1] >= rho[k] * pulled_k1) {
      rho[k] = pulled_k;
    } else {
      rho[k1] = pulled_k1;
    }
  }
  return rho;
}

}  // namespace

TEST(Shrink, AroundALoneCornerOnACoarseFanEveryVertexIsWhereTheRayLimitsAndThePullInsPutIt) {
  // A circular room with one corner poking in, on fans of 12-36 rays, deep corners and wide
  // robots: the rays near the corner meet its disc or an edge's inner side, and the chords
  // beside it cut the disc, so one vertex of each is pulled in. Every vertex must be where the
  // brute-force reference (ref_shrink) puts it. The tolerance, 1 mm: the 1 um a chord may dip
  // into the neighbourhood moves a pulled-in vertex by up to 0.52 mm here (the reference run
  // with that allowance), as the chord touches the corner's disc at its end on the corner's
  // ray, where the depth grows with the square of the turn; measured, the shrink stays within
  // 0.12 mm. The rooms are ones where the two triangles differ by at least 1%, so the choice
  // between them is not up to rounding. Accepting an edge's inner side past its end (the line
  // beyond it lies short of the corner's disc) puts a vertex 2.5 to 26 cm off in all rooms but
  // the 12-ray one with the 1 m corner and 0.3 m robot.
  struct Room {
    std::size_t n;
    float corner;
    float radius;
  };
  for (const Room room :
       {Room{12, 0.6F, 0.35F}, Room{12, 0.8F, 0.45F}, Room{12, 1.0F, 0.3F}, Room{14, 0.8F, 0.4F},
        Room{16, 0.6F, 0.3F}, Room{16, 0.7F, 0.35F}, Room{16, 1.0F, 0.45F}, Room{18, 0.8F, 0.35F},
        Room{20, 0.6F, 0.2F}, Room{20, 0.9F, 0.3F}, Room{20, 1.2F, 0.45F}, Room{24, 0.8F, 0.25F},
        Room{24, 1.0F, 0.35F}, Room{30, 0.9F, 0.25F}, Room{36, 1.0F, 0.2F}}) {
    const std::size_t n = room.n;
    for (const std::size_t m : {n / 4, n - 1, std::size_t{0}}) {
      StarPolygon free(n);
      free.fill(2.0F);
      free.set_rho_m(m, room.corner);
      StarPolygon nav;
      CHECK_TRUE(boticelli::mapping::shrink_by_radius(free, room.radius, nav));
      double margin = 0.0;
      const std::vector<double> expected =
          ref_shrink(free, static_cast<double>(room.radius), margin);
      CHECK_TRUE(margin >= 0.01);
      for (std::size_t k = 0; k < n; ++k) {
        DOUBLES_EQUAL(expected[k], nav.rho_m(k), 1e-3);
      }
    }
  }
}

TEST_GROUP(ExcludePoints){};

TEST(ExcludePoints, APointIsLeftOutsideAndOnlyItsSectorMoves) {
  StarPolygon free(360);
  free.fill(2.0F);
  const Point2 q{1.2F * std::cos(0.3F), 1.2F * std::sin(0.3F)};  // between rays 17 and 18
  CHECK_TRUE(free.contains(q));
  boticelli::mapping::exclude_points(std::span<const Point2>(&q, 1), free);
  CHECK_FALSE(free.contains(q));
  const float d = std::hypot(q.x_m, q.y_m);
  CHECK_TRUE(free.rho_m(17) < d && free.rho_m(18) < d);
  DOUBLES_EQUAL(1.2, free.rho_m(17), 1e-5);
  DOUBLES_EQUAL(2.0, free.rho_m(16), 0.0);
  DOUBLES_EQUAL(2.0, free.rho_m(19), 0.0);
}

TEST(ExcludePoints, APointOnAVertexRayCutsBothSectorsBesideIt) {
  StarPolygon free(360);
  free.fill(2.0F);
  const float a = free.angle_rad(90);
  const Point2 q{1.0F * std::cos(a), 1.0F * std::sin(a)};
  boticelli::mapping::exclude_points(std::span<const Point2>(&q, 1), free);
  CHECK_FALSE(free.contains(q));
  // Whether rounding puts it just before or just after ray 90, no triangle holds it.
  for (const float da : {-1e-4F, 0.0F, 1e-4F}) {
    CHECK_FALSE(free.contains({1.0F * std::cos(a + da), 1.0F * std::sin(a + da)}));
  }
  const float d = std::hypot(q.x_m, q.y_m);
  CHECK_TRUE(free.rho_m(89) < d && free.rho_m(90) < d && free.rho_m(91) < d);
}

TEST(ExcludePoints, APointWithinRoundingOfARayCutsBothSectorsBesideItAndOneJustBeyondOnlyItsOwn) {
  // Within 1e-5 rad of a vertex ray (the rounding allowance of the point's bearing) a point
  // counts as lying in both sectors beside the ray, whichever side of the ray it is on: the
  // ray's vertex and both its neighbours are cut. At 1.5e-5 rad it lies in one sector, and only
  // that sector's two vertices move. On ray 100 and on ray 0, across the seam.
  constexpr std::size_t kN = 360;
  for (const std::size_t ray : {std::size_t{100}, std::size_t{0}}) {
    for (const double da : {-1.5e-5, -0.5e-5, 0.0, 0.5e-5, 1.5e-5}) {
      StarPolygon free(kN);
      free.fill(2.0F);
      const double a = 2.0 * 3.14159265358979323846 * static_cast<double>(ray) / kN + da;
      const Point2 q{static_cast<float>(1.2 * std::cos(a)), static_cast<float>(1.2 * std::sin(a))};
      boticelli::mapping::exclude_points(std::span<const Point2>(&q, 1), free);
      CHECK_FALSE(free.contains(q));
      const float d = std::hypot(q.x_m, q.y_m);
      // By offset from the ray: the vertices in [lo, hi] are cut, none outside it move (within
      // rounding, one more on either side may).
      const bool within = std::fabs(da) < 1e-5;
      const int lo = within || da < 0.0 ? -1 : 0;
      const int hi = within || da > 0.0 ? 1 : 0;
      for (int off = -5; off <= 5; ++off) {
        const float rho =
            free.rho_m(static_cast<std::size_t>(static_cast<int>(ray + kN) + off) % kN);
        if (off >= lo && off <= hi) {
          CHECK_TRUE(rho < d && rho > d - 1e-5F);
        } else if (!within || off < lo - 1 || off > hi + 1) {
          DOUBLES_EQUAL(2.0, rho, 0.0);
        }
      }
    }
  }
}

TEST(ExcludePoints, PointsAcrossTheSeamAndAtTheCentreAreHandled) {
  StarPolygon free(360);
  free.fill(2.0F);
  const Point2 pts[2] = {{1.5F, -1e-3F}, {0.0F, 0.0F}};
  boticelli::mapping::exclude_points(std::span<const Point2>(&pts[0], 1), free);
  CHECK_FALSE(free.contains(pts[0]));
  const float d = std::hypot(pts[0].x_m, pts[0].y_m);
  CHECK_TRUE(free.rho_m(359) < d && free.rho_m(0) < d);
  boticelli::mapping::exclude_points(std::span<const Point2>(&pts[1], 1), free);
  DOUBLES_EQUAL(0.0, free.max_rho_m(), 0.0);  // an obstacle at the centre closes it
}

TEST(ExcludePoints, ADiscAroundAPointCutsEveryRayThatMeetsItAtItsNearEdgeAndNoOther) {
  // A feature 1 m away with 0.1 m of surface around it: the rays within asin(0.1) of its
  // bearing (about 5.7 degrees at 1 degree per vertex) stop before they enter the disc, and
  // the free polygon holds no point of the disc, sampled densely.
  StarPolygon free(360);
  free.fill(2.0F);
  const float bearing = 0.5F;
  const Point2 q{std::cos(bearing), std::sin(bearing)};
  boticelli::mapping::exclude_discs(std::span<const Point2>(&q, 1), 0.1F, free);
  for (int i = 0; i <= 40; ++i) {
    for (int j = 0; j < 72; ++j) {
      const float r = 0.1F * static_cast<float>(i) / 40.0F;
      const float t = 6.2831853F * static_cast<float>(j) / 72.0F;
      CHECK_FALSE(free.contains({q.x_m + r * std::cos(t), q.y_m + r * std::sin(t)}));
    }
  }
  std::size_t cut = 0;
  for (std::size_t k = 0; k < free.vertex_count(); ++k) {
    const float off = free.angle_rad(k) - bearing;
    const float across = std::sin(off);
    if (std::fabs(off) < 0.5F && std::fabs(across) <= 0.1F) {
      ++cut;
      const float enter = std::cos(off) - std::sqrt(0.01F - across * across);
      CHECK_TRUE(free.rho_m(k) <= enter + 1e-5F);
      CHECK_TRUE(free.rho_m(k) >= 0.9F - 0.02F);  // no nearer than the sector's nearest point
    } else if (std::fabs(off) > 0.12F) {
      DOUBLES_EQUAL(2.0, free.rho_m(k), 0.0);  // rays that miss the disc keep their range
    }
  }
  CHECK_TRUE(cut >= 11);
}

TEST(ExcludePoints, ADiscCutsTheSectorHoldingItsCentreJustShortOfItsNearestPointAndNoFurther) {
  // Both vertices of the sector holding the disc's centre are cut to its nearest distance
  // d - r less one part in a million (clear of float rounding), not more: at 0.9 m that is
  // 0.9 um, and the float arithmetic is good to about 0.2 um.
  StarPolygon free(360);
  free.fill(2.0F);
  const Point2 q{std::cos(0.5F), std::sin(0.5F)};  // in the sector of rays 28 and 29
  boticelli::mapping::exclude_discs(std::span<const Point2>(&q, 1), 0.1F, free);
  const double d = std::hypot(static_cast<double>(q.x_m), static_cast<double>(q.y_m));
  const double cut = (d - static_cast<double>(0.1F)) * (1.0 - 1e-6);
  DOUBLES_EQUAL(cut, free.rho_m(28), 3e-7);
  DOUBLES_EQUAL(cut, free.rho_m(29), 3e-7);
}

TEST(ExcludePoints, ADiscAroundAPointNearerThanItsRadiusCutsOnlyThePoint) {
  // A stray reading inside the robot's own reach must not close the whole polygon.
  StarPolygon free(360);
  free.fill(2.0F);
  const Point2 q{0.05F, 0.02F};
  boticelli::mapping::exclude_discs(std::span<const Point2>(&q, 1), 0.1F, free);
  CHECK_FALSE(free.contains(q));
  std::size_t untouched = 0;
  for (std::size_t k = 0; k < free.vertex_count(); ++k) untouched += free.rho_m(k) == 2.0F;
  CHECK_TRUE(untouched >= 356);
}

TEST(Shrink, StraightWallsSeenHeadOnStopEveryRayIncludingThoseThroughTheJoints) {
  // A square room 1 m from the centre on each side: along a wall the vertices are
  // collinear, so neighbouring inner sides meet end to end, and the rays at 0°, 90°, ...
  // pass exactly through such joints. No ray may slip through.
  for (const std::size_t n : {std::size_t{360}, std::size_t{720}, std::size_t{8}}) {
    StarPolygon square(n);
    for (std::size_t k = 0; k < n; ++k) {
      const double a = 2.0 * 3.14159265358979 * static_cast<double>(k) / static_cast<double>(n);
      square.set_rho_m(
          k, static_cast<float>(1.0 / std::fmax(std::fabs(std::cos(a)), std::fabs(std::sin(a)))));
    }
    StarPolygon nav;
    CHECK_TRUE(boticelli::mapping::shrink_by_radius(square, 0.3F, nav));
    for (std::size_t k = 0; k < n; k += n / 4) {
      DOUBLES_EQUAL(0.7, nav.rho_m(k), 1e-5);
    }
    float worst = 1e9F;
    for (std::size_t k = 0; k < n; ++k) {
      worst = std::fmin(worst, clearance_m(square, nav.vertex(k)));
      CHECK_TRUE(nav.rho_m(k) <= square.rho_m(k) - 0.3F + 1e-5F);
    }
    CHECK_TRUE(worst >= 0.3F - 1e-5F);
  }
}

TEST(Shrink, TheLibrarysSweepClearanceAgreesWithTheIndependentReference) {
  // mapping::sweep_clearance_m (used by the planning tests) against the oracle, on points
  // inside, on and outside jagged polygons.
  Random rng(41);
  for (int trial = 0; trial < 6; ++trial) {
    StarPolygon free;
    boticelli::test::random_star_polygon(rng, free, trial % 2 == 0 ? 360 : 37);
    for (int i = 0; i < 300; ++i) {
      const float a = rng.uniform(0.0F, 6.2831853F);
      const float d = rng.uniform(0.0F, 1.2F) * free.radius_at_m(a);
      const Point2 q{d * std::cos(a), d * std::sin(a)};
      DOUBLES_EQUAL(boticelli::test::reference_sweep_clearance_m(free, q),
                    boticelli::mapping::sweep_clearance_m(free, q), 1e-5);
    }
  }
}

TEST(Shrink, OnStraightWallsEveryVertexLiesOnTheExactOffsetWithinAMicrometre) {
  // Square rooms (their corners on vertex rays, so every edge lies on a wall) at many
  // resolutions, sizes and robot radii: the shrunk room is the square moved in by R, so
  // each vertex is at (side − R) / max(|cos θ|, |sin θ|), computed here directly. A ray
  // through the joint of two collinear inner sides that slips between them in rounding is
  // only caught later by the chord check and ends micrometres short.
  for (const std::size_t n :
       {std::size_t{8}, std::size_t{16}, std::size_t{24}, std::size_t{36}, std::size_t{72},
        std::size_t{120}, std::size_t{240}, std::size_t{360}, std::size_t{720}}) {
    for (const double side : {0.9, 1.0, 1.7}) {
      StarPolygon square(n);
      for (std::size_t k = 0; k < n; ++k) {
        const double a = 2.0 * 3.14159265358979 * static_cast<double>(k) / static_cast<double>(n);
        square.set_rho_m(k, static_cast<float>(
                                side / std::fmax(std::fabs(std::cos(a)), std::fabs(std::sin(a)))));
      }
      for (const float radius : {0.1F, 0.2F, 0.25F, 0.3F, 0.45F}) {
        StarPolygon nav;
        CHECK_TRUE(boticelli::mapping::shrink_by_radius(square, radius, nav));
        for (std::size_t k = 0; k < n; ++k) {
          const double a = 2.0 * 3.14159265358979 * static_cast<double>(k) / static_cast<double>(n);
          const double exact = (side - static_cast<double>(radius)) /
                               std::fmax(std::fabs(std::cos(a)), std::fabs(std::sin(a)));
          DOUBLES_EQUAL(exact, nav.rho_m(k), 1e-6);
        }
      }
    }
  }
}

TEST_GROUP(OpenSpikes){};

TEST(OpenSpikes, WedgesNarrowerThanTheWindowGoAndWiderOpeningsStay) {
  StarPolygon p(360);
  p.fill(2.0F);
  p.set_rho_m(10, 3.0F);  // one ray through the wall
  p.set_rho_m(50, 3.0F);  // two rays
  p.set_rho_m(51, 2.8F);
  p.set_rho_m(358, 3.0F);  // across the seam
  p.set_rho_m(359, 3.0F);
  for (std::size_t k = 100; k < 110; ++k) p.set_rho_m(k, 3.0F);  // a doorway, 10 rays wide
  p.set_rho_m(200, 0.5F);  // a notch (a thin leg): opening never fills it
  StarPolygon before = p;
  boticelli::mapping::open_spikes(p, 2);  // window of 5 rays
  for (std::size_t k = 0; k < 360; ++k) {
    CHECK(p.rho_m(k) <= before.rho_m(k));
    const bool doorway = k >= 100 && k < 110;
    DOUBLES_EQUAL(doorway ? 3.0 : (k == 200 ? 0.5 : 2.0), p.rho_m(k), 1e-6);
  }
  // Half width 0 leaves the polygon as it was.
  StarPolygon q = before;
  boticelli::mapping::open_spikes(q, 0);
  for (std::size_t k = 0; k < 360; ++k) DOUBLES_EQUAL(before.rho_m(k), q.rho_m(k), 0.0);
}

// An opening exactly as wide as the window (2 × half width + 1 rays) stays whole, one ray
// narrower goes; a polygon of three to five rays is opened too.
TEST(OpenSpikes, AnOpeningExactlyAsWideAsTheWindowStaysAndOneRayNarrowerGoes) {
  StarPolygon p(360);
  p.fill(2.0F);
  for (std::size_t k = 100; k < 105; ++k) p.set_rho_m(k, 3.0F);  // 5 rays: the window
  for (std::size_t k = 200; k < 204; ++k) p.set_rho_m(k, 3.0F);  // 4 rays
  boticelli::mapping::open_spikes(p, 2);
  for (std::size_t k = 0; k < 360; ++k) {
    DOUBLES_EQUAL(k >= 100 && k < 105 ? 3.0 : 2.0, p.rho_m(k), 1e-6);
  }
  StarPolygon small(5);
  small.fill(1.0F);
  small.set_rho_m(2, 4.0F);  // a spike one ray wide
  boticelli::mapping::open_spikes(small, 1);
  for (std::size_t k = 0; k < 5; ++k) DOUBLES_EQUAL(1.0, small.rho_m(k), 1e-6);
}

TEST_GROUP(KeepPointsThatCut){};

namespace {
// The nearest point's distance per vertex ray, by nearest_vertex (infinity where none).
void nearest_per_ray(std::span<const Point2> points, const StarPolygon& shape, float* out) {
  for (std::size_t k = 0; k < shape.vertex_count(); ++k) out[k] = INFINITY;
  for (const Point2& q : points) {
    const std::size_t k = boticelli::mapping::nearest_vertex(shape, std::atan2(q.y_m, q.x_m));
    out[k] = std::fmin(out[k], std::hypot(q.x_m, q.y_m));
  }
}
}  // namespace

TEST(KeepPointsThatCut, TheKeptPointsCutThePolygonAndGiveEachRayItsNearestPointAsAllOfThemDo) {
  Random rng(31);
  for (const std::size_t n : {std::size_t{90}, std::size_t{360}}) {
    // Clusters of features on a few surfaces (many per sector), points on vertex rays and
    // across the seam, and a scatter.
    Point2 points[3000];
    std::size_t count = 0;
    StarPolygon shape(n);
    for (int c = 0; c < 12; ++c) {
      const float a = rng.uniform(0.0F, 6.2831853F);
      const float d = rng.uniform(0.5F, 3.0F);
      for (int k = 0; k < 200; ++k) {
        const float da = rng.uniform(-0.15F, 0.15F);
        const float dd = rng.uniform(-0.1F, 0.1F);
        points[count++] = {(d + dd) * std::cos(a + da), (d + dd) * std::sin(a + da)};
      }
    }
    for (std::size_t k = 0; k < 300; ++k) {
      const float a = shape.angle_rad(k % n);
      const float d = rng.uniform(0.3F, 3.0F);
      points[count++] = {d * std::cos(a), d * std::sin(a)};
    }
    for (int k = 0; k < 300; ++k) {
      const float d = rng.uniform(0.3F, 3.0F);
      points[count++] = {d, rng.uniform(-1e-3F, 1e-3F)};  // on ray 0, either side of the seam
    }
    while (count < 3000) {
      const float a = rng.uniform(0.0F, 6.2831853F);
      const float d = rng.uniform(0.3F, 3.0F);
      points[count++] = {d * std::cos(a), d * std::sin(a)};
    }
    Point2 kept[3000];
    std::copy(points, points + count, kept);
    const std::size_t k = boticelli::mapping::keep_points_that_cut(kept, shape.vertex_count());
    CHECK(k <= 2 * n + 1);
    CHECK(k < count / 2);
    StarPolygon all(n);
    StarPolygon some(n);
    all.fill(5.0F);
    some.fill(5.0F);
    boticelli::mapping::exclude_points(std::span<const Point2>(points, count), all);
    boticelli::mapping::exclude_points(std::span<const Point2>(kept, k), some);
    for (std::size_t v = 0; v < n; ++v) CHECK_EQUAL(all.rho_m(v), some.rho_m(v));
    float near_all[360];
    float near_some[360];
    nearest_per_ray(std::span<const Point2>(points, count), shape, near_all);
    nearest_per_ray(std::span<const Point2>(kept, k), shape, near_some);
    for (std::size_t v = 0; v < n; ++v) CHECK_EQUAL(near_all[v], near_some[v]);
    // The kept points are some of the points, in their order.
    std::size_t at = 0;
    for (std::size_t i = 0; i < k; ++i) {
      while (at < count && (points[at].x_m != kept[i].x_m || points[at].y_m != kept[i].y_m)) ++at;
      CHECK(at < count);
      ++at;
    }
  }
}

TEST(KeepPointsThatCut, APointAtTheCentreIsKeptAndStillClosesThePolygon) {
  StarPolygon shape(360);
  Point2 points[3] = {{1.0F, 0.5F}, {0.0F, 0.0F}, {1.1F, 0.55F}};
  const std::size_t k = boticelli::mapping::keep_points_that_cut(points, shape.vertex_count());
  LONGS_EQUAL(2, k);  // the third is behind the first in the same sector and on the same ray
  CHECK(points[1].x_m == 0.0F && points[1].y_m == 0.0F);
  StarPolygon free(360);
  free.fill(2.0F);
  boticelli::mapping::exclude_points(std::span<const Point2>(points, k), free);
  DOUBLES_EQUAL(0.0, free.max_rho_m(), 0.0);
}
