// Tests of the LocalModelBuilder (one look's Think stage) on synthetic readings of a round room
// with a plain box only the floor cue reports.
#include <algorithm>
#include <cmath>
#include <initializer_list>
#include <cstddef>
#include <cstdio>
#include <span>

#include "algo/core/angles.h"
#include "algo/core/fixed_vector.h"
#include "algo/core/geometry.h"
#include "algo/evidence/occupancy_model.h"
#include "algo/evidence/reading.h"
#include "algo/evidence/reading_limits.h"
#include "algo/mapping/local_model_builder.h"
#include "algo/mapping/star_polygon.h"

#include "CppUTest/TestHarness.h"
#include "alloc_guard.h"

using boticelli::core::FixedVector;
using boticelli::core::Point2;
using boticelli::evidence::Reading;
namespace mapping = boticelli::mapping;
namespace evidence = boticelli::evidence;

namespace {

// The board's choices (firmware/board.h, firmware/mission/params/mission_params.cpp).
constexpr float kPtuHeight_m = 0.6F;
constexpr float kRobotRadius_m = 0.25F;
constexpr float kRobotHeight_m = 0.8F;
constexpr float kMargin_m = 0.05F;
constexpr float kGroundClearance_m = 0.03F;

// The room: a round wall of radius 2.5 m about the robot; a plain 0.5 m cube whose front
// face is 1.5 m away at pan 90° (x ∈ [−0.25, 0.25], y ∈ [1.5, 2.0]). A second look of the
// same room has no readings at all in the pan sector [200°, 230°] (nothing seen there).
// Also a table at pan 330°: its top (0.65–0.7 m above the floor, below the robot's top) from
// 1.2 to 1.8 m, 0.8 m wide, no legs; the stereo sees its front edge, the floor cue the floor
// under it. And a thin chair leg (radius 8 mm) 1.0 m away at pan 30°, that the floor cue
// reports weakly (m = 0.45) in one column while the next column, 0.45° on and in the same
// polygon sector, sees the floor past it up to the wall.
constexpr float kWall_m = 2.5F;
constexpr float kBoxNear_m = 1.5F;
constexpr float kBoxFar_m = 2.0F;
constexpr float kBoxHalfWidth_m = 0.25F;
constexpr float kBoxHeight_m = 0.5F;
constexpr float kGapFirst_deg = 200.0F;
constexpr float kGapLast_deg = 230.0F;
constexpr float kTableAt_deg = 330.0F;
constexpr float kTableNear_m = 1.2F;
constexpr float kTableFar_m = 1.8F;
constexpr float kTableHalfWidth_m = 0.4F;
constexpr float kTableUnder_m = 0.65F;
constexpr float kTableTop_m = 0.7F;
constexpr float kLegAt_deg = 30.0F;
constexpr float kLegNear_m = 1.0F;
constexpr float kLegRadius_m = 0.008F;

mapping::LocalModelParams make_params() {
  mapping::LocalModelParams m;
  const evidence::ReadingLimits limits = evidence::make_reading_limits(kPtuHeight_m, 2.5F, 4.5F);
  const evidence::ModelBox box = evidence::model_box(limits, evidence::ray_sample_reach(m.rays));
  m.model_lowest_h_m = box.lowest_h_m;
  m.model_highest_h_m = box.highest_h_m;
  m.model_max_range_m = box.max_range_m;
  m.seam_margin_rad = evidence::kSeamMarginRad;
  mapping::ExtractionParams& e = m.extraction;
  e.ptu_height_m = kPtuHeight_m;
  e.lowest_height_m = kGroundClearance_m;
  e.robot_height_m = kRobotHeight_m;
  e.robot_radius_m = kRobotRadius_m;
  e.clearance_margin_m = kMargin_m;
  e.height_count = 5;
  e.bounding_radius_m = 3.0F;
  m.trainer.epsilon = 0.15;
  m.trainer.max_iterations = 10;
  m.trainer.max_pieces = mapping::kLookMaxPieces;
  return m;
}

float deg(float d) {
  return boticelli::core::deg_to_rad(d);
}

// At least `away_deg` from the leg, the box and the table (centres at 30°, 90°, 330°).
bool in_open(float alpha_deg, float away_deg) {
  return alpha_deg >= kLegAt_deg + away_deg && std::fabs(alpha_deg - 90.0F) >= away_deg &&
         alpha_deg <= kTableAt_deg - away_deg;
}

// Horizontal distance [m] at pan α to the box's front face, or 0 if the ray misses it.
float box_front_m(float alpha_rad) {
  const float s = std::sin(alpha_rad);
  if (s <= 0.0F) return 0.0F;
  const float rho = kBoxNear_m / s;
  const float x = rho * std::cos(alpha_rad);
  return std::fabs(x) <= kBoxHalfWidth_m ? rho : 0.0F;
}

// Horizontal distance [m] at pan α to the table's front edge, or 0 if the ray misses it.
float table_front_m(float alpha_rad) {
  const float d = alpha_rad - deg(kTableAt_deg);
  if (std::cos(d) <= 0.0F) return 0.0F;
  return std::fabs(kTableNear_m * std::tan(d)) <= kTableHalfWidth_m ? kTableNear_m / std::cos(d)
                                                                    : 0.0F;
}

// Distance [m] from p to the table's footprint (0 beneath it).
float distance_to_table_m(Point2 p) {
  const float c = std::cos(deg(kTableAt_deg));
  const float s = std::sin(deg(kTableAt_deg));
  const float u = c * p.x_m + s * p.y_m;
  const float v = -s * p.x_m + c * p.y_m;
  const float du = std::max({kTableNear_m - u, u - kTableFar_m, 0.0F});
  const float dv = std::max(std::fabs(v) - kTableHalfWidth_m, 0.0F);
  return std::hypot(du, dv);
}

// Distance [m] from p to the leg.
float distance_to_leg_m(Point2 p) {
  const float centre_m = kLegNear_m + kLegRadius_m;
  return std::hypot(p.x_m - centre_m * std::cos(deg(kLegAt_deg)),
                    p.y_m - centre_m * std::sin(deg(kLegAt_deg))) -
         kLegRadius_m;
}

// A reading of the point at pan α, horizontal distance ρ, height z above the floor.
Reading at(float alpha_rad, float rho_m, float z_m, float m) {
  const float h = z_m - kPtuHeight_m;
  return {alpha_rad, h, std::sqrt(rho_m * rho_m + h * h), m};
}

// Distance [m] from p (floor plane) to the box's footprint (0 inside).
float distance_to_box_m(Point2 p) {
  const float dx = std::max(std::fabs(p.x_m) - kBoxHalfWidth_m, 0.0F);
  const float dy = std::max({kBoxNear_m - p.y_m, p.y_m - kBoxFar_m, 0.0F});
  return std::hypot(dx, dy);
}

struct Look {
  FixedVector<Reading, 4096> features;
  FixedVector<Reading, 2048> obstacles;
  FixedVector<Reading, 512> free;
};

// An empty look to fill, shared by the tests that build their own (one at a time).
Look& empty_look() {
  static Look look;
  look.features.clear();
  look.obstacles.clear();
  look.free.clear();
  return look;
}

// One look from the room's centre: stereo features on the wall at six heights every degree
// (m = 0.9; the box, plain, gives none, and hides the wall's low part behind it); the floor
// cue's obstacle readings at the base of the wall or the box (0.05, 0.2, 0.4 m above the
// floor, m = 0.9) and its free readings on the floor just short of that base (m = 0).
// Nothing at all in the pan sector [gap_first_deg, gap_last_deg] (none if first > last).
void build_look(Look& look, float gap_first_deg, float gap_last_deg) {
  constexpr float kWallHeights_m[] = {0.1F, 0.3F, 0.6F, 0.9F, 1.2F, 1.6F};
  constexpr float kBaseHeights_m[] = {0.05F, 0.2F, 0.4F};
  for (int d = 0; d < 360; ++d) {
    const auto alpha_deg = static_cast<float>(d);
    if (alpha_deg >= gap_first_deg && alpha_deg <= gap_last_deg) continue;
    const float alpha = deg(alpha_deg);
    const float box = box_front_m(alpha);
    const float table = table_front_m(alpha);
    const bool leg = d == static_cast<int>(kLegAt_deg);
    for (const float z : kWallHeights_m) {
      // Line of sight to the wall at height z: its height at horizontal distance ρ.
      const auto sight = [z](float rho) {
        return kPtuHeight_m + (z - kPtuHeight_m) * rho / kWall_m;
      };
      // Hidden by the box if below its top where it meets the front face; by the table top
      // if it crosses the top's slab; by the leg (0.7 m tall) if below its top.
      const bool hidden =
          (box > 0.0F && sight(box) < kBoxHeight_m) ||
          (table > 0.0F &&
           std::max(sight(table), sight(table * kTableFar_m / kTableNear_m)) >= kTableUnder_m &&
           std::min(sight(table), sight(table * kTableFar_m / kTableNear_m)) <= kTableTop_m) ||
          (leg && z < 0.7F);
      if (!hidden) (void)look.features.push_back(at(alpha, kWall_m, z, 0.9F));
    }
    if (table > 0.0F) {
      for (const float z : {kTableUnder_m, 0.5F * (kTableUnder_m + kTableTop_m), kTableTop_m}) {
        (void)look.features.push_back(at(alpha, table, z, 0.9F));
      }
    }
    const float base = box > 0.0F ? box : leg ? kLegNear_m : kWall_m;
    const float m = leg ? 0.45F : 0.9F;
    for (const float z : kBaseHeights_m) (void)look.obstacles.push_back(at(alpha, base, z, m));
    (void)look.free.push_back(at(alpha, base - 0.03F, 0.0F, 0.0F));
    if (leg) (void)look.free.push_back(at(deg(alpha_deg + 0.45F), kWall_m - 0.03F, 0.0F, 0.0F));
  }
}

// The looks and their built models, made once and read by several tests. Several MB each:
// static.
Look g_look;
Look g_gap_look;
mapping::LocalModelBuilder g_builder;
mapping::LocalModelBuilder g_gap_builder;
mapping::LocalModelBuilder g_other;  // re-runs

const mapping::LocalModelBuilder& build_once(mapping::LocalModelBuilder& b, Look& look,
                                             float gap_first_deg, float gap_last_deg) {
  if (!b.done()) {
    build_look(look, gap_first_deg, gap_last_deg);
    b.start(make_params(), look.features.span(), look.obstacles.span(), look.free.span());
    b.run();
  }
  return b;
}
const mapping::LocalModelBuilder& built() {
  return build_once(g_builder, g_look, 1.0F, 0.0F);
}
// A look with two image columns missing (pan 150° and 151°): a gap narrower than
// LocalModelBuilder's kMaxGap (3 vertices).
Look g_narrow_look;
mapping::LocalModelBuilder g_narrow_builder;
const mapping::LocalModelBuilder& built_with_narrow_gap() {
  return build_once(g_narrow_builder, g_narrow_look, 150.0F, 151.0F);
}
const mapping::LocalModelBuilder& built_with_gap() {
  return build_once(g_gap_builder, g_gap_look, kGapFirst_deg, kGapLast_deg);
}

float vertex_deg(const mapping::StarPolygon& p, std::size_t k) {
  return boticelli::core::rad_to_deg(p.angle_rad(k));
}

}  // namespace

TEST_GROUP(LocalModelBuilder){};

TEST(LocalModelBuilder, FitsAModelOfTheRoomAndCanMove) {
  const mapping::LocalModelBuilder& b = built();
  CHECK(b.done());
  CHECK(b.stats().model_valid);
  CHECK(b.stats().pieces > 1);
  CHECK(b.stats().samples > 0);
  CHECK(b.map().can_move);
}

// The box, the wall and the table top keep the robot radius plus the margin; the thin leg,
// which can reach between two vertex rays, at least the robot radius (the margin is for that).
TEST(LocalModelBuilder, NoNavigablePointBringsTheRobotsDiscNearAnObstacle) {
  const mapping::LocalModelBuilder& b = built();
  const mapping::StarPolygon& nav = b.map().navigable;
  const float keep_m = kRobotRadius_m + kMargin_m;
  float worst_box_m = 1e9F;
  float worst_wall_m = 1e9F;
  float worst_table_m = 1e9F;
  float worst_leg_m = 1e9F;
  // Every point of the star polygon lies on a ray from the centre below radius_at_m(θ).
  for (int i = 0; i < 360 * 8; ++i) {
    const float theta = deg(static_cast<float>(i) / 8.0F);
    const float reach = nav.radius_at_m(theta);
    for (float s = 0.0F; s <= reach; s += 0.005F) {
      const Point2 p{s * std::cos(theta), s * std::sin(theta)};
      worst_box_m = std::min(worst_box_m, distance_to_box_m(p));
      worst_wall_m = std::min(worst_wall_m, kWall_m - std::hypot(p.x_m, p.y_m));
      worst_table_m = std::min(worst_table_m, distance_to_table_m(p));
      worst_leg_m = std::min(worst_leg_m, distance_to_leg_m(p));
    }
    const Point2 edge{reach * std::cos(theta), reach * std::sin(theta)};
    worst_box_m = std::min(worst_box_m, distance_to_box_m(edge));
    worst_wall_m = std::min(worst_wall_m, kWall_m - std::hypot(edge.x_m, edge.y_m));
    worst_table_m = std::min(worst_table_m, distance_to_table_m(edge));
    worst_leg_m = std::min(worst_leg_m, distance_to_leg_m(edge));
  }
  std::printf(
      "\n  nearest navigable point: %.3f m from the box, %.3f m from the wall, %.3f m from the "
      "table, %.3f m from the leg\n",
      static_cast<double>(worst_box_m), static_cast<double>(worst_wall_m),
      static_cast<double>(worst_table_m), static_cast<double>(worst_leg_m));
  CHECK_TEXT(worst_box_m >= keep_m - 1e-4F, "the robot's disc (radius + margin) reaches the box");
  CHECK_TEXT(worst_wall_m >= keep_m - 1e-4F, "the robot's disc (radius + margin) reaches the wall");
  CHECK_TEXT(worst_table_m >= keep_m - 1e-4F,
             "the robot's disc (radius + margin) reaches the table");
  CHECK_TEXT(worst_leg_m >= kRobotRadius_m, "the robot's disc reaches the leg");
}

TEST(LocalModelBuilder, TheFreePolygonReachesCloseToTheWallInOpenDirections) {
  const mapping::LocalModelBuilder& b = built();
  const mapping::StarPolygon& free = b.map().free;
  const mapping::StarPolygon& nav = b.map().navigable;
  float least_free_m = 1e9F;
  float least_nav_m = 1e9F;
  for (std::size_t k = 0; k < free.vertex_count(); ++k) {
    // The free polygon 30° from the obstacles; the navigable one 45° (the disc's straight
    // path from the centre sweeps past an obstacle's corner at a wider angle).
    const float d = vertex_deg(free, k);
    if (in_open(d, 30.0F)) least_free_m = std::min(least_free_m, free.rho_m(k));
    if (in_open(d, 45.0F)) least_nav_m = std::min(least_nav_m, nav.rho_m(k));
  }
  std::printf("\n  open directions: free ρ ≥ %.3f m, navigable ρ ≥ %.3f m\n",
              static_cast<double>(least_free_m), static_cast<double>(least_nav_m));
  CHECK(least_free_m >= 1.8F);
  CHECK(least_nav_m >= 1.5F);
}

TEST(LocalModelBuilder, TheFreePolygonStopsInFrontOfTheBoxTheStereoDoesNotSee) {
  const mapping::LocalModelBuilder& b = built();
  const mapping::StarPolygon& free = b.map().free;
  for (std::size_t k = 0; k < free.vertex_count(); ++k) {
    const float box = box_front_m(free.angle_rad(k));
    if (box > 0.0F) CHECK(free.rho_m(k) <= box);
  }
  // Straight at the box: the navigable polygon keeps the disc and the margin off it.
  CHECK(b.map().navigable.radius_at_m(deg(90.0F)) <= kBoxNear_m - kRobotRadius_m - kMargin_m);
}

TEST(LocalModelBuilder, ADirectionWithNoReadingsIsNotFree) {
  const mapping::LocalModelBuilder& b = built_with_gap();
  const mapping::StarPolygon& free = b.map().free;
  float most_m = 0.0F;
  for (std::size_t k = 0; k < free.vertex_count(); ++k) {
    const float d = vertex_deg(free, k);
    if (d >= kGapFirst_deg + 5.0F && d <= kGapLast_deg - 5.0F) {
      most_m = std::max(most_m, free.rho_m(k));
    }
  }
  std::printf("\n  unseen sector: free ρ ≤ %.3f m\n", static_cast<double>(most_m));
  // At most the robot's own disc (it stands there) and a little.
  CHECK(most_m <= kRobotRadius_m + kMargin_m + 0.05F);
  CHECK(b.map().navigable.radius_at_m(deg(0.5F * (kGapFirst_deg + kGapLast_deg))) <= 0.05F);
}

TEST(LocalModelBuilder, ANarrowGapBetweenImageColumnsTakesItsNeighboursRange) {
  const mapping::LocalModelBuilder& b = built_with_narrow_gap();
  const mapping::StarPolygon& seen = b.seen_free();
  const float neighbours_m = std::min(seen.rho_m(149), seen.rho_m(152));
  CHECK(neighbours_m > 2.0F);
  DOUBLES_EQUAL(neighbours_m, seen.rho_m(150), 1e-6);
  DOUBLES_EQUAL(neighbours_m, seen.rho_m(151), 1e-6);
  CHECK(b.map().free.rho_m(150) > 1.8F);
}

// Before e831061 the unseen sector's vertices had ρ = 0 in the seen-free polygon: the free
// polygon's boundary ran through the robot's centre, the shrink found no clearance and the
// whole look said "cannot move". Now the robot's own disc counts as seen free: it can move,
// though only away from the unknown (a disc moving sideways would sweep into it).
TEST(LocalModelBuilder, AnUnseenSectorDoesNotStopTheRobotFromMovingAwayFromIt) {
  const mapping::LocalModelBuilder& b = built_with_gap();
  CHECK_TEXT(b.map().can_move, "one unseen sector made the whole look immovable");
  const mapping::StarPolygon& nav = b.map().navigable;
  // Between the leg, the box and the table, on the far side from the gap (200°–230°).
  CHECK(nav.radius_at_m(deg(10.0F)) >= 1.5F);
  CHECK(nav.radius_at_m(deg(60.0F)) >= 1.5F);
}

TEST(LocalModelBuilder, SteppingInSmallSlicesGivesTheSamePolygonAsOneShot) {
  const mapping::LocalModelBuilder& reference = built();  // default units, by run()
  mapping::LocalModelParams params = make_params();
  params.readings_per_unit = 7;
  params.visits_per_unit = 333;
  g_other.start(params, g_look.features.span(), g_look.obstacles.span(), g_look.free.span());
  std::size_t units = 0;
  while (!g_other.run_unit()) ++units;
  CHECK(units > reference.stats().units);  // it did take more, smaller units
  const mapping::LocalMap& a = reference.map();
  const mapping::LocalMap& c = g_other.map();
  UNSIGNED_LONGS_EQUAL(a.free.vertex_count(), c.free.vertex_count());
  UNSIGNED_LONGS_EQUAL(reference.stats().pieces, g_other.stats().pieces);
  for (std::size_t k = 0; k < a.free.vertex_count(); ++k) {
    DOUBLES_EQUAL(a.free.rho_m(k), c.free.rho_m(k), 1e-6);
    DOUBLES_EQUAL(a.navigable.rho_m(k), c.navigable.rho_m(k), 1e-6);
  }
  CHECK(a.can_move == c.can_move);
}

TEST(LocalModelBuilder, StartingAndSteppingDoNotAllocate) {
  (void)built();
  const mapping::LocalModelParams params = make_params();
  CHECK_NO_ALLOCATION({
    g_other.start(params, g_look.features.span(), g_look.obstacles.span(), g_look.free.span());
    while (!g_other.run_unit()) {
    }
  });
  CHECK(g_other.done());
  CHECK(g_other.map().can_move);
}

namespace {
// Runs g_other on a look of only the floor cue's reports: weak bases (m = 0.5) 0.05 m above
// the floor, one a degree on a ring at each of `rings` [m], and the floor seen free up to
// 1.97 m.
void run_on_base_rings(std::initializer_list<float> rings) {
  Look& look = empty_look();
  for (int d = 0; d < 360; ++d) {
    const float alpha = deg(static_cast<float>(d));
    for (const float rho : rings) (void)look.obstacles.push_back(at(alpha, rho, 0.05F, 0.5F));
    (void)look.free.push_back(at(alpha, 1.97F, 0.0F, 0.0F));
  }
  g_other.start(make_params(), look.features.span(), look.obstacles.span(), look.free.span());
  g_other.run();
}
}  // namespace

TEST(LocalModelBuilder, TheFloorCuesBasesRightAtTheFloorAreGuardCandidates) {
  // Only the floor cue's reports, 0.05 m above the floor (on the floor's line of sight within
  // 2 δr, where stereo features are not candidates) and weak (m = 0.5: their ray samples
  // plateau below m_safe, so the fit never holds them): every one is a guard candidate.
  run_on_base_rings({2.0F});
  UNSIGNED_LONGS_EQUAL(360, g_other.stats().guard_candidates);
}

TEST(LocalModelBuilder, AFloorCueBaseCutsTheFreePolygonItsMarginInFrontOfIt) {
  // A featured wall 3.5 m away all round (the fit's crossing beyond 2 m), weak bases (m = 0.5,
  // which never lift the fit to m_safe) on a ring 2 m away and the floor seen to 1.97 m: the
  // bases' own cut, base_margin_m in front of them, is the nearest.
  Look& look = empty_look();
  for (int d = 0; d < 360; ++d) {
    const float alpha = deg(static_cast<float>(d));
    for (const float z : {0.1F, 0.4F, 0.9F, 1.4F}) {
      (void)look.features.push_back(at(alpha, 3.5F, z, 0.9F));
    }
    (void)look.obstacles.push_back(at(alpha, 2.0F, 0.05F, 0.5F));
    (void)look.free.push_back(at(alpha, 1.97F, 0.0F, 0.0F));
  }
  const mapping::LocalModelParams params = make_params();
  g_other.start(params, look.features.span(), look.obstacles.span(), look.free.span());
  g_other.run();
  CHECK(g_other.stats().model_valid);
  const mapping::StarPolygon& free = g_other.map().free;
  const float cut_m = 2.0F - params.base_margin_m;
  float nearest_m = 3.0F;
  for (std::size_t k = 0; k < free.vertex_count(); ++k) {
    CHECK(free.rho_m(k) <= cut_m + 1e-4F);
    nearest_m = std::min(nearest_m, free.rho_m(k));
  }
  std::printf("\n  bases: free ρ from %.3f m\n", static_cast<double>(nearest_m));
  // Not vacuous: the polygon reaches the cut all round.
  CHECK(nearest_m > cut_m - 0.01F);
}

TEST(LocalModelBuilder, WithoutWalkStartsAFloorCueBaseShowsTheFloorBeforeItLessItsRangeError) {
  // Only bases, on a ring 2 m away, and no free floor readings: the floor is seen up to each
  // base less δr (δr = 0.1 r).
  Look& look = empty_look();
  for (int d = 0; d < 360; ++d) {
    (void)look.obstacles.push_back(at(deg(static_cast<float>(d)), 2.0F, 0.05F, 0.9F));
  }
  const mapping::LocalModelParams params = make_params();
  g_other.start(params, look.features.span(), look.obstacles.span(), look.free.span());
  g_other.run();
  const Reading base = at(deg(100.0F), 2.0F, 0.05F, 0.9F);
  const float seen_m = evidence::horizontal_m(base) * (1.0F - params.rays.delta_r_fraction);
  DOUBLES_EQUAL(seen_m, g_other.seen_free().radius_at_m(deg(100.0F)), 1e-3);
}

TEST(LocalModelBuilder, TheFreeSamplesOfAFloorPointLieOnItsLineOfSightShortOfIt) {
  // One floor point seen free, away from the seam: the fit's samples are the line of sight's
  // free samples, every one short of the point (none on or under the floor).
  Look& look = empty_look();
  const Reading floor = at(1.0F, 2.0F, 0.0F, 0.0F);
  (void)look.free.push_back(floor);
  const mapping::LocalModelParams params = make_params();
  g_other.start(params, look.features.span(), look.obstacles.span(), look.free.span());
  g_other.run();
  const std::span<const mapping::OccupancySample> samples = g_other.samples();
  UNSIGNED_LONGS_EQUAL(params.free_samples_per_ray, samples.size());
  for (const mapping::OccupancySample& s : samples) {
    DOUBLES_EQUAL(floor.alpha_rad, s.x(0), 1e-6);
    CHECK(s.x(2) > 0.0F);
    CHECK(s.x(2) < floor.r_m);
    DOUBLES_EQUAL(floor.h_m / floor.r_m, s.x(1) / s.x(2), 1e-5);
    DOUBLES_EQUAL(0.0, s.y, 0.0);
  }
}

TEST(LocalModelBuilder, TheGuardKeepsOnlyThePointsThatCanCutThePolygon) {
  // Bases on two rings, 2 m and 2.5 m away: all are corroborated guard points, but behind the
  // near ring the far one cuts nothing and is no ray's nearest.
  run_on_base_rings({2.0F, 2.5F});
  UNSIGNED_LONGS_EQUAL(720, g_other.stats().guard_corroborated);
  UNSIGNED_LONGS_EQUAL(360, g_other.stats().guard_points);
}

// A shelf (its front edge 1.5 m away, 0.45-0.55 m above the floor, below the robot's top) seen
// by the stereo only with m = 0.5 in one sector: below m_safe, so its ray samples plateau at
// 0.5 and the fit alone never reaches 0.6 there. The floor cue sees the floor free beneath it
// up to the wall behind. Only the guard's weak readings stand between the robot and the shelf:
// the robot must still not be let under it.
TEST(LocalModelBuilder, AShelfSeenOnlyWithLowEvidenceIsNotDrivenUnder) {
  Look& look = empty_look();
  constexpr float kWeakFirst_deg = 120.0F;
  constexpr float kWeakLast_deg = 180.0F;
  constexpr float kShelf_m = 1.5F;
  constexpr float kHeights_m[] = {0.1F, 0.3F, 0.6F, 0.9F, 1.2F, 1.6F};
  for (int d = 0; d < 360; ++d) {
    const auto alpha_deg = static_cast<float>(d);
    const float alpha = deg(alpha_deg);
    const bool shelf = alpha_deg >= kWeakFirst_deg && alpha_deg <= kWeakLast_deg;
    for (const float z : kHeights_m) {
      (void)look.features.push_back(at(alpha, kWall_m, z, 0.9F));
    }
    if (shelf) {
      for (const float z : {0.45F, 0.5F, 0.55F}) {
        for (const float da : {0.0F, 0.33F, 0.67F}) {
          (void)look.features.push_back(at(deg(alpha_deg + da), kShelf_m, z, 0.5F));
        }
      }
    }
    for (const float z : {0.05F, 0.2F, 0.4F}) {
      (void)look.obstacles.push_back(at(alpha, kWall_m, z, 0.9F));
    }
    (void)look.free.push_back(at(alpha, kWall_m - 0.03F, 0.0F, 0.0F));
  }
  g_other.start(make_params(), look.features.span(), look.obstacles.span(), look.free.span());
  g_other.run();
  CHECK(g_other.map().can_move);
  const mapping::StarPolygon& nav = g_other.map().navigable;
  float worst_m = 1e9F;
  for (float a = kWeakFirst_deg; a <= kWeakLast_deg; a += 0.25F) {
    worst_m = std::min(worst_m, kShelf_m - nav.radius_at_m(deg(a)));
  }
  // The robot's disc stays off the shelf's edge.
  CHECK_TEXT(worst_m >= kRobotRadius_m, "a navigable point puts the robot under the weak shelf");
}

// A look with the floor cue's walks: their far ends and, in step, where each began.
struct WalkedLook {
  Look look;
  FixedVector<Reading, 1024> free;
  FixedVector<float, 1024> near_m;
};

// The one shared WalkedLook, emptied.
WalkedLook& walked_look() {
  static WalkedLook w;
  w.look.features.clear();
  w.look.obstacles.clear();
  w.look.free.clear();
  w.free.clear();
  w.near_m.clear();
  return w;
}

// A plain low box (0.3 m tall, front 1.0 m away, pan 60°–90°) that neither the stereo nor the
// floor cue's appearance test sees: the low view's walks there end at its front (their
// floor stops), and a high view's walks, whose bottom row already lies beyond the box, see
// the floor behind it up to the wall. Only walks joined to the robot show floor free, so the
// free polygon stops at the box; counting every walk's far end (no walk starts given) lets
// it through. The wall's features in the sector lie above the robot's band (they show
// nothing about the floor).
TEST(LocalModelBuilder, AFloorWalkThatStartsBeyondAPlainBoxShowsNoFloorBeforeIt) {
  WalkedLook& w = walked_look();
  Look& look = w.look;
  auto& free = w.free;
  auto& near_m = w.near_m;
  constexpr float kBox_m = 1.0F;
  constexpr float kLowStart_m = 0.35F;
  constexpr float kHighStart_m = 1.7F;
  const auto boxed = [](int d) { return d >= 60 && d <= 90; };
  for (int d = 0; d < 360; ++d) {
    const float alpha = deg(static_cast<float>(d));
    for (const float z : {1.2F, 1.6F}) (void)look.features.push_back(at(alpha, kWall_m, z, 0.9F));
    if (!boxed(d)) {
      for (const float z : {0.1F, 0.4F}) {
        (void)look.features.push_back(at(alpha, kWall_m, z, 0.9F));
      }
      for (const float z : {0.05F, 0.2F, 0.4F}) {
        (void)look.obstacles.push_back(at(alpha, kWall_m, z, 0.9F));
      }
    }
    // The low view's walk: to the wall, or to the box's front.
    (void)free.push_back(at(alpha, (boxed(d) ? kBox_m : kWall_m) - 0.03F, 0.0F, 0.0F));
    (void)near_m.push_back(kLowStart_m);
    // The high view's walk, from beyond the box to the wall.
    (void)free.push_back(at(alpha, kWall_m - 0.03F, 0.0F, 0.0F));
    (void)near_m.push_back(kHighStart_m);
  }
  mapping::LocalModelParams params = make_params();
  params.seen_floor_start_m = 0.7F;
  const auto widest_over_box = [](const mapping::StarPolygon& polygon) {
    float widest = 0.0F;
    for (float a = 60.0F; a <= 90.0F; a += 0.25F) {
      widest = std::max(widest, polygon.radius_at_m(deg(a)));
    }
    return widest;
  };
  g_other.start(params, look.features.span(), look.obstacles.span(), free.span(), near_m.span());
  g_other.run();
  CHECK(g_other.map().can_move);
  CHECK_TEXT(widest_over_box(g_other.map().free) <= kBox_m,
             "the free polygon passes the box's front");
  // Away from the box the joined walks reach towards the wall (the fit's crossing, ~0.8 of it).
  CHECK(g_other.map().free.radius_at_m(deg(200.0F)) > kBox_m + 0.5F);
  // Without the walks' starts every far end counts: the polygon crosses the box.
  g_other.start(params, look.features.span(), look.obstacles.span(), free.span());
  g_other.run();
  CHECK(widest_over_box(g_other.map().free) > kBox_m + 0.5F);
}

TEST(LocalModelBuilder, AFeatureInTheBandShowsTheFloorBeforeItFreeOnlyWhenFeaturesShowFree) {
  WalkedLook& w = walked_look();
  Look& look = w.look;
  auto& free = w.free;
  auto& near_m = w.near_m;
  // A featured wall all round; the floor cue walked only the half 0–180°.
  for (int d = 0; d < 360; ++d) {
    const float alpha = deg(static_cast<float>(d));
    for (const float z : {0.1F, 0.4F}) (void)look.features.push_back(at(alpha, kWall_m, z, 0.9F));
    if (d < 180) {
      (void)free.push_back(at(alpha, kWall_m - 0.03F, 0.0F, 0.0F));
      (void)near_m.push_back(0.35F);
    }
  }
  mapping::LocalModelParams params = make_params();
  params.features_show_free = true;
  g_other.start(params, look.features.span(), look.obstacles.span(), free.span(), near_m.span());
  g_other.run();
  // The walked half is seen to the walks' ends either way; the other half only by features,
  // to 2 δr before them (δr = 0.1 r: 2.0 m of the wall's 2.5).
  CHECK(g_other.seen_free().radius_at_m(deg(90.0F)) > kWall_m - 0.1F);
  const float band_seen_m = kWall_m * (1.0F - 2.0F * params.rays.delta_r_fraction);
  DOUBLES_EQUAL(band_seen_m, g_other.seen_free().radius_at_m(deg(270.0F)), 1e-3);
  params.features_show_free = false;
  g_other.start(params, look.features.span(), look.obstacles.span(), free.span(), near_m.span());
  g_other.run();
  CHECK(g_other.seen_free().radius_at_m(deg(90.0F)) > kWall_m - 0.1F);
  // Unwalked: only the robot's own disc.
  CHECK(g_other.seen_free().radius_at_m(deg(270.0F)) < 0.5F);
  CHECK(g_other.map().free.radius_at_m(deg(270.0F)) < 0.5F);
}

// The blocked-walk tests: a featured wall all round at kWall_m, and the parameters with the
// lowest view's bottom row 0.78 m out (the sim board's).
void add_featured_wall(Look& look) {
  for (int d = 0; d < 360; ++d) {
    for (const float z : {0.1F, 0.4F}) {
      (void)look.features.push_back(at(deg(static_cast<float>(d)), kWall_m, z, 0.9F));
    }
  }
}
mapping::LocalModelParams blocked_walk_params() {
  mapping::LocalModelParams params = make_params();
  params.seen_floor_start_m = 0.78F;
  return params;
}

// A floor walk whose bottom row already shows no floor (FloorCue's kBlockedAtBottom): an
// obstacle stands somewhere between the robot's disc and that row, which no view sees. In
// the lowest view (its bottom row within seen_floor_start_m) its ray keeps only the robot's
// disc, unless a walk of another frame started on floor nearer than the blocked row; and it
// gives no map point (where the obstacle is, is not known).
TEST(LocalModelBuilder, AWalkBlockedAtTheLowestViewsBottomRowLeavesTheRobotOnlyItsDiscThatWay) {
  WalkedLook& w = walked_look();
  Look& look = w.look;
  FixedVector<Reading, 1024> blocked;
  add_featured_wall(look);
  for (int d = 0; d < 360; ++d) {
    const float alpha = deg(static_cast<float>(d));
    const bool low_blocked = (d >= 30 && d < 210) || (d >= 240 && d < 270);
    const bool high_blocked = d >= 300 && d < 330;
    if (low_blocked) (void)blocked.push_back(at(alpha, 0.6F, 0.0F, 0.5F));
    if (high_blocked) (void)blocked.push_back(at(alpha, 1.7F, 0.0F, 0.5F));
    // Walks everywhere but where the low view is blocked; at 240-270° another frame's
    // walk starts at 0.35 m, nearer than the blocked row, and ends before a box at 1.2 m.
    if (!(d >= 30 && d < 210)) {
      (void)w.free.push_back(at(alpha, d >= 240 && d < 270 ? 1.2F : kWall_m - 0.03F, 0.0F, 0.0F));
      (void)w.near_m.push_back(0.35F);
    }
  }
  mapping::LocalModelParams params = blocked_walk_params();
  const float own = kRobotRadius_m + kMargin_m;
  g_other.start(params, look.features.span(), look.obstacles.span(), w.free.span(), w.near_m.span(),
                blocked.span());
  CHECK_NO_ALLOCATION(g_other.run());
  const mapping::StarPolygon& free = g_other.map().free;
  for (const float d : {32.0F, 90.0F, 150.0F, 207.0F}) {
    CHECK(free.radius_at_m(deg(d)) < own + 0.05F);
  }
  CHECK(g_other.stats().blocked_rays >= 170U);
  CHECK(free.radius_at_m(deg(255.0F)) > 1.0F);  // a nearer walk saw the floor there
  CHECK(free.radius_at_m(deg(315.0F)) > 1.5F);  // a higher view's bottom row: nothing said
  CHECK(free.radius_at_m(deg(0.0F)) > 1.5F);
  // No map point on the blocked rays (half a circle at the disc's edge, wide enough to be
  // a frontier): where the obstacle is, is not known, and it is nowhere to explore.
  FixedVector<Point2, 2048> obstacles;
  FixedVector<Point2, 2048> exploration;
  CHECK(g_other.map_points(mapping::MapPointParams{}, obstacles, exploration));
  for (const FixedVector<Point2, 2048>* list : {&obstacles, &exploration}) {
    for (const Point2& p : *list) {
      float a = std::atan2(p.y_m, p.x_m) * 57.29578F;
      if (a < 0.0F) a += 360.0F;
      CHECK_TEXT(!(a > 31.0F && a < 209.0F), "a map point on a blocked ray");
    }
  }
  // Without the blocked walks the rays are open to the fit and the features.
  g_other.start(params, look.features.span(), look.obstacles.span(), w.free.span(),
                w.near_m.span());
  g_other.run();
  CHECK(g_other.map().free.radius_at_m(deg(90.0F)) > 1.0F);
  CHECK_EQUAL(0U, g_other.stats().blocked_rays);
  params.close_blocked_rays = false;
  g_other.start(params, look.features.span(), look.obstacles.span(), w.free.span(), w.near_m.span(),
                blocked.span());
  g_other.run();
  CHECK(g_other.map().free.radius_at_m(deg(90.0F)) > 1.0F);
  CHECK_EQUAL(0U, g_other.stats().blocked_rays);
}

// A blocked walk whose ray, or one of the two either side, holds evidence of an obstacle
// before the blocked row (here a lone feature, too few to move the fit or to be corroborated
// as a guard point): that is what blocks it, and the ray is cut at it, not at the robot's
// disc.
TEST(LocalModelBuilder, ABlockedWalkWithEvidenceBeforeItsRowIsCutAtTheEvidence) {
  WalkedLook& w = walked_look();
  Look& look = w.look;
  FixedVector<Reading, 1024> blocked;
  add_featured_wall(look);
  for (int d = 0; d < 360; ++d) {
    const float alpha = deg(static_cast<float>(d));
    if (d >= 30 && d < 90) {
      (void)blocked.push_back(at(alpha, 0.6F, 0.0F, 0.5F));
    } else {
      (void)w.free.push_back(at(alpha, kWall_m - 0.03F, 0.0F, 0.0F));
      (void)w.near_m.push_back(0.35F);
    }
  }
  (void)look.features.push_back(at(deg(60.0F), 0.55F, 0.3F, 0.9F));
  mapping::LocalModelParams params = blocked_walk_params();
  const float own = kRobotRadius_m + kMargin_m;
  g_other.start(params, look.features.span(), look.obstacles.span(), w.free.span(), w.near_m.span(),
                blocked.span());
  CHECK_NO_ALLOCATION(g_other.run());
  const mapping::StarPolygon& free = g_other.map().free;
  for (const float d : {58.0F, 60.0F, 62.0F}) {
    DOUBLES_EQUAL(0.55F, free.radius_at_m(deg(d)), 0.01);
  }
  for (const float d : {40.0F, 56.0F, 64.0F, 80.0F}) {
    CHECK(free.radius_at_m(deg(d)) < own + 0.05F);
  }
}

// Without evidence, a blocked ray keeps what an earlier look saw free of it (the prior: the
// obstacle stands still, so it stands beyond), up to the blocked row: here the earlier look
// stood 0.2 m behind this one, both at heading 0.5 rad, and its free polygon is a disc of
// 0.7 m. Without the prior the rays keep only the robot's disc; the rays stay without map
// points either way.
TEST(LocalModelBuilder, ABlockedRayKeepsWhatAnEarlierLookSawFreeOfIt) {
  WalkedLook& w = walked_look();
  Look& look = w.look;
  FixedVector<Reading, 1024> blocked;
  add_featured_wall(look);
  constexpr float kRow_m = 0.6F;
  for (int d = 0; d < 360; ++d) {
    const float alpha = deg(static_cast<float>(d));
    if (d >= 30 && d < 150) {
      (void)blocked.push_back(at(alpha, kRow_m, 0.0F, 0.5F));
    } else {
      (void)w.free.push_back(at(alpha, kWall_m - 0.03F, 0.0F, 0.0F));
      (void)w.near_m.push_back(0.35F);
    }
  }
  static mapping::StarPolygon prior_free(mapping::kDefaultPolygonVertices);
  prior_free.fill(0.7F);
  mapping::PriorLook prior;
  prior.free = &prior_free;
  prior.here = {2.0F, 1.0F, 0.5F};
  prior.pose = {2.0F - 0.2F * std::cos(0.5F), 1.0F - 0.2F * std::sin(0.5F), 0.5F};
  // Where the ray at α leaves the prior's disc: its centre is 0.2 m behind, at (-0.2, 0).
  auto leaves_m = [](float alpha) {
    const float b = 0.2F * std::cos(alpha);
    return -b + std::sqrt(b * b - 0.04F + 0.49F);
  };
  mapping::LocalModelParams params = blocked_walk_params();
  const float own = kRobotRadius_m + kMargin_m;
  g_other.start(params, look.features.span(), look.obstacles.span(), w.free.span(), w.near_m.span(),
                blocked.span(), prior);
  CHECK_NO_ALLOCATION(g_other.run());
  const mapping::StarPolygon& free = g_other.map().free;
  for (const float d : {35.0F, 50.0F, 60.0F}) {
    const float expected = leaves_m(deg(d));
    CHECK(expected < kRow_m);
    DOUBLES_EQUAL(expected - 0.01F, free.radius_at_m(deg(d)), 0.012);
  }
  for (const float d : {100.0F, 145.0F}) {  // the disc reaches past the blocked row
    CHECK(leaves_m(deg(d)) > kRow_m);
    DOUBLES_EQUAL(kRow_m - 0.01F, free.radius_at_m(deg(d)), 0.012);
  }
  CHECK(g_other.stats().blocked_by_prior >= 110U);
  FixedVector<Point2, 2048> obstacles;
  FixedVector<Point2, 2048> exploration;
  CHECK(g_other.map_points(mapping::MapPointParams{}, obstacles, exploration));
  for (const FixedVector<Point2, 2048>* list : {&obstacles, &exploration}) {
    for (const Point2& p : *list) {
      float a = std::atan2(p.y_m, p.x_m) * 57.29578F;
      if (a < 0.0F) a += 360.0F;
      CHECK_TEXT(!(a > 31.0F && a < 149.0F), "a map point on a blocked ray");
    }
  }
  g_other.start(params, look.features.span(), look.obstacles.span(), w.free.span(), w.near_m.span(),
                blocked.span());
  g_other.run();
  for (const float d : {35.0F, 70.0F, 145.0F}) {
    CHECK(g_other.map().free.radius_at_m(deg(d)) < own + 0.05F);
  }
  CHECK_EQUAL(0U, g_other.stats().blocked_by_prior);
}
