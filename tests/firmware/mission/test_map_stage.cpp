// Tests of the MapStage: the global lists from and back into the mission state, and a look's
// fusion with a lone target sighting (a look with no readings: the model is the robot's disc).
#include <cmath>
#include <cstddef>
#include <memory>

#include <Eigen/Core>

#include "algo/core/geometry.h"
#include "firmware/common/board_config.h"
#include "firmware/mission/look/look_processor.h"
#include "firmware/mission/map/map_stage.h"
#include "firmware/mission/params/mission_params.h"
#include "firmware/state/mission_state.h"

#include "CppUTest/TestHarness.h"

using boticelli::core::distance_m;
using boticelli::core::Point2;
using boticelli::core::Pose2;
using boticelli::firmware::BoardConfig;
using boticelli::firmware::MissionState;
using namespace boticelli::firmware::mission;

namespace {

// How many of `points` lie within `radius_m` of `p`.
template <typename List>
std::size_t near(const List& points, Point2 p, float radius_m) {
  std::size_t n = 0;
  for (const Point2& q : points) n += distance_m(p, q) < radius_m ? 1U : 0U;
  return n;
}

}  // namespace

TEST_GROUP(MapStage) {
  const MissionParams params = make_mission_params(BoardConfig{});
  std::unique_ptr<MapStage> stage;
  std::unique_ptr<MissionState> state;
  std::unique_ptr<LookReadings> readings;  // none: this look saw nothing
  FuseParams fuse;

  void setup() override {
    stage = std::make_unique<MapStage>();
    state = std::make_unique<MissionState>();
    readings = std::make_unique<LookReadings>();
    fuse.points = params.points;
    fuse.robot_radius_m = params.value.robot_radius_m;
    fuse.goal_standoff_m = params.rewards.goal_standoff_m;
  }
  void teardown() override {
    stage.reset();
    state.reset();
    readings.reset();
  }

  // A look at `pose` with no readings, fused with `candidate` (or nullptr).
  void look_at(const Pose2& pose, const Eigen::Vector3f* candidate) {
    stage->begin(params.model, *readings, pose);
    while (!stage->done()) stage->run_unit();
    stage->fuse(pose, fuse, candidate);
  }
};

TEST(MapStage, StartTakesTheGlobalListsFromTheStateAndSaveGivesThemBack) {
  (void)state->obstacles.push_back({1.0F, 2.0F});
  (void)state->obstacles.push_back({1.5F, 2.0F});
  (void)state->exploration.push_back({-3.0F, 0.5F});
  stage->start(*state, {});
  CHECK_EQUAL(2U, stage->global().obstacles().size());
  CHECK_EQUAL(1U, stage->global().exploration().size());
  DOUBLES_EQUAL(1.5, stage->global().obstacles()[1].x_m, 0.0);
  DOUBLES_EQUAL(-3.0, stage->global().exploration()[0].x_m, 0.0);
  static MissionState saved;
  saved.clear();
  (void)saved.obstacles.push_back({9.0F, 9.0F});  // whatever it held before goes
  stage->save(saved);
  CHECK_EQUAL(2U, saved.obstacles.size());
  CHECK_EQUAL(1U, saved.exploration.size());
  DOUBLES_EQUAL(1.0, saved.obstacles[0].x_m, 0.0);
  DOUBLES_EQUAL(0.5, saved.exploration[0].y_m, 0.0);
}

// The world memory survives a restart: the grid's tiles go into the state and a resumed
// mission's grid holds them again, cell for cell; a grid kept at another cell side is not
// restored (its cells would mean other places).
TEST(MapStage, TheGridGoesIntoTheStateAndAResumedMissionHasItBack) {
  stage->start(*state, {});
  CHECK(stage->swept({0.0F, 0.0F}, {1.0F, 0.0F}, 0.2F));  // a move: free cells along it
  look_at({5.0F, 5.0F, 0.0F}, nullptr);
  stage->begin_grid({5.0F, 5.0F, 0.0F}, {});
  while (!stage->grid_done()) stage->grid_unit();
  CHECK(stage->grid().tiles_used() > 0);
  const auto cell = stage->grid().cell_of({0.1F, -0.05F});
  const int before = stage->grid().log_odds(cell);
  CHECK(before < 0);
  stage->save(*state);
  CHECK_EQUAL(stage->grid().tiles_used(), state->grid.size());
  DOUBLES_EQUAL(stage->grid().cell_m(), state->grid_cell_m, 0.0);
  auto resumed = std::make_unique<MapStage>();
  resumed->start(*state, {});
  CHECK_EQUAL(stage->grid().tiles_used(), resumed->grid().tiles_used());
  CHECK_EQUAL(stage->grid().free_cells(), resumed->grid().free_cells());
  CHECK_EQUAL(stage->grid().occupied_cells(), resumed->grid().occupied_cells());
  CHECK_EQUAL(before, resumed->grid().log_odds(cell));
  boticelli::worldmap::GridMapParams coarser;
  coarser.cell_m = 0.1F;
  resumed->start(*state, coarser);
  CHECK_EQUAL(0U, resumed->grid().tiles_used());
}

TEST(MapStage, ARestartedMissionHoldsOnlyTheListsOfItsState) {
  (void)state->obstacles.push_back({1.0F, 2.0F});
  (void)state->exploration.push_back({-3.0F, 0.5F});
  stage->start(*state, {});
  stage->start(*state, {});
  CHECK_EQUAL(1U, stage->global().obstacles().size());
  CHECK_EQUAL(1U, stage->global().exploration().size());
  state->clear();
  stage->start(*state, {});
  CHECK_EQUAL(0U, stage->global().obstacles().size());
  CHECK_EQUAL(0U, stage->global().exploration().size());
}

TEST(MapStage, ALoneSightingGetsAnExplorationPointAtTheStandOffOnTheWayToIt) {
  stage->start(*state, {});
  // The target 3.5 m ahead of a robot at (1, 1) facing +y: the point 0.75 m short of it.
  const Pose2 pose{1.0F, 1.0F, 1.5707964F};
  const Eigen::Vector3f candidate(1.0F, 4.5F, 0.4F);
  look_at(pose, &candidate);
  const Point2 expected{1.0F, 4.5F - fuse.goal_standoff_m};
  CHECK_EQUAL(1U, near(stage->global().exploration(), expected, 0.01F));
  // Another look from the same place adds no second point there.
  look_at(pose, &candidate);
  CHECK_EQUAL(
      1U, near(stage->global().exploration(), expected, fuse.points.exploration_merge_radius_m));
}

TEST(MapStage, ASightingWithinTheLookRadiusAndTheStandOffGetsNoPoint) {
  stage->start(*state, {});
  const Pose2 pose{0.0F, 0.0F, 0.0F};
  // Seen from 1.5 m: the robot looked from (about) the stand-off already.
  const Eigen::Vector3f candidate(1.5F, 0.0F, 0.4F);
  CHECK(1.5F < fuse.points.explored_look_radius_m + fuse.goal_standoff_m);
  look_at(pose, &candidate);
  CHECK_EQUAL(0U, near(stage->global().exploration(), {0.75F, 0.0F}, 0.3F));
}

TEST(MapStage, AMovesSweptDiscIsWrittenIntoTheGridWithTheNextLookNotBefore) {
  stage->start(*state, {});
  CHECK(stage->swept({0.0F, 0.0F}, {1.0F, 0.0F}, 0.2F));
  const auto free_at = [&](float x, float y) {
    return stage->grid().state(stage->grid().cell_of({x, y})) ==
           boticelli::worldmap::CellState::kFree;
  };
  CHECK_FALSE(free_at(0.5F, 0.1F));  // noted on the mission task, written in the background
  look_at({5.0F, 5.0F, 0.0F}, nullptr);
  stage->begin_grid({5.0F, 5.0F, 0.0F}, {});
  while (!stage->grid_done()) stage->grid_unit();
  CHECK(free_at(0.5F, 0.1F));
  CHECK(free_at(1.1F, 0.0F));
  CHECK_FALSE(free_at(0.5F, 0.35F));
  // Written once: a restart forgets what was noted.
  CHECK(stage->swept({0.0F, 2.0F}, {1.0F, 2.0F}, 0.2F));
  stage->start(*state, {});
  stage->begin_grid({5.0F, 5.0F, 0.0F}, {});
  while (!stage->grid_done()) stage->grid_unit();
  CHECK_FALSE(free_at(0.5F, 2.0F));
}
