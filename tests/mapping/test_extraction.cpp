// Tests of the map extraction from an occupancy ALN, the map points and the global lists.
#include <array>
#include <cmath>
#include <cstddef>

#include <Eigen/Core>

#include "algo/aln/aln.h"
#include "algo/core/fixed_vector.h"
#include "algo/mapping/aln_free_range.h"
#include "algo/mapping/extraction.h"
#include "algo/mapping/map_points.h"
#include "polygon_fixtures.h"

#include "CppUTest/TestHarness.h"
#include "alloc_guard.h"

using boticelli::core::FixedVector;
using boticelli::core::Point2;
using boticelli::core::Pose2;
namespace mapping = boticelli::mapping;

namespace {

using Occupancy = boticelli::aln::Aln<float, 3, 16>;

// The occupancy of a cylindrical room of wall distance D [m] seen from its centre, as an ALN
// built by hand: m = MIN_j (0.6 + c (r − a_j h − b_j)), monotone in r (c > 0). Its inverse
// at m = 0.6 is r = MAX_j (a_j h + b_j): tangents of the true wall range √(D² + h²) at a
// few heights, so the polygon is the circle of radius D (tangents lie just below it).
void cylindrical_room(float wall_m, Occupancy& model) {
  constexpr float kSlope = 2.0F;  // occupancy per metre of r
  const float tangent_h[] = {-0.32F, -0.22F, -0.12F, -0.02F, 0.08F, 0.12F};
  Occupancy::PieceType pieces[6];
  for (std::size_t j = 0; j < 6; ++j) {
    const float h = tangent_h[j];
    const float g = std::sqrt(wall_m * wall_m + h * h);
    const float a = h / g;
    const float b = g - a * h;
    pieces[j].set(Eigen::Vector3f(0.0F, -kSlope * a, kSlope), Eigen::Vector3f(3.14F, 0.0F, b),
                  0.6F);
  }
  // A balanced MIN tree over the six pieces.
  using Node = Occupancy::Node;
  using boticelli::aln::NodeKind;
  const Node nodes[11] = {
      {NodeKind::kMin, 1, 2},   {NodeKind::kMin, 3, 4},   {NodeKind::kMin, 5, 6},
      {NodeKind::kMin, 7, 8},   {NodeKind::kPiece, 2, 0}, {NodeKind::kPiece, 3, 0},
      {NodeKind::kMin, 9, 10},  {NodeKind::kPiece, 0, 0}, {NodeKind::kPiece, 1, 0},
      {NodeKind::kPiece, 4, 0}, {NodeKind::kPiece, 5, 0}};
  CHECK_TRUE(model.assign(nodes, pieces));
  model.set_weight_bounds(2, 1e-4F, 100.0F);
}

mapping::ExtractionParams params() {
  mapping::ExtractionParams p;
  p.bounding_radius_m = 3.5F;
  return p;
}

}  // namespace

TEST_GROUP(Extraction){};

TEST(Extraction, CylindricalRoomSeenFromItsCentreGivesTheCircleMinusTheRobotRadius) {
  static Occupancy model;
  cylindrical_room(2.5F, model);
  static mapping::AlnFreeRange<float, 16> free_range;
  CHECK_TRUE(free_range.set_model(model, 0.6F));
  static mapping::LocalMap map;
  static mapping::StarPolygon scratch;
  mapping::ExtractionParams p = params();
  p.clearance_margin_m = 0.0F;  // the geometry alone: no margin for obstacles between rays
  mapping::extract_local_map(free_range, p, map, scratch);
  CHECK_TRUE(map.can_move);
  LONGS_EQUAL(360, map.navigable.vertex_count());
  for (std::size_t k = 0; k < 360; ++k) {
    DOUBLES_EQUAL(2.5, map.free.rho_m(k), 0.02);
    DOUBLES_EQUAL(2.5 - 0.2, map.navigable.rho_m(k), 0.02);
  }
  // With the default margin the circle is that much smaller.
  p.clearance_margin_m = params().clearance_margin_m;
  mapping::extract_local_map(free_range, p, map, scratch);
  DOUBLES_EQUAL(2.5 - 0.2 - static_cast<double>(p.clearance_margin_m), map.navigable.rho_m(100),
                0.02);
}

TEST(Extraction, TheRobotMayMoveWithoutItsMarginButNotOnceItsDiscTouchesAnObstacle) {
  static mapping::StarPolygon free;
  static mapping::StarPolygon navigable;
  free.set_vertex_count(360);
  // Obstacles 0.23 m all round: the robot's 0.2 m disc fits, its 0.05 m margin does not, so
  // the polygon is shrunk by what clearance there is and the robot may still move.
  for (std::size_t k = 0; k < free.vertex_count(); ++k) free.set_rho_m(k, 0.23F);
  CHECK_TRUE(mapping::shrink_for_robot(free, 0.2F, 0.05F, navigable));
  for (std::size_t k = 0; k < navigable.vertex_count(); ++k) CHECK(navigable.rho_m(k) < 0.03F);
  // 0.15 m all round: the disc already overlaps them.
  for (std::size_t k = 0; k < free.vertex_count(); ++k) free.set_rho_m(k, 0.15F);
  CHECK_FALSE(mapping::shrink_for_robot(free, 0.2F, 0.05F, navigable));
}

TEST(Extraction, AModelThatIsNotMonotoneInRangeIsRefused) {
  static Occupancy model;
  Occupancy::PieceType piece;
  piece.set(Eigen::Vector3f(0.0F, 0.0F, -1.0F), Eigen::Vector3f::Zero(), 0.5F);
  model.reset(piece);
  static mapping::AlnFreeRange<float, 16> free_range;
  CHECK_FALSE(free_range.set_model(model, 0.6F));
  DOUBLES_EQUAL(0.0, free_range(1.0F, 0.0F), 0.0);  // nothing is known to be free
}

TEST(Extraction, HorizontalDistanceHandlesNoSolutionAndRangesShorterThanTheHeight) {
  DOUBLES_EQUAL(std::sqrt(4.0 - 0.09), mapping::horizontal_free_distance_m(2.0F, -0.3F, 3.0F),
                1e-6);
  DOUBLES_EQUAL(3.0, mapping::horizontal_free_distance_m(9.0F, 0.1F, 3.0F), 0.0);
  DOUBLES_EQUAL(3.0, mapping::horizontal_free_distance_m(NAN, 0.1F, 3.0F), 0.0);
  DOUBLES_EQUAL(3.0, mapping::horizontal_free_distance_m(INFINITY, 0.1F, 3.0F), 0.0);
  DOUBLES_EQUAL(0.0, mapping::horizontal_free_distance_m(0.2F, -0.3F, 3.0F), 0.0);
  DOUBLES_EQUAL(0.0, mapping::horizontal_free_distance_m(-1.0F, 0.0F, 3.0F), 0.0);
}

TEST(Extraction, AtTheSeamTheModelIsAlsoReadOneTurnAway) {
  // A model that disagrees with itself across the α seam: near α = 0 the copy at α + 2π
  // sees an obstacle at 1 m; the extraction keeps the nearer answer.
  auto free_range = [](float alpha, float) { return alpha >= 6.0F ? 1.0F : 2.0F; };
  mapping::StarPolygon slice;
  mapping::ExtractionParams p = params();
  mapping::extract_slice(free_range, 0.0F, p, slice);
  DOUBLES_EQUAL(1.0, slice.rho_m(0), 1e-6);
  DOUBLES_EQUAL(1.0, slice.rho_m(5), 1e-6);
  DOUBLES_EQUAL(2.0, slice.rho_m(180), 1e-6);
}

TEST(Extraction, TheLowestSliceWithAnObstacleLimitsThePolygon) {
  // A 0.1 m high box 1 m ahead (pan angles 0..10°) shows only in the lowest slice.
  auto free_range = [](float alpha, float h) {
    const bool box = alpha < 0.1745F && h < 0.1F - 0.35F;
    return box ? std::sqrt(1.0F + h * h) : 2.0F;
  };
  static mapping::LocalMap map;
  static mapping::StarPolygon scratch;
  mapping::extract_local_map(free_range, params(), map, scratch);
  DOUBLES_EQUAL(1.0, map.free.rho_m(5), 1e-4);
  CHECK_TRUE(map.free.rho_m(20) > 1.9F);
}

TEST_GROUP(MapPoints){};

TEST(MapPoints, ObstaclePointsLieOnTheWallAndExplorationPointsOnTheCircle) {
  // Free to the 3 m circle except a wall 1 m ahead (x = 1 for |y| ≤ 1).
  std::array<boticelli::test::Wall, 1> walls{{{{1.0F, -1.0F}, {1.0F, 1.0F}}}};
  mapping::StarPolygon free(360);
  for (std::size_t k = 0; k < 360; ++k) {
    free.set_rho_m(
        k, std::fmin(3.0F, boticelli::test::cast_ray_m(walls, 1, {0.0F, 0.0F}, free.angle_rad(k))));
  }
  FixedVector<Point2, 256> obstacles;
  FixedVector<Point2, 256> exploration;
  mapping::MapPointParams mp;
  CHECK_TRUE(mapping::extract_map_points(free, 3.0F, mp, obstacles, exploration));
  // The wall is 2 m long: about 2 / 0.15 points, all on it.
  CHECK_TRUE(obstacles.size() >= 13 && obstacles.size() <= 15);
  for (const Point2& o : obstacles) {
    DOUBLES_EQUAL(1.0, o.x_m, 1e-3);
  }
  // The rest of the circle: 2π·3 m minus the wall's 90° ≈ 14.1 m of arc at 0.5 m.
  CHECK_TRUE(exploration.size() >= 28 && exploration.size() <= 30);
  for (const Point2& e : exploration) {
    DOUBLES_EQUAL(3.0, std::hypot(e.x_m, e.y_m), 1e-3);
    CHECK_TRUE(std::fabs(std::atan2(e.y_m, e.x_m)) > 0.78F);
  }
  // Evenly spaced: neighbouring exploration points are 0.5 m apart or a little less.
  for (std::size_t i = 1; i < exploration.size(); ++i) {
    const float d = boticelli::core::distance_m(exploration[i - 1], exploration[i]);
    CHECK_TRUE(d > 0.4F && d < 0.55F);
  }
}

TEST(MapPoints, GlobalListsDeduplicateObstaclesAndDropExploredPoints) {
  std::array<boticelli::test::Wall, 1> walls{{{{1.0F, -1.0F}, {1.0F, 1.0F}}}};
  static mapping::GlobalMap global;
  global.clear();
  mapping::MapPointParams mp;
  static mapping::StarPolygon free(360);
  FixedVector<Point2, 256> obstacles;
  FixedVector<Point2, 256> exploration;
  auto observe = [&](Pose2 pose, float bound) {
    for (std::size_t k = 0; k < 360; ++k) {
      free.set_rho_m(
          k, std::fmin(bound, boticelli::test::cast_ray_m(walls, 1, {pose.x_m, pose.y_m},
                                                          free.angle_rad(k) + pose.yaw_rad)));
    }
    obstacles.clear();
    exploration.clear();
    CHECK_TRUE(mapping::extract_map_points(free, bound, mp, obstacles, exploration));
    CHECK_TRUE(global.merge(pose, free, bound, obstacles, exploration, mp));
  };
  observe({0.0F, 0.0F, 0.0F}, 3.0F);
  const std::size_t walls_first = global.obstacles().size();
  const std::size_t exploration_first = global.exploration().size();
  // The same wall seen again from 2 cm aside, turned: no new obstacle points.
  observe({0.0F, 0.02F, 0.3F}, 3.0F);
  CHECK_TRUE(global.obstacles().size() <= walls_first + 2);
  for (const Point2& o : global.obstacles()) {
    DOUBLES_EQUAL(1.0, o.x_m, 2e-3);
  }
  // Moving 1.5 m to the left and looking with a larger circle covers the old exploration
  // points on that side: they are dropped, the new circle's points are added.
  observe({-1.5F, 0.0F, 0.0F}, 4.0F);
  std::size_t old_left = 0;
  for (const Point2& e : global.exploration()) {
    const float from_first = std::hypot(e.x_m, e.y_m);
    if (std::fabs(from_first - 3.0F) < 1e-3F && e.x_m < -2.0F) {
      ++old_left;
    }
  }
  LONGS_EQUAL(0, old_left);
  CHECK_TRUE(global.exploration().size() > 0);
  CHECK_TRUE(exploration_first > 0);
}

TEST(MapPoints, ExtractionAndMergingDoNotAllocate) {
  static Occupancy model;
  cylindrical_room(2.5F, model);
  static mapping::AlnFreeRange<float, 16> free_range;
  CHECK_TRUE(free_range.set_model(model, 0.6F));
  static mapping::LocalMap map;
  static mapping::StarPolygon scratch;
  static mapping::GlobalMap global;
  static FixedVector<Point2, 512> obstacles;
  static FixedVector<Point2, 512> exploration;
  const mapping::ExtractionParams p = params();
  const mapping::MapPointParams mp;
  CHECK_NO_ALLOCATION({
    mapping::extract_local_map(free_range, p, map, scratch);
    (void)mapping::extract_map_points(map.free, p.bounding_radius_m, mp, obstacles, exploration);
    (void)global.merge({0.1F, 0.2F, 0.3F}, map.free, p.bounding_radius_m, obstacles, exploration,
                       mp);
  });
  CHECK_TRUE(map.can_move);
  CHECK_TRUE(obstacles.size() > 0);
}

TEST_GROUP(BlockInverse){};

namespace {
// A jagged 9-piece occupancy model: MAX and MIN of planes in (α, h, r), monotone in r.
void jagged_room(Occupancy& model) {
  Occupancy::PieceType pieces[9];
  for (std::size_t j = 0; j < 9; ++j) {
    const auto fj = static_cast<float>(j);
    pieces[j].set(
        Eigen::Vector3f(0.3F * std::sin(1.7F * fj), 2.0F * std::cos(fj), 0.8F + 0.2F * fj),
        Eigen::Vector3f(0.7F * fj, 0.1F * fj - 0.4F, 1.5F + 0.1F * fj), 0.6F);
  }
  using Node = Occupancy::Node;
  using boticelli::aln::NodeKind;
  // MAX(MIN(p0, p1, p2), MIN(p3, MAX(p4, p5)), MAX(p6, MIN(p7, p8)))
  const Node nodes[17] = {
      {NodeKind::kMax, 1, 2},   {NodeKind::kMin, 3, 4},   {NodeKind::kMax, 5, 6},
      {NodeKind::kPiece, 0, 0}, {NodeKind::kMin, 7, 8},   {NodeKind::kMin, 9, 10},
      {NodeKind::kMax, 11, 12}, {NodeKind::kPiece, 1, 0}, {NodeKind::kPiece, 2, 0},
      {NodeKind::kPiece, 3, 0}, {NodeKind::kMax, 13, 14}, {NodeKind::kPiece, 6, 0},
      {NodeKind::kMin, 15, 16}, {NodeKind::kPiece, 4, 0}, {NodeKind::kPiece, 5, 0},
      {NodeKind::kPiece, 7, 0}, {NodeKind::kPiece, 8, 0}};
  CHECK_TRUE(model.assign(nodes, pieces));
}
}  // namespace

TEST(BlockInverse, AWholeSliceAtOnceEqualsOneAngleAtATime) {
  static Occupancy model;
  jagged_room(model);
  static mapping::AlnFreeRange<float, 16> free_range;
  CHECK_TRUE(free_range.set_model(model, 0.6F));
  mapping::StarPolygon polygon(360);
  std::array<float, 400> block{};
  for (const float h : {-0.5F, -0.1F, 0.0F, 0.3F}) {
    for (const float offset : {0.0F, 6.2831853F, -6.2831853F}) {
      free_range.ranges_at_height(h, polygon.angle_step_rad(), 7, 353, offset, block.data());
      for (std::size_t i = 0; i < 353; ++i) {
        const float alpha = polygon.angle_rad(7 + i) + offset;
        const float one = free_range(alpha, h);
        DOUBLES_EQUAL(one, block[i], 1e-5 * (1.0 + std::fabs(static_cast<double>(one))));
      }
    }
  }
}

TEST(BlockInverse, TheExtractionGivesTheSameSlicesEitherWayIncludingTheSeam) {
  static Occupancy model;
  jagged_room(model);
  static mapping::AlnFreeRange<float, 16> free_range;
  CHECK_TRUE(free_range.set_model(model, 0.6F));
  // The same function without the block interface: the one-angle path of extract_slice.
  auto one_at_a_time = [](float alpha, float h) { return free_range(alpha, h); };
  mapping::ExtractionParams p = params();
  p.seam_margin_rad = 0.3F;
  mapping::StarPolygon a;
  mapping::StarPolygon b;
  for (const float h : {-0.3F, 0.0F, 0.1F}) {
    mapping::extract_slice(free_range, h, p, a);
    mapping::extract_slice(one_at_a_time, h, p, b);
    for (std::size_t k = 0; k < a.vertex_count(); ++k) {
      DOUBLES_EQUAL(b.rho_m(k), a.rho_m(k), 1e-5);
    }
  }
}

TEST(BlockInverse, WithoutAValidModelNothingIsFree) {
  static Occupancy model;
  Occupancy::PieceType piece;
  piece.set(Eigen::Vector3f(0.0F, 0.0F, -1.0F), Eigen::Vector3f::Zero(), 0.5F);
  model.reset(piece);
  static mapping::AlnFreeRange<float, 16> free_range;
  CHECK_FALSE(free_range.set_model(model, 0.6F));
  std::array<float, 20> out{};
  out.fill(7.0F);
  free_range.ranges_at_height(0.0F, 0.1F, 0, 20, 0.0F, out.data());
  for (const float r : out) DOUBLES_EQUAL(0.0, r, 0.0);
}
