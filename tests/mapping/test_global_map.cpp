// Tests of the global point lists: retired obstacle points, explored and unreachable exploration
// points.
#include <cmath>
#include <cstddef>

#include "algo/core/fixed_vector.h"
#include "algo/core/geometry.h"
#include "algo/mapping/map_points.h"
#include "algo/mapping/star_polygon.h"

#include "CppUTest/TestHarness.h"

using boticelli::core::FixedVector;
using boticelli::core::Point2;
using boticelli::core::Pose2;
namespace core = boticelli::core;
namespace mapping = boticelli::mapping;

namespace {

// The robot sees from here, turned, so that the frames matter.
constexpr Pose2 kPose{1.0F, 2.0F, 0.5F};

// The world point at distance d [m] and bearing a [rad] from the robot at kPose.
Point2 seen_at(float d, float a) {
  return core::to_world(kPose, {d * std::cos(a), d * std::sin(a)});
}

bool holds(const mapping::PointList& list, Point2 p) {
  for (const Point2& q : list) {
    if (core::distance_m(p, q) < 1e-4F) {
      return true;
    }
  }
  return false;
}

}  // namespace

TEST_GROUP(GlobalMap) {
  mapping::GlobalMap* global = nullptr;
  mapping::StarPolygon* free = nullptr;
  FixedVector<Point2, 8> none;
  mapping::MapPointParams params;

  void setup() override {
    static mapping::GlobalMap g;
    static mapping::StarPolygon f(360);
    global = &g;
    free = &f;
    global->clear();
  }
};

TEST(GlobalMap, AnObstaclePointWellInsideALaterFreePolygonIsRetired) {
  free->fill(2.0F);                                 // the new view: free floor to 2 m all round
  const Point2 deep = seen_at(1.0F, 0.3F);          // 1 m inside
  const Point2 past_margin = seen_at(1.84F, 2.0F);  // 0.16 m inside, more than the margin
  CHECK_TRUE(global->obstacles().push_back(deep));
  CHECK_TRUE(global->obstacles().push_back(past_margin));
  CHECK_TRUE(global->merge(kPose, *free, 3.0F, none, none, params));
  LONGS_EQUAL(0, global->obstacles().size());
  LONGS_EQUAL(2, global->retired_points());
}

TEST(GlobalMap, AnObstaclePointOnOrNearTheNewBoundaryOrBeyondItIsKept) {
  free->fill(2.0F);
  const Point2 on = seen_at(2.0F, 1.0F);      // on the boundary: the wall is still there
  const Point2 near = seen_at(1.9F, 4.0F);    // 0.1 m inside: within the margin
  const Point2 beyond = seen_at(2.6F, 5.5F);  // outside the polygon
  CHECK_TRUE(global->obstacles().push_back(on));
  CHECK_TRUE(global->obstacles().push_back(near));
  CHECK_TRUE(global->obstacles().push_back(beyond));
  CHECK_TRUE(global->merge(kPose, *free, 3.0F, none, none, params));
  LONGS_EQUAL(3, global->obstacles().size());
  LONGS_EQUAL(0, global->retired_points());
}

TEST(GlobalMap, APolygonSaysNothingBeyondItsBoundingCircleLessTheMargin) {
  free->fill(4.0F);  // reaches past the circle: the polygon alone would retire both
  const Point2 rim = seen_at(2.9F, 0.7F);    // 0.1 m inside the 3 m circle: kept
  const Point2 inner = seen_at(2.8F, 0.7F);  // 0.2 m inside it: retired
  CHECK_TRUE(global->obstacles().push_back(rim));
  CHECK_TRUE(global->obstacles().push_back(inner));
  CHECK_TRUE(global->merge(kPose, *free, 3.0F, none, none, params));
  LONGS_EQUAL(1, global->obstacles().size());
  CHECK_TRUE(holds(global->obstacles(), rim));
}

TEST(GlobalMap, RetiringKeepsTheOrderOfThePointsThatStay) {
  // Free to 2 m only towards bearing 0 (±30°), 0.5 m elsewhere.
  for (std::size_t k = 0; k < free->vertex_count(); ++k) {
    const float a = free->angle_rad(k);
    free->set_rho_m(k, (a < 0.52F || a > 5.76F) ? 2.0F : 0.5F);
  }
  Point2 expected[4];
  std::size_t n_expected = 0;
  for (int i = 0; i < 8; ++i) {
    const bool ahead = i % 2 == 0;  // ahead: 1 m inside, retired; aside: outside, kept
    const Point2 p = seen_at(1.0F + 0.05F * static_cast<float>(i), ahead ? 0.0F : 3.0F);
    CHECK_TRUE(global->obstacles().push_back(p));
    if (!ahead) {
      expected[n_expected++] = p;
    }
  }
  CHECK_TRUE(global->merge(kPose, *free, 3.0F, none, none, params));
  LONGS_EQUAL(n_expected, global->obstacles().size());
  for (std::size_t i = 0; i < n_expected; ++i) {
    DOUBLES_EQUAL(expected[i].x_m, global->obstacles()[i].x_m, 1e-6);
    DOUBLES_EQUAL(expected[i].y_m, global->obstacles()[i].y_m, 1e-6);
  }
}

TEST(GlobalMap, AWallFromACoarseEarlyViewGivesWayToTheWallSeenLater) {
  // First look: the model put a wall all round at 1 m; a better fit later sees it at 2.5 m.
  FixedVector<Point2, 256> obstacles;
  FixedVector<Point2, 64> exploration;
  free->fill(1.0F);
  CHECK_TRUE(mapping::extract_map_points(*free, 3.0F, params, obstacles, exploration));
  CHECK_TRUE(global->merge(kPose, *free, 3.0F, obstacles, exploration, params));
  const std::size_t early = global->obstacles().size();
  CHECK_TRUE(early > 10);
  obstacles.clear();
  exploration.clear();
  free->fill(2.5F);
  CHECK_TRUE(mapping::extract_map_points(*free, 3.0F, params, obstacles, exploration));
  CHECK_TRUE(global->merge(kPose, *free, 3.0F, obstacles, exploration, params));
  LONGS_EQUAL(early, global->retired_points());
  LONGS_EQUAL(obstacles.size(), global->obstacles().size());
  for (const Point2& o : global->obstacles()) {
    DOUBLES_EQUAL(2.5, core::distance_m(o, {kPose.x_m, kPose.y_m}), 1e-3);
  }
}

TEST(GlobalMap, AKnownExplorationPointNearALaterLooksPositionIsExplored) {
  free->fill(0.5F);  // a small polygon: covers neither point below
  const Point2 near_look = seen_at(0.9F, 1.0F);
  const Point2 far_look = seen_at(1.1F, 1.0F);
  CHECK_TRUE(global->exploration().push_back(near_look));
  CHECK_TRUE(global->exploration().push_back(far_look));
  CHECK_TRUE(global->merge(kPose, *free, 3.0F, none, none, params));
  CHECK_FALSE(holds(global->exploration(), near_look));
  CHECK_TRUE(holds(global->exploration(), far_look));
}

TEST(GlobalMap, AnExplorationPointTouchingAnObstacleMovesTowardTheLookUntilTheDiscClears) {
  const Point2 origin{0.0F, 0.0F};
  // A door frame's obstacle point 0.1 m beside the point; the look is 2 m away along -x.
  CHECK_TRUE(global->obstacles().push_back({2.0F, 0.1F}));
  CHECK_TRUE(global->exploration().push_back({2.0F, 0.0F}));
  CHECK_EQUAL(0U, global->clear_exploration(origin, 0.3F, 3.0F, params));
  CHECK_EQUAL(1U, global->exploration().size());
  const Point2 moved = global->exploration()[0];
  CHECK(core::distance_m(moved, {2.0F, 0.1F}) >= 0.3F);
  // The first clear position on the way in 5 cm steps: at x = 1.75 the obstacle is
  // sqrt(0.25² + 0.1²) = 0.269 m off, at x = 1.70 0.316 m.
  DOUBLES_EQUAL(1.70, moved.x_m, 1e-4);
  DOUBLES_EQUAL(0.0, moved.y_m, 1e-6);
}

TEST(GlobalMap, AnExplorationPointThatCannotBeClearedOrIsNotThisLooksIsDropped) {
  const Point2 origin{0.0F, 0.0F};
  // Boxed in by obstacle points all along its way back to the look.
  for (int i = 0; i <= 20; ++i) {
    CHECK_TRUE(global->obstacles().push_back({2.0F - 0.05F * static_cast<float>(i), 0.1F}));
  }
  CHECK_TRUE(global->exploration().push_back({2.0F, 0.0F}));
  // Touching an obstacle, 4 m from the look (beyond its 3 m reach): not moved, dropped.
  CHECK_TRUE(global->obstacles().push_back({-4.0F, 0.1F}));
  CHECK_TRUE(global->exploration().push_back({-4.0F, 0.0F}));
  // Clear already: kept where it is.
  CHECK_TRUE(global->exploration().push_back({0.0F, 2.0F}));
  CHECK_EQUAL(2U, global->clear_exploration(origin, 0.3F, 3.0F, params));
  CHECK_EQUAL(1U, global->exploration().size());
  CHECK_TRUE(holds(global->exploration(), {0.0F, 2.0F}));
}

TEST(GlobalMap, AKnownExplorationPointALookSawIsExploredAndOneBeyondWhatItSawStays) {
  free->fill(2.0F);                            // how far this look saw the floor, all round
  const Point2 seen = seen_at(1.8F, -1.0F);    // 0.2 m inside what was seen
  const Point2 beyond = seen_at(1.95F, 2.5F);  // only 0.05 m inside: not by the margin
  CHECK_TRUE(global->exploration().push_back(seen));
  CHECK_TRUE(global->exploration().push_back(beyond));
  CHECK_EQUAL(1U, global->mark_explored(kPose, *free, 3.0F, params));
  CHECK_FALSE(holds(global->exploration(), seen));
  CHECK_TRUE(holds(global->exploration(), beyond));
}
