// Tests of the feature guard: unexplained features, their corroboration, and the polygon kept
// clear of them.
#include <algorithm>
#include <array>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <span>

#include "algo/core/fixed_vector.h"
#include "algo/evidence/reading.h"
#include "algo/mapping/extraction.h"
#include "algo/mapping/feature_guard.h"
#include "algo/mapping/polygon_ops.h"
#include "polygon_fixtures.h"

#include "CppUTest/TestHarness.h"
#include "alloc_guard.h"

using boticelli::core::FixedVector;
using boticelli::core::Point2;
using boticelli::evidence::Reading;
namespace mapping = boticelli::mapping;

namespace {

template <std::size_t N>
using GuardCandidatesFor = FixedVector<mapping::GuardPoint, N>;

// A room whose model sees a wall at 2.5 m in every direction and nothing closer: it calls
// everything nearer than 2.5 m free (occupancy 0.9 beyond, 0 before).
float wall_only(float /*alpha*/, float h, float r) {
  const float rho = std::sqrt(std::fmax(0.0F, r * r - h * h));
  return rho >= 2.5F ? 0.9F : 0.0F;
}

// PTU 0.6 m above the floor, robot body 0.05-0.8 m: slices from h = -0.55 to +0.2 m.
mapping::ExtractionParams robot() {
  mapping::ExtractionParams p;
  p.ptu_height_m = 0.6F;
  p.lowest_height_m = 0.05F;
  p.robot_height_m = 0.8F;
  p.robot_radius_m = 0.25F;
  p.bounding_radius_m = 3.0F;
  return p;
}

// A reading of the point at horizontal distance ρ, pan α and height h (PTU frame).
Reading at(float alpha, float rho, float h, float m = 0.9F) {
  return {alpha, h, std::sqrt(rho * rho + h * h), m};
}

// n features on the front face of a small box 1 m ahead: pan ±0.1 rad, heights -0.48..-0.24
// (0.12 m and more above the floor: lower ones are the floor's line of sight within 2 δr).
template <std::size_t N>
void box_face(FixedVector<Reading, N>& out, std::size_t n) {
  for (std::size_t i = 0; i < n; ++i) {
    const float u = static_cast<float>(i % 7) / 6.0F;
    const float v = static_cast<float>(i / 7 % 5) / 4.0F;
    const float alpha = -0.1F + 0.2F * u;
    (void)out.push_back(
        at(alpha < 0.0F ? alpha + 6.2831853F : alpha, 1.0F / std::cos(alpha), -0.48F + 0.24F * v));
  }
}

// Deterministic uniform numbers in [-1, 1] (a 32-bit LCG).
struct Uniform {
  std::uint32_t state = 12345U;
  float next() {
    state = state * 1664525U + 1013904223U;
    return static_cast<float>(state >> 8) / 8388608.0F - 1.0F;
  }
};

// A model that sees only a wall 4 m away: everything nearer is free.
float far_wall(float /*alpha*/, float h, float r) {
  const float rho = std::sqrt(std::fmax(0.0F, r * r - h * h));
  return rho >= 4.0F ? 0.9F : 0.0F;
}

// n readings of the front face of a 0.5 m box 2.5 m ahead (pan ±0.1 rad, heights
// -0.48..-0.24 m), each with a range error uniform in ±error_m (median |error| error_m / 2).
template <std::size_t N>
void noisy_box(FixedVector<Reading, N>& out, std::size_t n, float error_m, Uniform& noise) {
  for (std::size_t i = 0; i < n; ++i) {
    const float u = static_cast<float>(i % 6) / 5.0F;
    const float v = static_cast<float>(i / 6 % 4) / 3.0F;
    const float alpha = -0.1F + 0.2F * u;
    Reading rd =
        at(alpha < 0.0F ? alpha + 6.2831853F : alpha, 2.5F / std::cos(alpha), -0.48F + 0.24F * v);
    rd.r_m += error_m * noise.next();
    (void)out.push_back(rd);
  }
}

template <std::size_t N>
std::size_t kept_by(const GuardCandidatesFor<N>& candidates, const mapping::FeatureGuardParams& g,
                    FixedVector<Point2, N>& kept) {
  kept.clear();
  CHECK_TRUE(mapping::corroborated_points(candidates.span(), g, kept));
  return kept.size();
}

}  // namespace

TEST_GROUP(FeatureGuard){};

TEST(FeatureGuard, OnlySurfacesTheModelCallsFreeInTheRobotsHeightBandAreCandidates) {
  FixedVector<Reading, 8> readings;
  (void)readings.push_back(at(0.5F, 1.0F, -0.3F));         // in the band, model says free
  (void)readings.push_back(at(0.5F, 2.6F, -0.3F));         // the model holds it (wall)
  (void)readings.push_back(at(0.5F, 1.0F, 0.5F));          // above the robot
  (void)readings.push_back(at(0.5F, 1.0F, -0.58F));        // below the lowest slice
  (void)readings.push_back(at(0.5F, 1.0F, -0.3F, 0.3F));   // too little evidence
  (void)readings.push_back(at(2.0F, 1.5F, 0.1F));          // in the band, model says free
  (void)readings.push_back(at(3.0F, 1.2F, -0.1F, 0.45F));  // weak, in the band, free
  FixedVector<mapping::GuardPoint, 8> candidates;
  LONGS_EQUAL(0, mapping::collect_unexplained_features(readings, wall_only, robot(),
                                                       mapping::FeatureGuardParams{}, candidates));
  LONGS_EQUAL(3, candidates.size());
  DOUBLES_EQUAL(std::cos(0.5), candidates[0].x_m, 1e-5);
  DOUBLES_EQUAL(std::sin(0.5), candidates[0].y_m, 1e-5);
  DOUBLES_EQUAL(-0.3, candidates[0].h_m, 1e-6);
  DOUBLES_EQUAL(std::hypot(1.0, 0.3), candidates[0].r_m, 1e-5);
  DOUBLES_EQUAL(0.9, candidates[0].m, 1e-6);
  DOUBLES_EQUAL(1.5 * std::cos(2.0), candidates[1].x_m, 1e-5);
  DOUBLES_EQUAL(0.45, candidates[2].m, 1e-6);
  // With weak features turned off, only the two strong ones.
  mapping::FeatureGuardParams strong_only;
  strong_only.min_weak_evidence = strong_only.min_evidence;
  candidates.clear();
  (void)mapping::collect_unexplained_features(readings, wall_only, robot(), strong_only,
                                              candidates);
  LONGS_EQUAL(2, candidates.size());
}

TEST(FeatureGuard, FloorMismatchesAreNotCandidatesButTheFloorCuesBasesAndLowSurfacesAre) {
  // Floor points 0.6-1.0 m ahead (PTU 0.6 m up) read 11-15% short along their rays: they lie
  // 0.07-0.09 m above the floor, inside the robot's band, and within 2 δr of the floor.
  FixedVector<Reading, 64> readings;
  for (int i = 0; i < 20; ++i) {
    const float rho = 0.6F + 0.02F * static_cast<float>(i);
    const float shrink = 0.85F + 0.002F * static_cast<float>(i);
    const Reading floor = at(0.05F * static_cast<float>(i % 5), rho, -0.6F);
    (void)readings.push_back({floor.alpha_rad, floor.h_m * shrink, floor.r_m * shrink, 0.9F});
  }
  FixedVector<mapping::GuardPoint, 64> candidates;
  (void)mapping::collect_unexplained_features(readings, wall_only, robot(),
                                              mapping::FeatureGuardParams{}, candidates);
  LONGS_EQUAL(0, candidates.size());
  // The same points as the floor cue's obstacle bases: all candidates.
  (void)mapping::collect_unexplained_features(readings, wall_only, robot(),
                                              mapping::FeatureGuardParams{}, candidates, true);
  LONGS_EQUAL(20, candidates.size());
  // With the rule off, stereo features there are candidates too.
  candidates.clear();
  mapping::FeatureGuardParams off;
  off.floor_delta_r_factor = 0.0F;
  (void)mapping::collect_unexplained_features(readings, wall_only, robot(), off, candidates);
  LONGS_EQUAL(20, candidates.size());
  // A surface 0.15 m above the floor at 0.8 m is more than 2 δr short of the floor: kept.
  readings.clear();
  candidates.clear();
  (void)readings.push_back(at(0.2F, 0.8F, -0.45F));
  (void)mapping::collect_unexplained_features(readings, wall_only, robot(),
                                              mapping::FeatureGuardParams{}, candidates);
  LONGS_EQUAL(1, candidates.size());
}

TEST(FeatureGuard, AFullCandidateListCountsWhatItCouldNotKeep) {
  FixedVector<Reading, 8> readings;
  for (int i = 0; i < 5; ++i)
    (void)readings.push_back(at(0.1F * static_cast<float>(i), 1.0F, 0.0F));
  FixedVector<mapping::GuardPoint, 3> candidates;
  LONGS_EQUAL(2, mapping::collect_unexplained_features(readings, wall_only, robot(),
                                                       mapping::FeatureGuardParams{}, candidates));
  LONGS_EQUAL(3, candidates.size());
}

TEST(FeatureGuard, AClusterIsKeptAndLoneOutliersAreDropped) {
  FixedVector<mapping::GuardPoint, 32> candidates;
  for (int i = 0; i < 6; ++i) {  // six features within 4 cm of each other
    (void)candidates.push_back({1.0F + 0.01F * static_cast<float>(i), 0.2F, -0.3F});
  }
  (void)candidates.push_back({-1.0F, 0.5F, -0.2F});  // alone
  (void)candidates.push_back({0.0F, -1.5F, 0.0F});   // alone
  (void)candidates.push_back({0.0F, -1.45F, 0.0F});  // one neighbour is not enough
  FixedVector<Point2, 32> kept;
  CHECK_TRUE(mapping::corroborated_points(candidates, mapping::FeatureGuardParams{}, kept));
  LONGS_EQUAL(6, kept.size());
  for (const Point2& q : kept) {
    CHECK_TRUE(q.x_m >= 1.0F && q.x_m <= 1.06F);
  }
  // A stricter rule drops the cluster too.
  mapping::FeatureGuardParams strict;
  strict.min_neighbours = 6;
  kept.clear();
  CHECK_TRUE(mapping::corroborated_points(candidates, strict, kept));
  LONGS_EQUAL(0, kept.size());
}

TEST(FeatureGuard, NoisyReadingsOfABoxAreKeptWhereAFixedRadiusKeepsFew) {
  // 23 readings (as many as real stereo gives of a plain table) with a range error of up to
  // 0.4 m at 2.5 m, median 0.2 m: more than twice the sensor model's δr = 0.1 r apart.
  FixedVector<Reading, 64> readings;
  Uniform noise;
  noisy_box(readings, 23, 0.4F, noise);
  GuardCandidatesFor<64> candidates;
  (void)mapping::collect_unexplained_features(readings, far_wall, robot(),
                                              mapping::FeatureGuardParams{}, candidates);
  LONGS_EQUAL(23, candidates.size());
  FixedVector<Point2, 64> kept;
  CHECK_TRUE(kept_by(candidates, mapping::FeatureGuardParams{}, kept) >= 21);
  for (const Point2& q : kept) {  // on the box, within the range error
    CHECK_TRUE(q.x_m > 2.05F && q.x_m < 2.95F && std::fabs(q.y_m) < 0.35F);
  }
  mapping::FeatureGuardParams fixed;
  fixed.neighbour_delta_r_factor = 0.0F;  // the old rule: a 0.1 m ball whatever the range
  fixed.lateral_radius_m = 0.0F;
  CHECK_TRUE(kept_by(candidates, fixed, kept) <= 5);
}

TEST(FeatureGuard, IsolatedOutliersAreNotKeptThoughTheRadiusGrowsWithRange) {
  FixedVector<Reading, 64> readings;
  Uniform noise;
  noisy_box(readings, 23, 0.4F, noise);
  // Lone mismatches all round the room, 1-3.9 m away, at least 1 m apart.
  for (int i = 0; i < 10; ++i) {
    const float fi = static_cast<float>(i);
    (void)readings.push_back(at(0.5F + 0.55F * fi, 1.0F + 0.3F * fi, -0.5F + 0.07F * fi));
  }
  GuardCandidatesFor<64> candidates;
  (void)mapping::collect_unexplained_features(readings, far_wall, robot(),
                                              mapping::FeatureGuardParams{}, candidates);
  LONGS_EQUAL(33, candidates.size());
  FixedVector<Point2, 64> kept;
  CHECK_TRUE(kept_by(candidates, mapping::FeatureGuardParams{}, kept) >= 21);
  for (const Point2& q : kept) {
    CHECK_TRUE(q.x_m > 2.05F && std::fabs(q.y_m) < 0.35F);  // only the box
  }
}

TEST(FeatureGuard, NeighboursAreFoundAlongTheLineOfSightWithinTheSummedRangeError) {
  const mapping::FeatureGuardParams g;  // δr = 0.1 r, 0.25 m across the line of sight
  // Along the line of sight (x axis) at 2 m and 2.4 m: 0.4 ≤ 0.2 + 0.24 m.
  const mapping::GuardPoint a{2.0F, 0.0F, 0.0F, 2.0F};
  CHECK_TRUE(mapping::are_neighbours(a, {2.4F, 0.0F, 0.0F, 2.4F}, g));
  CHECK_FALSE(mapping::are_neighbours(a, {2.6F, 0.0F, 0.0F, 2.6F}, g));  // 0.6 > 0.46 m
  // Across it the range error does not count: 0.24 m is near, 0.3 m is not, though both are
  // well within 0.5 m.
  CHECK_TRUE(mapping::are_neighbours(a, {2.0F, 0.24F, 0.0F, 2.01F}, g));
  CHECK_FALSE(mapping::are_neighbours(a, {2.0F, 0.3F, 0.0F, 2.02F}, g));
  CHECK_FALSE(mapping::are_neighbours(a, {2.0F, 0.0F, 0.3F, 2.02F}, g));  // above, too
}

TEST(FeatureGuard, NeighboursAreFoundWithinTheSummedRangeErrorOfThePair) {
  mapping::FeatureGuardParams g;  // δr = 0.1 r
  g.lateral_radius_m = 0.0F;      // a ball of that radius
  // Two readings at 2 m and 3 m: 0.2 + 0.3 = 0.5 m.
  const mapping::GuardPoint a{2.0F, 0.0F, 0.0F, 2.0F};
  CHECK_TRUE(mapping::are_neighbours(a, {2.0F, 0.49F, 0.0F, 3.0F}, g));
  CHECK_FALSE(mapping::are_neighbours(a, {2.0F, 0.51F, 0.0F, 3.0F}, g));
  // Near the camera the fixed radius rules: 0.02 + 0.02 < 0.1 m.
  const mapping::GuardPoint c{0.2F, 0.0F, 0.0F, 0.2F};
  CHECK_TRUE(mapping::are_neighbours(c, {0.2F, 0.09F, 0.0F, 0.2F}, g));
  CHECK_FALSE(mapping::are_neighbours(c, {0.2F, 0.11F, 0.0F, 0.2F}, g));
  // Height counts (3-D distance), and the rule is symmetric.
  CHECK_FALSE(mapping::are_neighbours(a, {2.0F, 0.4F, 0.4F, 3.0F}, g));
  CHECK_TRUE(mapping::are_neighbours({2.0F, 0.49F, 0.0F, 3.0F}, a, g));
}

namespace {
// The neighbour rule (FeatureGuardParams) computed in double apart from the guard's code: the
// pair's radius from its summed range error, and with a lateral radius its offset split along
// and across a + b (the pair's mean line of sight from the PTU centre). Returns the smaller
// margin by which the pair meets its bounds [m]; negative: not neighbours.
double neighbour_margin(const mapping::GuardPoint& a, const mapping::GuardPoint& b,
                        const mapping::FeatureGuardParams& g) {
  const auto wide = [](float v) { return static_cast<double>(v); };
  const double radius = std::max(wide(g.neighbour_radius_m),
                                 wide(g.neighbour_delta_r_factor) * wide(g.delta_r_fraction) *
                                     (std::fabs(wide(a.r_m)) + std::fabs(wide(b.r_m))));
  const std::array<double, 3> d = {wide(b.x_m) - wide(a.x_m), wide(b.y_m) - wide(a.y_m),
                                   wide(b.h_m) - wide(a.h_m)};
  const double dist = std::sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
  if (!(g.lateral_radius_m > 0.0F)) return radius - dist;
  const std::array<double, 3> s = {wide(a.x_m) + wide(b.x_m), wide(a.y_m) + wide(b.y_m),
                                   wide(a.h_m) + wide(b.h_m)};
  const double along = (d[0] * s[0] + d[1] * s[1] + d[2] * s[2]) /
                       std::sqrt(s[0] * s[0] + s[1] * s[1] + s[2] * s[2]);
  const double across = std::sqrt(std::max(dist * dist - along * along, 0.0));
  const double lateral = std::min(wide(g.lateral_radius_m), radius);
  return std::min(radius - std::fabs(along), lateral - across);
}
}  // namespace

// Pairs about lines of sight in every direction, up to 80° above and below the horizon, 0.3 to
// 5 m out, offset along and across their line of sight by up to 1.3 times what the rule allows:
// are_neighbours decides as the rule computed independently does, with each parameter set
// (ranges known or not), leaving out only pairs within 0.1 mm of a bound.
TEST(FeatureGuard, NeighboursAlongAndAcrossTheirMeanLineOfSightAreThoseTheRuleComputedApartGives) {
  boticelli::test::Random rng(47);
  std::array<mapping::FeatureGuardParams, 5> rules{};
  rules[1].lateral_radius_m = 0.0F;          // a ball of the pair's radius
  rules[2].neighbour_delta_r_factor = 0.0F;  // the fixed radius, narrower across
  rules[3].lateral_radius_m = 0.6F;          // wider across than many pairs' radius
  rules[4].delta_r_fraction = 0.05F;
  int near = 0;
  int apart = 0;
  int oblique_beyond_lateral = 0;  // neighbours only along a steep line of sight
  for (const mapping::FeatureGuardParams& g : rules) {
    for (int k = 0; k < 2000; ++k) {
      const float pan = rng.uniform(-3.14159F, 3.14159F);
      const float el = rng.uniform(-1.4F, 1.4F);
      const float range = rng.uniform(0.3F, 5.0F);
      const std::array<float, 3> los = {std::cos(el) * std::cos(pan), std::cos(el) * std::sin(pan),
                                        std::sin(el)};
      // A unit vector across the line of sight, at a random angle about it.
      const float turn = rng.uniform(-3.14159F, 3.14159F);
      const std::array<float, 3> e1 = {-std::sin(pan), std::cos(pan), 0.0F};
      const std::array<float, 3> e2 = {-std::sin(el) * std::cos(pan), -std::sin(el) * std::sin(pan),
                                       std::cos(el)};
      const bool known = k % 10 != 0;  // a tenth with unknown ranges: the fixed radius
      const float bound =
          std::fmax(g.neighbour_radius_m,
                    known ? g.neighbour_delta_r_factor * g.delta_r_fraction * 2.0F * range : 0.0F);
      const float along = bound * rng.uniform(-1.3F, 1.3F);
      const float across =
          std::fmin(g.lateral_radius_m > 0.0F ? g.lateral_radius_m : bound, bound) *
          rng.uniform(0.0F, 1.3F);
      std::array<float, 3> pa{};
      std::array<float, 3> pb{};
      for (std::size_t i = 0; i < 3; ++i) {
        const float mid = range * los[i];
        const float half =
            0.5F * (along * los[i] + across * (std::cos(turn) * e1[i] + std::sin(turn) * e2[i]));
        pa[i] = mid - half;
        pb[i] = mid + half;
      }
      const mapping::GuardPoint a{
          pa[0], pa[1], pa[2],
          known ? std::sqrt(pa[0] * pa[0] + pa[1] * pa[1] + pa[2] * pa[2]) : 0.0F};
      const mapping::GuardPoint b{
          pb[0], pb[1], pb[2],
          known ? std::sqrt(pb[0] * pb[0] + pb[1] * pb[1] + pb[2] * pb[2]) : 0.0F};
      const double margin = neighbour_margin(a, b, g);
      if (std::fabs(margin) < 1e-4) continue;
      CHECK_EQUAL(margin > 0.0, mapping::are_neighbours(a, b, g));
      CHECK_EQUAL(margin > 0.0, mapping::are_neighbours(b, a, g));
      (margin > 0.0 ? near : apart) += 1;
      const float dist = std::hypot(pb[0] - pa[0], pb[1] - pa[1], pb[2] - pa[2]);
      if (margin > 0.0 && g.lateral_radius_m > 0.0F && std::fabs(el) > 0.5F &&
          dist > 1.1F * g.lateral_radius_m) {
        ++oblique_beyond_lateral;
      }
    }
  }
  CHECK(near > 2500 && apart > 2500);  // both kinds, well spread
  CHECK(oblique_beyond_lateral > 100);
}

TEST(FeatureGuard, AWeakFeatureNeedsMoreCorroborationThanAStrongOne) {
  GuardCandidatesFor<32> candidates;
  for (int i = 0; i < 6; ++i) {  // six weak features within 5 cm: five neighbours each
    (void)candidates.push_back({1.0F + 0.01F * static_cast<float>(i), 0.2F, -0.3F, 1.0F, 0.5F});
  }
  FixedVector<Point2, 32> kept;
  LONGS_EQUAL(0, kept_by(candidates, mapping::FeatureGuardParams{}, kept));
  for (mapping::GuardPoint& c : candidates) {
    c.m = 0.9F;  // the same cluster with strong evidence
  }
  LONGS_EQUAL(6, kept_by(candidates, mapping::FeatureGuardParams{}, kept));
  for (mapping::GuardPoint& c : candidates) {
    c.m = 0.5F;
  }
  for (int i = 0; i < 4; ++i) {  // ten weak features: nine neighbours each
    (void)candidates.push_back({1.0F, 0.21F + 0.01F * static_cast<float>(i), -0.3F, 1.0F, 0.5F});
  }
  LONGS_EQUAL(10, kept_by(candidates, mapping::FeatureGuardParams{}, kept));
}

TEST(FeatureGuard, TheNavigablePolygonKeepsTheRobotClearOfABoxTheModelMissed) {
  FixedVector<Reading, 64> readings;
  box_face(readings, 35);
  FixedVector<mapping::GuardPoint, 64> candidates;
  const mapping::ExtractionParams p = robot();
  (void)mapping::collect_unexplained_features(readings, wall_only, p, mapping::FeatureGuardParams{},
                                              candidates);
  LONGS_EQUAL(35, candidates.size());
  FixedVector<Point2, 64> guard;
  CHECK_TRUE(mapping::corroborated_points(candidates, mapping::FeatureGuardParams{}, guard));
  LONGS_EQUAL(35, guard.size());
  // The model alone: the wall at 2.5 m (r at h from the occupancy above).
  auto free_range = [](float, float h) { return std::sqrt(2.5F * 2.5F + h * h); };
  static mapping::LocalMap map;
  static mapping::StarPolygon scratch;
  mapping::extract_local_map(free_range, p, map, scratch);
  CHECK_TRUE(map.free.contains({1.0F, 0.0F}));  // the model drives into the box
  mapping::extract_local_map(free_range, p, map, scratch, guard);
  CHECK_TRUE(map.can_move);
  for (const Point2& q : guard) {
    CHECK_FALSE(map.free.contains(q));
  }
  // Every straight path to a navigable point stays a robot radius from every box feature.
  for (std::size_t k = 0; k < map.navigable.vertex_count(); ++k) {
    const Point2 v = map.navigable.vertex(k);
    for (const Point2& q : guard) {
      // Distance from q to the segment [0, v].
      const float len2 = v.x_m * v.x_m + v.y_m * v.y_m;
      const float s = len2 > 0.0F
                          ? std::fmin(1.0F, std::fmax(0.0F, (q.x_m * v.x_m + q.y_m * v.y_m) / len2))
                          : 0.0F;
      CHECK_TRUE(std::hypot(q.x_m - s * v.x_m, q.y_m - s * v.y_m) >= p.robot_radius_m);
    }
  }
  // Away from the box nothing changed.
  DOUBLES_EQUAL(2.5, map.free.rho_m(180), 1e-3);
}

TEST(FeatureGuard, CollectingCorroboratingAndExcludingAllocateNothing) {
  static FixedVector<Reading, 64> readings;
  readings.clear();  // static: a repeated run (-r) starts from none
  box_face(readings, 35);
  static FixedVector<mapping::GuardPoint, 64> candidates;
  static FixedVector<Point2, 64> guard;
  static FixedVector<Point2, 64> thinned;
  static std::array<std::uint32_t, 64> order;  // the readings by pan (drop_seen_through)
  static mapping::LocalMap map;
  static mapping::StarPolygon scratch;
  const mapping::ExtractionParams p = robot();
  auto free_range = [](float, float h) { return std::sqrt(2.5F * 2.5F + h * h); };
  CHECK_NO_ALLOCATION({
    candidates.clear();
    guard.clear();
    (void)mapping::collect_unexplained_features(readings, wall_only, p,
                                                mapping::FeatureGuardParams{}, candidates);
    mapping::FeatureGuardParams see_through;
    see_through.see_through_readings = 2;
    (void)mapping::drop_seen_through(readings, see_through, candidates);
    (void)mapping::drop_seen_through(readings, see_through, candidates, order);
    (void)mapping::corroborated_points(candidates, mapping::FeatureGuardParams{}, guard);
    thinned.clear();
    for (const Point2& q : guard) (void)thinned.push_back(q);
    thinned.resize(mapping::keep_points_that_cut(thinned.span(), scratch.vertex_count()));
    mapping::extract_local_map(free_range, p, map, scratch, guard);
  });
  LONGS_EQUAL(35, guard.size());
  CHECK(thinned.size() > 0 && thinned.size() < 35);
}

// More candidates than the first wave's list held (2,048; looks on rendered frames have up to
// 6,700): clusters and strays over a 5 m square, ranges 0.5–5 m. Sorted by x, the windowed
// search must keep exactly the points the all-pairs search keeps.
TEST(FeatureGuard, SortedCandidatesKeepTheSamePointsAsTheAllPairsSearch) {
  static GuardCandidatesFor<mapping::kMaxGuardCandidates> candidates;
  candidates.clear();
  std::uint32_t state = 12345U;
  const auto next = [&state]() {  // uniform in [0, 1)
    state = state * 1664525U + 1013904223U;
    return static_cast<float>(state >> 8) / 16777216.0F;
  };
  for (int c = 0; c < 700; ++c) {
    const float cx = -2.5F + 5.0F * next();
    const float cy = -2.5F + 5.0F * next();
    const int members = c % 3 == 0 ? 1 : 2 + c % 9;  // a third are strays
    for (int k = 0; k < members; ++k) {
      const float x = cx + 0.15F * (next() - 0.5F);
      const float y = cy + 0.15F * (next() - 0.5F);
      const float h = -0.5F + 0.6F * next();
      (void)candidates.push_back({x, y, h, std::hypot(x, y), next() < 0.3F ? 0.5F : 0.9F});
    }
  }
  CHECK(candidates.size() > 2048U);
  static FixedVector<Point2, mapping::kMaxGuardPoints> all_pairs;
  static FixedVector<Point2, mapping::kMaxGuardPoints> windowed;
  all_pairs.clear();
  windowed.clear();
  CHECK_TRUE(
      mapping::corroborated_points(candidates.span(), mapping::FeatureGuardParams{}, all_pairs));
  CHECK_NO_ALLOCATION(mapping::sort_guard_candidates(candidates.span()));
  // In bounded slices, as the local model builder runs it.
  for (std::size_t first = 0; first < candidates.size(); first += 256) {
    CHECK_TRUE(mapping::corroborated_points(candidates.span(), first, first + 256,
                                            mapping::FeatureGuardParams{}, windowed));
  }
  CHECK(all_pairs.size() > 1000U);
  CHECK(all_pairs.size() < candidates.size());  // the strays are not kept
  LONGS_EQUAL(all_pairs.size(), windowed.size());
  const auto by_xy = [](const Point2& a, const Point2& b) {
    return a.x_m < b.x_m || (a.x_m == b.x_m && a.y_m < b.y_m);
  };
  std::sort(all_pairs.begin(), all_pairs.end(), by_xy);
  std::sort(windowed.begin(), windowed.end(), by_xy);
  for (std::size_t i = 0; i < all_pairs.size(); ++i) {
    CHECK_EQUAL(all_pairs[i].x_m, windowed[i].x_m);
    CHECK_EQUAL(all_pairs[i].y_m, windowed[i].y_m);
  }
}

// Rows of five readings 3 cm apart along x, 0.4 m away at the four diagonal pans: each pair is
// as far along its line of sight as across it, so the ends of a row are neighbours, |Δx| =
// 0.12 m, though farther apart in x than the range error alone allows (0.1 m): the sorted
// search must reach over the lateral radius too to keep them as the all-pairs search does.
TEST(FeatureGuard, SortedCandidatesKeepTheAllPairsPointsOfRowsAcrossObliqueLinesOfSight) {
  GuardCandidatesFor<64> candidates;
  for (const float pan : {0.25F, 0.75F, 1.25F, 1.75F}) {
    const float cx = 0.4F * std::cos(pan * 3.14159265F);
    const float cy = 0.4F * std::sin(pan * 3.14159265F);
    for (int k = -2; k <= 2; ++k) {
      const float x = cx + 0.03F * static_cast<float>(k);
      (void)candidates.push_back({x, cy, 0.0F, std::hypot(x, cy), 0.9F});
    }
  }
  FixedVector<Point2, 64> all_pairs;
  FixedVector<Point2, 64> sorted;
  CHECK_TRUE(
      mapping::corroborated_points(candidates.span(), mapping::FeatureGuardParams{}, all_pairs));
  LONGS_EQUAL(candidates.size(), all_pairs.size());  // every reading has its four neighbours
  mapping::sort_guard_candidates(candidates.span());
  CHECK_TRUE(
      mapping::corroborated_points(candidates.span(), mapping::FeatureGuardParams{}, sorted));
  LONGS_EQUAL(all_pairs.size(), sorted.size());
}

namespace {
// A candidate at pan α, horizontal distance ρ and height h (PTU frame), as
// collect_unexplained_features makes it.
mapping::GuardPoint candidate_at(float alpha, float rho, float h) {
  return {rho * std::cos(alpha), rho * std::sin(alpha), h, std::sqrt(rho * rho + h * h), 0.9F};
}
}  // namespace

TEST(FeatureGuard, ACandidateTheCameraSawPastOnItsLineOfSightIsDroppedAndOthersStay) {
  FixedVector<Reading, 16> readings;
  // Behind A (pan 0, 1 m ahead, 0.3 m down): two readings 2 m out on lines of sight 5 mrad
  // off its own (the same elevation).
  (void)readings.push_back(at(0.005F, 2.0F, -0.6F));
  (void)readings.push_back(at(6.2781853F, 2.0F, -0.6F));  // -0.005 rad, across the seam
  // B (pan 1): two readings beyond it but 50 mrad to the side; two on its line of sight but
  // within the two range errors (δr = 0.1 r each); one in front of it.
  (void)readings.push_back(at(1.05F, 2.0F, -0.6F));
  (void)readings.push_back(at(0.95F, 2.0F, -0.6F));
  (void)readings.push_back(at(1.0F, 1.1F, -0.33F));
  (void)readings.push_back(at(1.0F, 1.2F, -0.36F));
  (void)readings.push_back(at(1.0F, 0.5F, -0.15F));
  // C (pan 2): one reading beyond it.
  (void)readings.push_back(at(2.0F, 2.5F, -0.75F));
  // D (pan just below 2π): two readings beyond it just above 0, across the seam.
  (void)readings.push_back(at(0.004F, 2.0F, 0.2F));
  (void)readings.push_back(at(0.002F, 3.0F, 0.3F));
  const std::array<mapping::GuardPoint, 4> all = {
      candidate_at(0.0F, 1.0F, -0.3F), candidate_at(1.0F, 1.0F, -0.3F),
      candidate_at(2.0F, 1.0F, -0.3F), candidate_at(6.2731853F, 1.0F, 0.1F)};
  // The plain scan and the one over the readings ordered by pan drop the same.
  const auto run = [&](std::size_t through) {
    mapping::FeatureGuardParams g;
    g.see_through_readings = through;
    GuardCandidatesFor<4> candidates;
    GuardCandidatesFor<4> ordered;
    for (const mapping::GuardPoint& c : all) {
      (void)candidates.push_back(c);
      (void)ordered.push_back(c);
    }
    const std::size_t dropped = mapping::drop_seen_through(readings, g, candidates);
    LONGS_EQUAL(dropped, all.size() - candidates.size());
    std::array<std::uint32_t, 16> scratch{};
    LONGS_EQUAL(dropped, mapping::drop_seen_through(readings, g, ordered, scratch));
    LONGS_EQUAL(candidates.size(), ordered.size());
    for (std::size_t i = 0; i < candidates.size(); ++i) {
      CHECK_EQUAL(candidates[i].x_m, ordered[i].x_m);
    }
    return candidates;
  };
  // Two readings needed: A and D go, B and C stay, in their order.
  const GuardCandidatesFor<4> two = run(2);
  LONGS_EQUAL(2, two.size());
  DOUBLES_EQUAL(all[1].x_m, two[0].x_m, 0.0);
  DOUBLES_EQUAL(all[2].x_m, two[1].x_m, 0.0);
  // One reading is enough for C too; off, nothing goes.
  LONGS_EQUAL(1, run(1).size());
  LONGS_EQUAL(4, run(0).size());
}

namespace {
// The see-through test by its definition alone, without the guard's cone or buckets: reading
// q, seen from its view, lies farther than the candidate by both range errors and within the
// angle of the candidate's line of sight. Candidates no farther than the camera's lever from
// the PTU centre are never tested.
template <std::size_t N>
bool seen_through_by_definition(const FixedVector<Reading, N>& readings,
                                const mapping::GuardPoint& c,
                                const mapping::FeatureGuardParams& g) {
  float lever = 0.0F;
  for (const Reading& q : readings) {
    lever = std::fmax(lever, std::sqrt(q.view_x_m * q.view_x_m + q.view_y_m * q.view_y_m +
                                       q.view_z_m * q.view_z_m));
  }
  if (!(std::sqrt(c.x_m * c.x_m + c.y_m * c.y_m + c.h_m * c.h_m) > lever)) return false;
  const float far_factor = (1.0F + g.delta_r_fraction) / (1.0F - g.delta_r_fraction);
  const float cos_max = std::cos(g.see_through_angle_rad);
  std::size_t through = 0;
  for (const Reading& q : readings) {
    const Point2 qp = boticelli::evidence::floor_point_m(q);
    const float ux = qp.x_m - q.view_x_m;
    const float uy = qp.y_m - q.view_y_m;
    const float uz = q.h_m - q.view_z_m;
    const float wx = c.x_m - q.view_x_m;
    const float wy = c.y_m - q.view_y_m;
    const float wz = c.h_m - q.view_z_m;
    const float u = std::sqrt(ux * ux + uy * uy + uz * uz);
    const float w = std::sqrt(wx * wx + wy * wy + wz * wz);
    if (u > w * far_factor && ux * wx + uy * wy + uz * wz >= cos_max * u * w) ++through;
  }
  return through >= g.see_through_readings;
}
}  // namespace

// Readings from views on a 0.21 m lever (the pan-tilt unit's camera), some lying just past
// candidates near and far, above and below: both scans drop exactly the candidates the
// definition drops (their cones and buckets only skip readings that cannot count).
TEST(FeatureGuard, BothScansDropExactlyTheCandidatesTheDefinitionOfSeeingPastDrops) {
  static FixedVector<Reading, 3000> readings;
  readings.clear();
  boticelli::test::Random rng(43);
  static GuardCandidatesFor<400> plain;
  static GuardCandidatesFor<400> ordered;
  plain.clear();
  ordered.clear();
  for (int k = 0; k < 400; ++k) {
    const float alpha = rng.uniform(-3.14F, 3.14F);
    const mapping::GuardPoint c =
        candidate_at(alpha, rng.uniform(0.22F, 3.5F), rng.uniform(-0.8F, 0.5F));
    (void)plain.push_back(c);
    (void)ordered.push_back(c);
    // Three readings from views on the lever, beyond the candidate by 1.1 to 1.6 times, up to
    // 0.12 rad off its line of sight (the test's angle is 0.05 rad).
    for (int j = 0; j < 3; ++j) {
      const float view = rng.uniform(0.0F, 6.2831853F);
      const float vx = 0.21F * std::cos(view);
      const float vy = 0.21F * std::sin(view);
      const float vz = rng.uniform(-0.05F, 0.05F);
      const float t = rng.uniform(1.1F, 1.6F);
      const float off = rng.uniform(-0.12F, 0.12F) * t * std::hypot(c.x_m - vx, c.y_m - vy);
      const float px = vx + t * (c.x_m - vx) + off;
      const float py = vy + t * (c.y_m - vy) - off;
      const float pz = vz + t * (c.h_m - vz) + 0.5F * off;
      float a = std::atan2(py, px);
      if (a < 0.0F) a += 6.2831853F;
      Reading q = at(a, std::hypot(px, py), pz);
      q.view_x_m = vx;
      q.view_y_m = vy;
      q.view_z_m = vz;
      (void)readings.push_back(q);
    }
  }
  mapping::FeatureGuardParams g;
  g.see_through_readings = 2;
  g.see_through_angle_rad = 0.05F;
  std::size_t expected = 0;
  for (const mapping::GuardPoint& c : plain) expected += seen_through_by_definition(readings, c, g);
  CHECK(expected > 40 && expected < 360);  // the test has both kinds
  static std::array<std::uint32_t, 3000> scratch;
  LONGS_EQUAL(expected, mapping::drop_seen_through(readings, g, plain));
  LONGS_EQUAL(expected, mapping::drop_seen_through(readings, g, ordered, scratch));
  for (const mapping::GuardPoint& c : plain)
    CHECK_FALSE(seen_through_by_definition(readings, c, g));
  for (const mapping::GuardPoint& c : ordered) {
    CHECK_FALSE(seen_through_by_definition(readings, c, g));
  }
}

// The ordered scan visits every pan bucket within the cone once: a reading alone in its bucket
// counts once, however many buckets round it are looked at.
TEST(FeatureGuard, AReadingSeenPastACandidateCountsOnceInEitherScan) {
  FixedVector<Reading, 4> readings;
  (void)readings.push_back(at(1.0F, 3.0F, 0.0F));  // straight behind the candidate
  mapping::FeatureGuardParams g;
  g.see_through_readings = 2;
  std::array<std::uint32_t, 4> scratch{};
  for (int behind = 1; behind <= 2; ++behind) {
    GuardCandidatesFor<2> plain;
    (void)plain.push_back(candidate_at(1.0F, 2.0F, 0.0F));
    GuardCandidatesFor<2> ordered = plain;
    const std::size_t expected = behind == 2 ? 1U : 0U;  // two readings needed
    LONGS_EQUAL(expected, mapping::drop_seen_through(readings, g, plain));
    LONGS_EQUAL(expected, mapping::drop_seen_through(readings, g, ordered, scratch));
    (void)readings.push_back(at(1.001F, 3.5F, 0.0F));
  }
}

// However coarse the range error (any fraction below the whole range), a reading far enough
// behind a candidate shows the camera saw past it.
TEST(FeatureGuard, WithARangeErrorOfMoreThanHalfTheRangeAReadingFarBehindStillSeesPast) {
  FixedVector<Reading, 2> readings;
  (void)readings.push_back(at(1.0F, 10.0F, 0.0F));  // 5 times as far: beyond both errors at 0.6
  mapping::FeatureGuardParams g;
  g.see_through_readings = 1;
  g.delta_r_fraction = 0.6F;
  std::array<std::uint32_t, 2> scratch{};
  GuardCandidatesFor<2> plain;
  (void)plain.push_back(candidate_at(1.0F, 2.0F, 0.0F));
  GuardCandidatesFor<2> ordered = plain;
  LONGS_EQUAL(1, mapping::drop_seen_through(readings, g, plain));
  LONGS_EQUAL(1, mapping::drop_seen_through(readings, g, ordered, scratch));
}

TEST(FeatureGuard, OrderingTheReadingsByPanDropsTheSameCandidatesAsThePlainScan) {
  // A room's readings from views on a 0.21 m lever, and candidates among and in front of
  // them, many near the seam at pan 0 / 2π: both scans drop the same ones, in the same order.
  static FixedVector<Reading, 4000> readings;
  readings.clear();
  boticelli::test::Random rng(41);
  for (int k = 0; k < 4000; ++k) {
    const float alpha = k % 4 == 0 ? rng.uniform(6.1F, 6.2831F) : rng.uniform(0.0F, 6.2831F);
    Reading q = at(alpha, rng.uniform(1.0F, 4.0F), rng.uniform(-0.8F, 0.6F));
    const float view = rng.uniform(0.0F, 6.2831853F);
    q.view_x_m = 0.21F * std::cos(view);
    q.view_y_m = 0.21F * std::sin(view);
    (void)readings.push_back(q);
  }
  static GuardCandidatesFor<600> plain;
  static GuardCandidatesFor<600> ordered;
  plain.clear();
  ordered.clear();
  for (int k = 0; k < 600; ++k) {
    const float alpha = k % 3 == 0 ? rng.uniform(-0.2F, 0.2F) : rng.uniform(-3.14F, 3.14F);
    const mapping::GuardPoint c =
        candidate_at(alpha, rng.uniform(0.3F, 3.5F), rng.uniform(-0.8F, 0.5F));
    (void)plain.push_back(c);
    (void)ordered.push_back(c);
  }
  mapping::FeatureGuardParams g;
  g.see_through_readings = 2;
  g.see_through_angle_rad = 0.05F;
  static std::array<std::uint32_t, 4000> scratch;
  const std::size_t dropped = mapping::drop_seen_through(readings, g, plain);
  CHECK(dropped > 60 && dropped < 540);  // the test has both kinds
  LONGS_EQUAL(dropped, mapping::drop_seen_through(readings, g, ordered, scratch));
  LONGS_EQUAL(plain.size(), ordered.size());
  for (std::size_t i = 0; i < plain.size(); ++i) {
    CHECK_EQUAL(plain[i].x_m, ordered[i].x_m);
    CHECK_EQUAL(plain[i].y_m, ordered[i].y_m);
  }
}

TEST(FeatureGuard, TheLinesOfSightThatSeePastACandidateStartAtTheReadingsViews) {
  // A candidate 1 m ahead at pan 0; two readings 2 m beyond it on lines of sight from an
  // optical centre 0.21 m to the side (pan π/2). From the PTU centre their directions are
  // 0.14 rad off the candidate's; from their view, they pass through it.
  const mapping::GuardPoint c = candidate_at(0.0F, 1.0F, 0.0F);
  FixedVector<Reading, 4> readings;
  for (const float dz : {0.0F, 0.01F}) {
    // view v = (0, 0.21, 0); the point v + 3 (c − v).
    const float x = 3.0F * 1.0F;
    const float y = 0.21F + 3.0F * (0.0F - 0.21F);
    Reading q = at(std::atan2(y, x) + 6.2831853F, std::hypot(x, y), dz);
    q.view_y_m = 0.21F;
    (void)readings.push_back(q);
  }
  mapping::FeatureGuardParams g;
  g.see_through_readings = 2;
  GuardCandidatesFor<2> candidates;
  (void)candidates.push_back(c);
  LONGS_EQUAL(1, mapping::drop_seen_through(readings, g, candidates));
  LONGS_EQUAL(0, candidates.size());
  // The same points seen from the PTU centre pass 0.14 rad to the side: the candidate stays.
  for (Reading& q : readings) q.view_y_m = 0.0F;
  (void)candidates.push_back(c);
  LONGS_EQUAL(0, mapping::drop_seen_through(readings, g, candidates));
  LONGS_EQUAL(1, candidates.size());
}

namespace {
// A reading of the point view + t û, seen from view, where û lies `off` radians from the
// direction view → c, turned `turn` about it; t is `beyond` times the distance to c.
Reading reading_past(const mapping::GuardPoint& c, const std::array<float, 3>& view, float off,
                     float turn, float beyond) {
  const std::array<float, 3> w = {c.x_m - view[0], c.y_m - view[1], c.h_m - view[2]};
  const float wn = std::sqrt(w[0] * w[0] + w[1] * w[1] + w[2] * w[2]);
  // Two unit vectors across w.
  const float wh = std::hypot(w[0], w[1]);
  const std::array<float, 3> e1 = wh > 1e-6F ? std::array<float, 3>{-w[1] / wh, w[0] / wh, 0.0F}
                                             : std::array<float, 3>{1, 0, 0};
  const std::array<float, 3> e2 = {(w[1] * e1[2] - w[2] * e1[1]) / wn,
                                   (w[2] * e1[0] - w[0] * e1[2]) / wn,
                                   (w[0] * e1[1] - w[1] * e1[0]) / wn};
  std::array<float, 3> p{};
  for (std::size_t i = 0; i < 3; ++i) {
    const float u = std::cos(off) * w[i] / wn +
                    std::sin(off) * (std::cos(turn) * e1[i] + std::sin(turn) * e2[i]);
    p[i] = view[i] + beyond * wn * u;
  }
  float a = std::atan2(p[1], p[0]);
  if (a < 0.0F) a += 6.2831853F;
  Reading q = at(a, std::hypot(p[0], p[1]), p[2]);
  q.view_x_m = view[0];
  q.view_y_m = view[1];
  q.view_z_m = view[2];
  return q;
}
}  // namespace

// Candidates on steep lines of sight, 70° to 89.9° above and below the horizon, where a cone
// about the line of sight spans wide pans and, once it holds the vertical, every pan. Readings
// lie 1.1 to 2 times as far out (some not beyond both range errors), up to 2.5 times the angle
// off, turned any way about the line of sight, seen from the PTU centre or from views on a short
// lever: both scans drop exactly the candidates the definition drops.
TEST(FeatureGuard, BothScansDropTheCandidatesTheDefinitionDropsAlsoOnLinesOfSightNearTheVertical) {
  for (const float lever : {0.0F, 0.05F}) {
    static FixedVector<Reading, 1200> readings;
    static GuardCandidatesFor<400> plain;
    static GuardCandidatesFor<400> ordered;
    readings.clear();
    plain.clear();
    ordered.clear();
    boticelli::test::Random rng(lever > 0.0F ? 53U : 59U);
    for (int k = 0; k < 400; ++k) {
      const float el = (k % 2 == 0 ? 1.0F : -1.0F) * rng.uniform(1.22F, 1.5690F);
      const float range = rng.uniform(0.5F, 4.0F);
      const mapping::GuardPoint c = candidate_at(rng.uniform(-3.14159F, 3.14159F),
                                                 range * std::cos(el), range * std::sin(el));
      (void)plain.push_back(c);
      (void)ordered.push_back(c);
      for (int j = 0; j < 3; ++j) {
        const float view_pan = rng.uniform(0.0F, 6.2831853F);
        const std::array<float, 3> view = {lever * std::cos(view_pan), lever * std::sin(view_pan),
                                           rng.uniform(-0.5F, 0.5F) * lever};
        (void)readings.push_back(reading_past(c, view, rng.uniform(0.0F, 0.05F),
                                              rng.uniform(-3.14159F, 3.14159F),
                                              rng.uniform(1.1F, 2.0F)));
      }
    }
    mapping::FeatureGuardParams g;
    g.see_through_readings = 2;  // the test's angle: 0.02 rad
    std::size_t expected = 0;
    for (const mapping::GuardPoint& c : plain) {
      expected += seen_through_by_definition(readings, c, g) ? 1U : 0U;
    }
    CHECK(expected > 40 && expected < 360);  // the test has both kinds
    static std::array<std::uint32_t, 1200> scratch;
    LONGS_EQUAL(expected, mapping::drop_seen_through(readings, g, plain));
    LONGS_EQUAL(expected, mapping::drop_seen_through(readings, g, ordered, scratch));
    for (const mapping::GuardPoint& c : plain) {
      CHECK_FALSE(seen_through_by_definition(readings, c, g));
    }
    LONGS_EQUAL(plain.size(), ordered.size());
    for (std::size_t i = 0; i < plain.size(); ++i) {
      CHECK_EQUAL(plain[i].x_m, ordered[i].x_m);
    }
  }
}

// A scratch shorter than the readings cannot hold their pan order: nothing is written past its
// end, and the candidates dropped are the plain scan's.
TEST(FeatureGuard, AScratchShorterThanTheReadingsIsNotWrittenPastItsEndAndThePlainScanDecides) {
  FixedVector<Reading, 64> readings;
  boticelli::test::Random rng(61);
  GuardCandidatesFor<16> plain;
  for (int k = 0; k < 16; ++k) {
    const mapping::GuardPoint c =
        candidate_at(rng.uniform(-3.0F, 3.0F), rng.uniform(0.5F, 2.5F), rng.uniform(-0.5F, 0.2F));
    (void)plain.push_back(c);
    for (int j = 0; j < (k % 2 == 0 ? 3 : 1); ++j) {
      (void)readings.push_back(reading_past(c, {0.0F, 0.0F, 0.0F}, 0.005F, 0.0F, 1.5F));
    }
  }
  mapping::FeatureGuardParams g;
  g.see_through_readings = 2;
  for (const std::size_t size : {std::size_t{0}, readings.size() / 2, readings.size() - 1}) {
    GuardCandidatesFor<16> ordered;
    GuardCandidatesFor<16> candidates = plain;
    for (const mapping::GuardPoint& c : plain) (void)ordered.push_back(c);
    std::array<std::uint32_t, 64> buffer{};
    buffer.fill(0xDEADBEEFU);
    const std::size_t dropped = mapping::drop_seen_through(readings, g, candidates);
    LONGS_EQUAL(8, dropped);
    LONGS_EQUAL(dropped,
                mapping::drop_seen_through(readings, g, ordered, std::span(buffer).first(size)));
    for (const std::uint32_t v : buffer) CHECK_EQUAL(0xDEADBEEFU, v);
    LONGS_EQUAL(candidates.size(), ordered.size());
    for (std::size_t i = 0; i < candidates.size(); ++i) {
      CHECK_EQUAL(candidates[i].x_m, ordered[i].x_m);
    }
  }
}
