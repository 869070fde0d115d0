// Tests of the exploration points where the belief and plausibility polygons disagree (§7.2.3).
#include <cmath>
#include <cstddef>

#include "algo/core/angles.h"
#include "algo/core/fixed_vector.h"
#include "algo/mapping/map_points.h"
#include "algo/mapping/star_polygon.h"
#include "polygon_fixtures.h"

#include "CppUTest/TestHarness.h"
#include "alloc_guard.h"

using boticelli::core::FixedVector;
using boticelli::core::Point2;
using boticelli::mapping::MapPointParams;
using boticelli::mapping::StarPolygon;
namespace mapping = boticelli::mapping;

namespace {

constexpr float kBoundM = 3.0F;
constexpr float kPlausibleM = 1.5F;

// Vertex index (one per degree) of a point's direction on a 360-gon (the points lie on vertex
// rays).
std::size_t vertex_of(Point2 p) {
  const float a = boticelli::core::wrap_two_pi(std::atan2(p.y_m, p.x_m));
  const long k = std::lround(static_cast<double>(a) * 180.0 / 3.14159265358979);
  return static_cast<std::size_t>(k) % 360U;
}

// Sets ρ = rho_m on the vertices [first, first + count) (mod n).
void set_sector(StarPolygon& p, std::size_t first, std::size_t count, float rho_m) {
  for (std::size_t i = 0; i < count; ++i) {
    p.set_rho_m((first + i) % p.vertex_count(), rho_m);
  }
}

bool in_sector(std::size_t k, std::size_t first, std::size_t count) {
  return (k + 360U - first) % 360U < count;
}

}  // namespace

TEST_GROUP(GapExplorationPoints) {
  StarPolygon belief{360};
  StarPolygon plausibility{360};
  MapPointParams params;
  FixedVector<Point2, 64> points;

  void setup() override {
    belief.fill(kPlausibleM);
    plausibility.fill(kPlausibleM);
  }
};

TEST(GapExplorationPoints, EqualPolygonsGiveNoPoints) {
  CHECK_TRUE(
      mapping::extract_gap_exploration_points(belief, plausibility, kBoundM, params, points));
  UNSIGNED_LONGS_EQUAL(0, points.size());

  boticelli::test::Random rng(3);
  boticelli::test::random_star_polygon(rng, plausibility);
  belief = plausibility;
  CHECK_TRUE(
      mapping::extract_gap_exploration_points(belief, plausibility, kBoundM, params, points));
  UNSIGNED_LONGS_EQUAL(0, points.size());
}

TEST(GapExplorationPoints, AGapSectorGivesEvenlySpacedPointsOnlyInThatSector) {
  set_sector(belief, 90, 60, 2.8F);  // unknown band 1.3 m wide on [90°, 150°)
  CHECK_TRUE(
      mapping::extract_gap_exploration_points(belief, plausibility, kBoundM, params, points));
  // Arc 1.45 m · 59° ≈ 1.49 m at 0.5 m spacing: three points, at offsets 10, 30, 50.
  UNSIGNED_LONGS_EQUAL(3, points.size());
  UNSIGNED_LONGS_EQUAL(100, vertex_of(points[0]));
  UNSIGNED_LONGS_EQUAL(120, vertex_of(points[1]));
  UNSIGNED_LONGS_EQUAL(140, vertex_of(points[2]));
  const float gap01 = boticelli::core::distance_m(points[0], points[1]);
  const float gap12 = boticelli::core::distance_m(points[1], points[2]);
  DOUBLES_EQUAL(gap01, gap12, 1e-5);
  // One point per exploration_spacing_m of arc, give or take one vertex step (1° here).
  const float vertex_step_m = (kPlausibleM - params.gap_point_inset_m) * 3.14159265F / 180.0F;
  CHECK_TRUE(gap01 <= params.exploration_spacing_m + vertex_step_m);
  for (const Point2& p : points) {
    CHECK_TRUE(in_sector(vertex_of(p), 90, 60));
    // At the near edge of the band, just inside the plausibility polygon.
    DOUBLES_EQUAL(kPlausibleM - params.gap_point_inset_m, std::hypot(p.x_m, p.y_m), 1e-5);
    CHECK_TRUE(plausibility.contains(p));
  }
}

TEST(GapExplorationPoints, PointsLieInsideAJaggedPlausibilityPolygon) {
  boticelli::test::Random rng(11);
  for (int trial = 0; trial < 20; ++trial) {
    boticelli::test::random_star_polygon(rng, plausibility);
    belief = plausibility;
    const std::size_t first = rng.next() % 360U;
    const std::size_t count = 5 + rng.next() % 120U;
    for (std::size_t i = 0; i < count; ++i) {
      const std::size_t k = (first + i) % 360U;
      belief.set_rho_m(k, plausibility.rho_m(k) + 0.8F);
    }
    // Keep the polygons inside the bounding circle, where the band is not cut.
    points.clear();
    CHECK_TRUE(mapping::extract_gap_exploration_points(belief, plausibility, 4.0F, params, points));
    CHECK_TRUE(points.size() >= 1);
    for (const Point2& p : points) {
      const std::size_t k = vertex_of(p);
      CHECK_TRUE(in_sector(k, first, count));
      CHECK_TRUE(plausibility.contains(p));
      CHECK_TRUE(std::hypot(p.x_m, p.y_m) < plausibility.rho_m(k));
    }
  }
}

TEST(GapExplorationPoints, AGapAcrossTheSeamIsOneSector) {
  set_sector(belief, 330, 60, 2.8F);  // [330°, 30°)
  CHECK_TRUE(
      mapping::extract_gap_exploration_points(belief, plausibility, kBoundM, params, points));
  // One sector of 60 rays: three points with the middle one on angle 0 (two sectors of 30
  // rays would give two points each).
  UNSIGNED_LONGS_EQUAL(3, points.size());
  UNSIGNED_LONGS_EQUAL(340, vertex_of(points[0]));
  UNSIGNED_LONGS_EQUAL(0, vertex_of(points[1]));
  UNSIGNED_LONGS_EQUAL(20, vertex_of(points[2]));
}

TEST(GapExplorationPoints, AGapAllRoundIsOneSector) {
  belief.fill(2.8F);
  CHECK_TRUE(
      mapping::extract_gap_exploration_points(belief, plausibility, kBoundM, params, points));
  // About 2π · 1.45 m ≈ 9.1 m of arc at 0.5 m spacing.
  UNSIGNED_LONGS_EQUAL(19, points.size());
}

TEST(GapExplorationPoints, BandsBeyondTheBoundingCircleAndNarrowOrReversedBandsGiveNoPoints) {
  set_sector(plausibility, 0, 40, kBoundM);  // belief beyond the circle: cut to it, no gap
  set_sector(belief, 0, 40, 5.0F);
  set_sector(belief, 100, 40, kPlausibleM + 0.4F);  // narrower than exploration_gap_m
  set_sector(belief, 200, 40, 0.5F);                // Bel > Pl: a broken fit, not unknown
  CHECK_TRUE(
      mapping::extract_gap_exploration_points(belief, plausibility, kBoundM, params, points));
  UNSIGNED_LONGS_EQUAL(0, points.size());
}

TEST(GapExplorationPoints, PolygonsOfDifferentResolutionAreRejectedAndTheListIsUnchanged) {
  StarPolygon coarse(180);
  coarse.fill(2.8F);
  CHECK_TRUE(points.push_back({1.0F, 2.0F}));
  CHECK_FALSE(
      mapping::extract_gap_exploration_points(coarse, plausibility, kBoundM, params, points));
  UNSIGNED_LONGS_EQUAL(1, points.size());
  DOUBLES_EQUAL(1.0, points[0].x_m, 0.0);
  DOUBLES_EQUAL(2.0, points[0].y_m, 0.0);
}

TEST(GapExplorationPoints, AFullListReturnsFalseAndKeepsWhatFitted) {
  FixedVector<Point2, 2> small;
  set_sector(belief, 90, 60, 2.8F);  // three points
  CHECK_FALSE(
      mapping::extract_gap_exploration_points(belief, plausibility, kBoundM, params, small));
  UNSIGNED_LONGS_EQUAL(2, small.size());
  UNSIGNED_LONGS_EQUAL(100, vertex_of(small[0]));
  UNSIGNED_LONGS_EQUAL(120, vertex_of(small[1]));
}

TEST(GapExplorationPoints, ExtractionAllocatesNothing) {
  set_sector(belief, 330, 60, 2.8F);
  set_sector(belief, 90, 60, 2.8F);
  bool ok = false;
  CHECK_NO_ALLOCATION(
      ok = mapping::extract_gap_exploration_points(belief, plausibility, kBoundM, params, points));
  CHECK_TRUE(ok);
  UNSIGNED_LONGS_EQUAL(6, points.size());
}
