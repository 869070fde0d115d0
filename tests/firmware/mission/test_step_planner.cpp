// Tests of the StepPlanner: the step's outcome on hand-made polygons and maps (turning round,
// no safe step, backing off along the breadcrumbs, giving up, the next step on the same look).
#include <cmath>
#include <cstddef>

#include "algo/core/angles.h"
#include "algo/core/geometry.h"
#include "algo/mapping/map_points.h"
#include "algo/mapping/star_polygon.h"
#include "algo/planning/planner.h"
#include "firmware/common/board_config.h"
#include "firmware/mission/drive/breadcrumbs.h"
#include "firmware/mission/params/mission_params.h"
#include "firmware/mission/plan/step_planner.h"

#include "CppUTest/TestHarness.h"

using boticelli::core::Point2;
using boticelli::core::Pose2;
using boticelli::core::to_robot;
using boticelli::firmware::BoardConfig;
using boticelli::mapping::GlobalMap;
using boticelli::mapping::StarPolygon;
using boticelli::planning::StepKind;
using namespace boticelli::firmware::mission;

namespace {

StarPolygon disc(float radius_m) {
  StarPolygon p;
  p.fill(radius_m);
  return p;
}

boticelli::worldmap::GridMap g_grid;  // large: static

// The thesis's planner (reward cones and value iteration), which these tests were written for.
MissionParams thesis_params() {
  BoardConfig config;
  config.thesis_planner = true;
  return make_mission_params(config);
}

}  // namespace

TEST_GROUP(StepPlanner) {
  const MissionParams params = thesis_params();
  StepPlanner planner{params};
  GlobalMap map;
  Breadcrumbs crumbs;
  const StarPolygon look_disc = disc(1.0F);  // the look's navigable polygon: a 1 m disc
  const Pose2 origin{};

  void setup() override {
    planner.clear();
  }

  void choose() {
    while (!planner.choice_done()) planner.choose_heading();
  }
  // One cycle's step from `here` on the look taken at `look` (something left to explore).
  StepOutcome cycle(const Pose2& here, const Pose2& look) {
    CHECK(planner.begin_choice(here, look_disc, true, false) == StepOutcome::kChoosing);
    choose();
    return planner.end_choice(here, look, look_disc, crumbs);
  }
  // A cycle with no safe step: the look was taken 5 m away, so no step from here lies in it.
  StepOutcome failed_cycle() {
    return cycle(origin, {5.0F, 0.0F, 0.0F});
  }
  // A cycle whose step lies in the look's polygon: the look was taken where the robot stands.
  StepOutcome safe_cycle() {
    return cycle(origin, origin);
  }
};

TEST(StepPlanner, NothingToExploreAndNoGoalTurnsRoundThenEndsOnlyWithinHalfAMetreOfTheTurn) {
  CHECK(planner.begin_choice(origin, look_disc, false, false) == StepOutcome::kTurnRound);
  planner.turned_round_at({0.0F, 0.0F});
  CHECK(planner.begin_choice({0.3F, 0.2F, 1.0F}, look_disc, false, false) ==
        StepOutcome::kNothingLeft);
  // Elsewhere the sector behind the robot has not been looked at yet.
  CHECK(planner.begin_choice({0.6F, 0.0F, 0.0F}, look_disc, false, false) ==
        StepOutcome::kTurnRound);
  // Something to explore, or a goal: the step is chosen, turned round or not.
  CHECK(planner.begin_choice(origin, look_disc, true, false) == StepOutcome::kChoosing);
  CHECK(planner.begin_choice(origin, look_disc, false, true) == StepOutcome::kChoosing);
  // A new run has not turned round anywhere.
  planner.clear();
  CHECK(planner.begin_choice(origin, look_disc, false, false) == StepOutcome::kTurnRound);
}

TEST(StepPlanner, AStepInsideTheLooksNavigablePolygonIsAMoveOfAtMostOneActionsLength) {
  CHECK(safe_cycle() == StepOutcome::kMove);
  CHECK(planner.decision().kind == StepKind::kMove);
  const float d = boticelli::core::distance_m({0.0F, 0.0F}, planner.target());
  CHECK(d >= params.step.min_step_m);
  CHECK(d <= params.value.step_m + 1e-5F);
  CHECK_FALSE(planner.gave_up());
}

TEST(StepPlanner, AChosenStepLeavingTheLooksPolygonIsNoSafeStepAndThePlaceCountsAsVisited) {
  // The robot stands 0.8 m from where the look was taken, near its polygon's edge; an
  // exploration point ahead draws the step out of the polygon (the chooser cuts the step to
  // the polygon as if it were seen from here).
  (void)map.exploration().push_back({1.6F, 0.0F});
  planner.start_value(map, g_grid, nullptr, {0.0F, 0.0F}, 1);
  CHECK(planner.value().sources().visited.empty());
  const Pose2 here{0.8F, 0.0F, 0.0F};
  CHECK(planner.begin_choice(here, look_disc, true, false) == StepOutcome::kChoosing);
  choose();
  CHECK(planner.end_choice(here, origin, look_disc, crumbs) == StepOutcome::kNoSafeStep);
  // The step the chooser found does leave the look's polygon.
  CHECK(planner.decision().kind == StepKind::kMove);
  CHECK_FALSE(look_disc.contains(to_robot(origin, planner.target())));
  // The place is on the trail the next value iteration is repelled by.
  planner.start_value(map, g_grid, nullptr, {0.8F, 0.0F}, 2);
  CHECK_EQUAL(1U, planner.value().sources().visited.size());
  DOUBLES_EQUAL(0.8, planner.value().sources().visited[0].x_m, 1e-6);
  CHECK(failed_cycle() == StepOutcome::kNoSafeStep);
  planner.start_value(map, g_grid, nullptr, {0.0F, 0.0F}, 3);
  CHECK_EQUAL(2U, planner.value().sources().visited.size());
}

TEST(StepPlanner, BacksOffAlongItsBreadcrumbsFromTheSecondCycleWithoutASafeStep) {
  crumbs.step_started({-1.0F, 0.5F});
  // The first such cycle looks again on the spot.
  CHECK(failed_cycle() == StepOutcome::kNoSafeStep);
  // The second backs off to where the last step began.
  CHECK(failed_cycle() == StepOutcome::kBackOff);
  CHECK(planner.decision().kind == StepKind::kMove);
  DOUBLES_EQUAL(-1.0, planner.target().x_m, 1e-6);
  DOUBLES_EQUAL(0.5, planner.target().y_m, 1e-6);
  CHECK_FALSE(planner.gave_up());
}

TEST(StepPlanner, WithNoBreadcrumbLeftTheSecondCycleWithoutASafeStepLooksAgain) {
  CHECK(failed_cycle() == StepOutcome::kNoSafeStep);
  CHECK(failed_cycle() == StepOutcome::kNoSafeStep);
}

TEST(StepPlanner, GivesUpAfterMaxFailedCyclesInARowAndDoesNotBackOffOnTheLast) {
  for (int i = 0; i < 8; ++i) crumbs.step_started({-1.0F - static_cast<float>(i), 0.0F});
  CHECK_EQUAL(4U, params.max_failed_cycles);
  CHECK(failed_cycle() == StepOutcome::kNoSafeStep);
  CHECK_FALSE(planner.gave_up());
  CHECK(failed_cycle() == StepOutcome::kBackOff);
  CHECK_FALSE(planner.gave_up());
  CHECK(failed_cycle() == StepOutcome::kBackOff);
  CHECK_FALSE(planner.gave_up());
  CHECK(failed_cycle() == StepOutcome::kNoSafeStep);
  CHECK_TRUE(planner.gave_up());
  // A new run starts counting afresh.
  planner.clear();
  CHECK_FALSE(planner.gave_up());
}

TEST(StepPlanner, ASafeMoveResetsTheCountOfCyclesWithoutASafeStep) {
  crumbs.step_started({-1.0F, 0.0F});
  CHECK(failed_cycle() == StepOutcome::kNoSafeStep);
  CHECK(safe_cycle() == StepOutcome::kMove);
  // The next failure is the first in a row again: a fresh look, not a back-off.
  CHECK(failed_cycle() == StepOutcome::kNoSafeStep);
  CHECK(failed_cycle() == StepOutcome::kBackOff);
  CHECK(safe_cycle() == StepOutcome::kMove);
  CHECK(failed_cycle() == StepOutcome::kNoSafeStep);
  CHECK(failed_cycle() == StepOutcome::kBackOff);
  CHECK(failed_cycle() == StepOutcome::kBackOff);
  CHECK_FALSE(planner.gave_up());
}

TEST(StepPlanner, WithinTheStandOffOfTheGoalTheRobotIsAtTheGoal) {
  const Point2 goal{0.5F, 0.0F};
  planner.start_value(map, g_grid, &goal, {0.0F, 0.0F}, 1);
  CHECK(planner.begin_choice(origin, look_disc, false, true) == StepOutcome::kChoosing);
  CHECK_TRUE(planner.choice_done());
  CHECK(planner.end_choice(origin, origin, look_disc, crumbs) == StepOutcome::kAtGoal);
}

// The consistency check samples the step from where the robot stands: from 0.7 m out along
// either axis, a step back towards the look's centre lies inside its 1 m polygon.
TEST(StepPlanner, FromNearTheLooksEdgeAStepBackAlongXTowardsItsCentreIsAMove) {
  (void)map.exploration().push_back({-0.9F, 0.0F});
  planner.start_value(map, g_grid, nullptr, {0.0F, 0.0F}, 1);
  const Pose2 here{0.7F, 0.0F, 0.0F};
  CHECK(cycle(here, origin) == StepOutcome::kMove);
  CHECK(planner.target().x_m < here.x_m - 0.2F);
}

TEST(StepPlanner, FromNearTheLooksEdgeAStepBackAlongYTowardsItsCentreIsAMove) {
  (void)map.exploration().push_back({0.0F, -0.9F});
  planner.start_value(map, g_grid, nullptr, {0.0F, 0.0F}, 1);
  const Pose2 here{0.0F, 0.7F, 0.0F};
  CHECK(cycle(here, origin) == StepOutcome::kMove);
  CHECK(planner.target().y_m < here.y_m - 0.2F);
}

// Seen from where the robot stands, each heading of the look's polygon reaches as far as the
// look allows whatever the robot's own heading: facing +x, it steps straight to its left.
TEST(StepPlanner, AnotherStepOnTheSameLookCanHeadSquareToTheRobotsOwnHeading) {
  (void)map.exploration().push_back({0.0F, 0.9F});
  planner.start_value(map, g_grid, nullptr, {0.0F, 0.0F}, 1);
  const Pose2 here{0.0F, -0.4F, 0.0F};
  CHECK_TRUE(planner.begin_next_on_look(here, origin, look_disc));
  choose();
  CHECK(planner.end_next_on_look() == StepOutcome::kMove);
  CHECK(planner.target().y_m > here.y_m + 0.3F);
  CHECK(std::fabs(planner.target().x_m) < 0.1F);
}

TEST(StepPlanner, AnotherStepOnTheSameLookIsRefusedWhenTheRobotStandsOutsideItsPolygon) {
  CHECK_FALSE(planner.begin_next_on_look({1.5F, 0.0F, 0.0F}, origin, look_disc));
  // A look taken elsewhere, its polygon seen from there.
  CHECK_FALSE(planner.begin_next_on_look(origin, {0.0F, 2.0F, 1.0F}, look_disc));
}

TEST(StepPlanner, AnotherStepOnTheSameLookStaysInsideTheLooksPolygonSeenFromWhereTheRobotIs) {
  // The robot took a step to near the polygon's edge; an exploration point ahead draws it on.
  (void)map.exploration().push_back({1.6F, 0.0F});
  planner.start_value(map, g_grid, nullptr, {0.0F, 0.0F}, 1);
  const Pose2 here{0.8F, 0.0F, 0.3F};
  CHECK_TRUE(planner.begin_next_on_look(here, origin, look_disc));
  choose();
  CHECK(planner.end_next_on_look() == StepOutcome::kMove);
  CHECK(planner.target().x_m > here.x_m);  // on towards the exploration point
  CHECK(look_disc.contains(to_robot(origin, planner.target())));
}

// A narrow notch cuts the look's 1 m disc from its centre outwards along +y (a thin post
// seen edge on). The robot stands left of it, an exploration point draws it right: seen from
// where the robot is, the heading along +x leaves the polygon at the notch and comes back
// into it beyond, and no step may cross the notch.
TEST(StepPlanner, AnotherStepOnTheSameLookEndsEachHeadingWhereItFirstLeavesThePolygon) {
  StarPolygon notched = disc(1.0F);
  for (std::size_t k = 0; k < notched.vertex_count(); ++k) {
    const float a = notched.angle_rad(k);
    if (std::fabs(a - 0.5F * boticelli::core::kPi<float>) <= 0.18F) notched.set_rho_m(k, 0.1F);
  }
  const Pose2 here{-0.2F, 0.4F, 0.0F};
  CHECK(!notched.contains({0.0F, 0.4F}));  // the notch lies across the heading
  CHECK(notched.contains({0.2F, 0.4F}));   // and the polygon goes on beyond it
  (void)map.exploration().push_back({1.0F, 0.4F});
  planner.start_value(map, g_grid, nullptr, {0.0F, 0.0F}, 1);
  CHECK_TRUE(planner.begin_next_on_look(here, origin, notched));
  choose();
  if (planner.end_next_on_look() != StepOutcome::kMove) return;  // no step: nothing crossed
  const Point2 target = planner.target();
  for (int i = 1; i <= 100; ++i) {
    const float t = static_cast<float>(i) / 100.0F;
    const Point2 p{here.x_m + t * (target.x_m - here.x_m), here.y_m + t * (target.y_m - here.y_m)};
    CHECK_TEXT(notched.contains(p), "the step crosses the notch");
  }
}

TEST(StepPlanner, AnotherStepOnTheSameLookIsNoSafeStepWhenThePolygonLeavesNoRoom) {
  const StarPolygon tiny = disc(0.04F);  // less than the shortest step in every direction
  CHECK_TRUE(planner.begin_next_on_look(origin, origin, tiny));
  choose();
  CHECK(planner.end_next_on_look() == StepOutcome::kNoSafeStep);
}

// The step is valued on the global map's obstacle points too: a short wall across
// the straight way to an exploration point turns the step aside, clear of the wall.
TEST(StepPlanner, AWallAcrossTheWayToAnExplorationPointTurnsTheStepAsideClearOfIt) {
  (void)map.exploration().push_back({1.6F, 0.0F});
  planner.start_value(map, g_grid, nullptr, {0.0F, 0.0F}, 1);
  CHECK(safe_cycle() == StepOutcome::kMove);
  const Point2 straight = planner.target();
  for (int i = -3; i <= 3; ++i)
    (void)map.obstacles().push_back({0.5F, 0.05F * static_cast<float>(i)});
  planner.start_value(map, g_grid, nullptr, {0.0F, 0.0F}, 1);
  CHECK(safe_cycle() == StepOutcome::kMove);
  const Point2 aside = planner.target();
  float straight_clear = 10.0F;
  float aside_clear = 10.0F;
  for (const Point2& o : map.obstacles().span()) {
    straight_clear = std::fmin(straight_clear, boticelli::core::distance_m(straight, o));
    aside_clear = std::fmin(aside_clear, boticelli::core::distance_m(aside, o));
  }
  // The straight step would end within the robot's radius of the wall; the step taken ends
  // beyond it, still on towards the exploration point.
  CHECK(straight_clear < params.value.robot_radius_m);
  CHECK(aside_clear > params.value.robot_radius_m);
  CHECK(aside.x_m > 0.1F);
}

// The consistency check covers the whole step, to its end: from places along the look's x axis
// near its edge, the step drawn outward by an exploration point beyond the polygon is a move
// exactly when its end lies in the look's (convex) polygon, and no safe step otherwise.
TEST(StepPlanner, AStepDrawnOutOfTheLooksPolygonIsAMoveExactlyWhenItsEndLiesInside) {
  (void)map.exploration().push_back({1.6F, 0.0F});
  planner.start_value(map, g_grid, nullptr, {0.0F, 0.0F}, 1);
  int moves = 0;
  int refused = 0;
  for (int k = 0; k <= 10; ++k) {
    planner.clear();
    const Pose2 here{0.555F + 0.01F * static_cast<float>(k), 0.0F, 0.0F};
    const StepOutcome outcome = cycle(here, origin);
    CHECK(planner.decision().kind == StepKind::kMove);
    const bool end_inside = look_disc.contains(to_robot(origin, planner.target()));
    CHECK_EQUAL(end_inside, outcome == StepOutcome::kMove);
    if (outcome == StepOutcome::kMove) ++moves;
    if (outcome == StepOutcome::kNoSafeStep) ++refused;
  }
  CHECK(moves > 0);
  CHECK(refused > 0);
}

// Seen from wherever the robot stands near the look's edge, off its axes and whatever the
// robot's heading, another step drawn outward stays inside the look's polygon all along.
TEST(StepPlanner, AnotherStepOnTheSameLookDrawnOutwardStaysInsideItsPolygonFromAnywhere) {
  for (int k = 0; k < 8; ++k) {
    const float b = 0.25F * boticelli::core::kPi<float> * static_cast<float>(k) + 0.3F;
    map.exploration().clear();
    (void)map.exploration().push_back({1.6F * std::cos(b), 1.6F * std::sin(b)});
    planner.start_value(map, g_grid, nullptr, {0.0F, 0.0F}, 1);
    const Pose2 here{0.75F * std::cos(b), 0.75F * std::sin(b), 1.1F * static_cast<float>(k)};
    CHECK_TRUE(planner.begin_next_on_look(here, origin, look_disc));
    choose();
    CHECK(planner.end_next_on_look() == StepOutcome::kMove);
    const Point2 target = planner.target();
    for (int i = 1; i <= 100; ++i) {
      const float t = static_cast<float>(i) / 100.0F;
      const Point2 p{here.x_m + t * (target.x_m - here.x_m),
                     here.y_m + t * (target.y_m - here.y_m)};
      CHECK_TEXT(look_disc.contains(p), "the step leaves the look's polygon");
    }
  }
}

namespace {

// A free square 3 m a side round the origin in the grid, unknown beyond: frontiers all round.
void free_square() {
  g_grid.configure({});
  for (int iy = -30; iy < 30; ++iy) {
    for (int ix = -30; ix < 30; ++ix) (void)g_grid.add({ix, iy}, -10);
  }
}

}  // namespace

namespace {

// The frontier planner on the world memory's grid.
MissionParams frontier_params() {
  BoardConfig config;
  config.thesis_planner = false;
  return make_mission_params(config);
}

}  // namespace

TEST_GROUP(FrontierStepPlanner) {
  const MissionParams params = frontier_params();
  StepPlanner planner{params};
  GlobalMap map;
  Breadcrumbs crumbs;
  const Pose2 origin{};

  void setup() override {
    planner.clear();
    free_square();
  }
  StepOutcome plan(const Pose2& here, const StarPolygon& navigable, const Point2* goal) {
    planner.start_value(map, g_grid, goal, {here.x_m, here.y_m}, 1);
    while (!planner.value_done()) planner.value_unit();
    const StepOutcome begun = planner.begin_choice(here, navigable, false, false);
    if (begun != StepOutcome::kChoosing) return begun;
    CHECK(planner.choice_done());
    return planner.end_choice(here, here, navigable, crumbs);
  }
};

TEST(FrontierStepPlanner, TheStepFollowsThePathToTheFrontierWithinTheLooksPolygon) {
  CHECK_FALSE(params.thesis_planner);
  const StarPolygon navigable = disc(0.6F);
  CHECK(plan(origin, navigable, nullptr) == StepOutcome::kMove);
  const float d = boticelli::core::distance_m({0.0F, 0.0F}, planner.target());
  CHECK(d > 0.4F);
  CHECK(d <= 0.6F);
  CHECK(planner.nav_choice().kind == boticelli::worldmap::NavGoalKind::kFrontier);
  // The step heads for the goal along the path.
  const Point2 g = planner.nav_choice().goal;
  const Point2 t = planner.target();
  CHECK(t.x_m * g.x_m + t.y_m * g.y_m > 0.0F);
}

TEST(FrontierStepPlanner, NoPathPointInsideTheLooksPolygonIsNoSafeStep) {
  CHECK(plan(origin, disc(0.02F), nullptr) == StepOutcome::kNoSafeStep);
}

TEST(FrontierStepPlanner, WithinTheStandOffOfTheTargetTheRobotIsAtTheGoal) {
  const Point2 target{0.5F, 0.0F};
  CHECK(plan(origin, disc(0.6F), &target) == StepOutcome::kAtGoal);
  const Point2 far{1.3F, 0.0F};
  CHECK(plan(origin, disc(0.6F), &far) == StepOutcome::kMove);
  CHECK(planner.nav_choice().kind == boticelli::worldmap::NavGoalKind::kTarget);
  CHECK(planner.target().x_m > 0.3F);
}

TEST(FrontierStepPlanner, TheRobotIsAtTheGoalWithinTheStandOffAndItsArrivalTolerance) {
  // Beyond the stand-off by less than the arrival tolerance: there; by twice it: not yet.
  const float standoff = params.rewards.goal_standoff_m;
  const float tolerance = params.step.arrival_tolerance_m;
  const Point2 near_enough{standoff + 0.6F * tolerance, 0.0F};
  CHECK(plan(origin, disc(0.6F), &near_enough) == StepOutcome::kAtGoal);
  const Point2 not_yet{standoff + 2.0F * tolerance, 0.0F};
  CHECK(plan(origin, disc(0.6F), &not_yet) != StepOutcome::kAtGoal);
}

// An occupied cell a quarter of a metre behind the robot: the cell it stands on is within
// the path's clearance of it (not passable), but the part of a step within half the robot's
// radius is the place it stands on, not the way ahead.
TEST(FrontierStepPlanner, ARobotWithinAnObstaclesClearanceStillStepsAwayFromIt) {
  (void)g_grid.add({-5, 0}, 20);
  CHECK(plan(origin, disc(0.6F), nullptr) == StepOutcome::kMove);
  CHECK_FALSE(planner.nav().passable({0.0F, 0.0F}));
  CHECK(boticelli::core::distance_m({0.0F, 0.0F}, planner.target()) > 0.3F);
}

TEST(FrontierStepPlanner, AStepAlongThePathIsAtMostNavStepLongEvenInAWidePolygon) {
  CHECK(plan(origin, disc(3.0F), nullptr) == StepOutcome::kMove);
  const float d = boticelli::core::distance_m({0.0F, 0.0F}, planner.target());
  CHECK(d > 0.5F);
  CHECK(d <= params.nav_step_m + 1e-5F);
}

// Wherever the robot stands in its cell, a move along the path is at least the minimum step:
// the path runs from the robot's cell down its column (0.05 m cells), and the look's polygon
// (0.06 m round the robot) reaches the path's next cell, nearer than the minimum step from the
// cell's lower half, just far enough from its middle, and not at all from its upper part.
TEST(FrontierStepPlanner, AMoveAlongThePathIsNeverShorterThanTheMinimumStep) {
  const StarPolygon navigable = disc(0.06F);
  int moves = 0;
  int refused = 0;
  for (const float dy : {-0.02F, -0.01F, 0.0F, 0.01F}) {
    for (const float dx : {-0.012F, 0.003F, 0.017F}) {
      planner.clear();
      const Pose2 here{0.025F + dx, 0.025F + dy, 0.0F};
      const StepOutcome outcome = plan(here, navigable, nullptr);
      if (outcome == StepOutcome::kMove) {
        ++moves;
        CHECK(boticelli::core::distance_m({here.x_m, here.y_m}, planner.target()) >=
              params.step.min_step_m);
      } else {
        CHECK(outcome == StepOutcome::kNoSafeStep);
        ++refused;
      }
    }
  }
  CHECK(moves > 0);
  CHECK(refused > 0);
}

TEST(FrontierStepPlanner, AGridWithNothingReachableTurnsRoundThenEnds) {
  g_grid.configure({});  // nothing known
  CHECK(plan(origin, disc(0.6F), nullptr) == StepOutcome::kTurnRound);
  planner.turned_round_at({0.0F, 0.0F});
  CHECK(plan(origin, disc(0.6F), nullptr) == StepOutcome::kNothingLeft);
}

TEST_GROUP(ThesisPlannerTargetByPath) {
  MissionParams params = thesis_params();  // the planner reads it by reference
  StepPlanner planner{params};
  GlobalMap map;
  Breadcrumbs crumbs;
  const Pose2 origin{};
  const StarPolygon look = disc(0.6F);  // the chooser keeps it: it must outlive the choice

  void setup() override {
    planner.clear();
    free_square();
  }
  // plan() from a robot at `here` that looked where it stands.
  StepOutcome plan_from(const Pose2& here, const Point2* goal) {
    return plan_from(here, goal, look, here);
  }
  // The same with the look's polygon `navigable`, taken at `look_pose`.
  StepOutcome plan_from(const Pose2& here, const Point2* goal, const StarPolygon& navigable,
                        const Pose2& look_pose) {
    planner.start_value(map, g_grid, goal, {here.x_m, here.y_m}, 1);
    while (!planner.value_done()) planner.value_unit();
    const StepOutcome begun = planner.begin_choice(here, navigable, true, goal != nullptr);
    if (begun != StepOutcome::kChoosing) return begun;
    while (!planner.choice_done()) planner.choose_heading();
    return planner.end_choice(here, look_pose, navigable, crumbs);
  }
  StepOutcome plan(const Point2* goal) {
    planner.start_value(map, g_grid, goal, {0.0F, 0.0F}, 1);
    while (!planner.value_done()) planner.value_unit();
    const StepOutcome begun = planner.begin_choice(origin, look, true, goal != nullptr);
    if (begun != StepOutcome::kChoosing) return begun;
    while (!planner.choice_done()) planner.choose_heading();
    return planner.end_choice(origin, origin, look, crumbs);
  }
};

TEST(ThesisPlannerTargetByPath, AConfirmedTargetWithAPathOnTheGridIsApproachedAlongIt) {
  CHECK(params.target_by_path);
  params.final_approach_m = 0.0F;  // the path's step alone (the final approach below)
  const Point2 target{1.3F, 0.9F};
  CHECK(plan(&target) == StepOutcome::kMove);
  CHECK(planner.nav_choice().kind == boticelli::worldmap::NavGoalKind::kTarget);
  // The step is the path's, cut to the look's polygon (0.6 m): longer than one action of the
  // value function, on toward the stand-off cell.
  const Point2 t = planner.target();
  CHECK(boticelli::core::distance_m({0.0F, 0.0F}, t) <= 0.6F + 1e-5F);
  CHECK(boticelli::core::distance_m({0.0F, 0.0F}, t) > params.value.step_m);
  const Point2 g = planner.nav_choice().goal;
  CHECK(boticelli::core::distance_m(t, g) < boticelli::core::distance_m({0.0F, 0.0F}, g));
}

TEST(ThesisPlannerTargetByPath, NearTheStandOffTheGridTakesTheRobotThereBeyondThePolygon) {
  const Point2 target{1.3F, 0.9F};
  CHECK(plan(&target) == StepOutcome::kMove);
  // The stand-off cell is within the final approach (1 m): the step ends there, beyond the
  // look's polygon (0.6 m), the way there being free on the grid.
  const Point2 t = planner.target();
  const Point2 g = planner.nav_choice().goal;
  CHECK(boticelli::core::distance_m({0.0F, 0.0F}, t) > 0.6F + 0.05F);
  CHECK(boticelli::core::distance_m({0.0F, 0.0F}, t) <= params.final_approach_m);
  DOUBLES_EQUAL(g.x_m, t.x_m, 0.051);
  DOUBLES_EQUAL(g.y_m, t.y_m, 0.051);
}

TEST(ThesisPlannerTargetByPath, AnObstacleOnTheStraightWayLeavesTheStepToThePolygon) {
  // A wall across the straight way to the stand-off, the path round it.
  for (int iy = -4; iy <= 12; ++iy) (void)g_grid.add({10, iy}, 20);
  const Point2 target{1.3F, 0.1F};
  CHECK(plan(&target) == StepOutcome::kMove);
  CHECK(planner.nav_choice().kind == boticelli::worldmap::NavGoalKind::kTarget);
  CHECK(boticelli::core::distance_m({0.0F, 0.0F}, planner.target()) <= 0.6F + 1e-5F);
}

TEST(ThesisPlannerTargetByPath, WithoutAPathToTheStandOffTheValueFunctionChoosesTheStep) {
  g_grid.configure({});  // nothing known: no path anywhere
  const Point2 target{1.3F, 0.9F};
  CHECK(plan(&target) == StepOutcome::kMove);
  CHECK(planner.nav_choice().kind == boticelli::worldmap::NavGoalKind::kNone);
  // A step of the value function: one action's length at most.
  CHECK(boticelli::core::distance_m({0.0F, 0.0F}, planner.target()) <= params.value.step_m + 1e-5F);
}

// A provisional goal (a candidate not yet confirmed) is approached by path as a confirmed one
// is; one the grid shows no way to draws no cone and is no goal: with nothing to explore the
// robot turns round, where a confirmed goal out of reach keeps it choosing by the cones.
TEST(ThesisPlannerTargetByPath, AProvisionalGoalIsAGoalOnlyWhenTheGridShowsAWayToItsStandOff) {
  const auto begin = [&](const Point2& goal, bool provisional) {
    planner.start_value(map, g_grid, &goal, {0.0F, 0.0F}, 1, provisional);
    CHECK(planner.value().sources().has_goal == !provisional);
    while (!planner.value_done()) planner.value_unit();
    return planner.begin_choice(origin, look, false, true);
  };
  params.final_approach_m = 0.0F;
  CHECK(begin({1.3F, 0.9F}, true) == StepOutcome::kChoosing);
  while (!planner.choice_done()) planner.choose_heading();
  CHECK(planner.end_choice(origin, origin, look, crumbs) == StepOutcome::kMove);
  CHECK(planner.nav_choice().kind == boticelli::worldmap::NavGoalKind::kTarget);
  CHECK(begin({20.0F, 0.0F}, true) == StepOutcome::kTurnRound);
  CHECK(begin({20.0F, 0.0F}, false) == StepOutcome::kChoosing);
}

TEST(ThesisPlannerTargetByPath, NoTargetNoWavefront) {
  CHECK(plan(nullptr) == StepOutcome::kMove);
  CHECK(planner.nav_choice().kind == boticelli::worldmap::NavGoalKind::kNone);
  CHECK_FALSE(planner.nav().done());
}

// The final approach seen from a robot away from the origin (the look taken where it stands):
// the step ends at the stand-off cell, heading there.
TEST(ThesisPlannerTargetByPath, TheFinalApproachFromAnywhereEndsAtTheStandOffHeadingThere) {
  const Pose2 here{-0.5F, -0.3F, 0.4F};
  const Point2 target{0.8F, 0.6F};
  CHECK(plan_from(here, &target) == StepOutcome::kMove);
  const Point2 t = planner.target();
  const Point2 g = planner.nav_choice().goal;
  const Point2 at{here.x_m, here.y_m};
  CHECK(boticelli::core::distance_m(at, t) > 0.6F + 0.05F);  // beyond the look's polygon
  DOUBLES_EQUAL(g.x_m, t.x_m, 0.051);
  DOUBLES_EQUAL(g.y_m, t.y_m, 0.051);
  DOUBLES_EQUAL(std::atan2(t.y_m - at.y_m, t.x_m - at.x_m), planner.decision().heading_rad, 1e-5);
  DOUBLES_EQUAL(boticelli::core::distance_m(at, t), planner.decision().distance_m, 1e-5);
}

// A final approach is a move beyond the look's polygon only for that cycle: a later step of
// the value function (no path on the grid now) that leaves its look's polygon is no safe step.
TEST(ThesisPlannerTargetByPath, AfterAFinalApproachAStepLeavingTheLooksPolygonIsNoSafeStep) {
  const Point2 target{1.3F, 0.9F};
  CHECK(plan(&target) == StepOutcome::kMove);
  CHECK(boticelli::core::distance_m({0.0F, 0.0F}, planner.target()) > 0.6F + 0.05F);
  g_grid.configure({});  // nothing known: no path anywhere
  planner.start_value(map, g_grid, &target, {0.0F, 0.0F}, 2);
  while (!planner.value_done()) planner.value_unit();
  CHECK(planner.begin_choice(origin, look, true, true) == StepOutcome::kChoosing);
  while (!planner.choice_done()) planner.choose_heading();
  // The look was taken 5 m away: no step from here lies in its polygon.
  CHECK(planner.end_choice(origin, {5.0F, 0.0F, 0.0F}, look, crumbs) == StepOutcome::kNoSafeStep);
}

// The final approach goes by the grid alone: it is a move even when the look's polygon holds
// no step at all.
TEST(ThesisPlannerTargetByPath,
     NearTheStandOffTheFinalApproachIsAMoveEvenIfTheLooksPolygonHoldsNoStep) {
  const Point2 target{1.3F, 0.9F};
  const StarPolygon cramped = disc(0.02F);
  CHECK(plan_from(origin, &target, cramped, origin) == StepOutcome::kMove);
  const Point2 g = planner.nav_choice().goal;
  DOUBLES_EQUAL(g.x_m, planner.target().x_m, 0.051);
  DOUBLES_EQUAL(g.y_m, planner.target().y_m, 0.051);
}

// The path's step is sampled from where the robot stands: 0.3 m below the look's centre, the
// path up and to the right stays inside the look's 0.6 m polygon for more than one action.
TEST(ThesisPlannerTargetByPath, ThePathsStepFromBesideTheLooksCentreStaysInsideItsPolygon) {
  params.final_approach_m = 0.0F;  // the path's step alone
  const Pose2 here{0.0F, -0.3F, 0.0F};
  const Point2 target{1.3F, 0.9F};
  CHECK(plan_from(here, &target, look, origin) == StepOutcome::kMove);
  const Point2 t = planner.target();
  CHECK(look.contains(to_robot(origin, t)));
  CHECK(boticelli::core::distance_m({here.x_m, here.y_m}, t) > params.value.step_m);
}

// The final approach checks the whole straight way on the grid: an obstacle whose clearance
// reaches across the far part of the way to the stand-off (not the stand-off itself, nor the
// way's near half) leaves the step to the look's polygon.
TEST(ThesisPlannerTargetByPath, AnObstacleAcrossTheFarPartOfTheWayLeavesTheStepToThePolygon) {
  const Point2 target{1.0F, 1.0F};
  (void)g_grid.add({8, 8}, 20);  // the cell from (0.4, 0.4) to (0.45, 0.45)
  CHECK(plan(&target) == StepOutcome::kMove);
  const Point2 g = planner.nav_choice().goal;
  const float way = boticelli::core::distance_m({0.0F, 0.0F}, g);
  CHECK(way > 0.6F && way <= params.final_approach_m);  // a final approach but for the obstacle
  float first_blocked = 2.0F;
  for (int i = 1; i <= 100; ++i) {
    const float s = static_cast<float>(i) / 100.0F;
    if (!planner.nav().passable({s * g.x_m, s * g.y_m}))
      first_blocked = std::fmin(first_blocked, s);
  }
  CHECK(first_blocked > 0.5F && first_blocked < 1.0F);
  CHECK(boticelli::core::distance_m({0.0F, 0.0F}, planner.target()) <= 0.6F + 1e-5F);
}

// The target itself is an obstacle on the grid: the final approach ends at its stand-off, the
// way there being free, whatever lies beyond the stand-off.
TEST(ThesisPlannerTargetByPath, TheFinalApproachToATargetThatIsAnObstacleEndsAtItsStandOff) {
  const Point2 target{1.0F, 1.0F};
  (void)g_grid.add({20, 20}, 20);  // the target's own cell
  CHECK(plan(&target) == StepOutcome::kMove);
  const Point2 g = planner.nav_choice().goal;
  const Point2 t = planner.target();
  CHECK(boticelli::core::distance_m({0.0F, 0.0F}, t) > 0.6F + 0.05F);
  DOUBLES_EQUAL(g.x_m, t.x_m, 0.051);
  DOUBLES_EQUAL(g.y_m, t.y_m, 0.051);
}

// A robot standing at a cell's centre within an occupied cell's clearance (its own cell and the
// three ahead along the path are not passable) steps along the path to the target: the part of
// the step nearer than half the robot's radius is the place it stands on; from there on, the
// step's straight way crosses passable cells only.
TEST(ThesisPlannerTargetByPath, ARobotWithinAnObstaclesClearanceStepsOnlyAcrossPassableCells) {
  params.final_approach_m = 0.0F;  // the path's step alone
  (void)g_grid.add({-5, 0}, 20);
  const float cell = g_grid.cell_m();
  const Pose2 here{-2.5F * cell, 0.5F * cell, 0.0F};
  const Point2 target{1.4F, 0.5F * cell};
  const StarPolygon wide = disc(1.5F);
  CHECK(plan_from(here, &target, wide, here) == StepOutcome::kMove);
  const Point2 at{here.x_m, here.y_m};
  CHECK_FALSE(planner.nav().passable(at));
  CHECK_FALSE(planner.nav().passable({0.5F * cell, at.y_m}));
  CHECK_TRUE(planner.nav().passable({1.5F * cell, at.y_m}));
  const Point2 t = planner.target();
  CHECK(boticelli::core::distance_m(at, t) >= params.step.min_step_m);
  const float own = 0.5F * params.nav.robot_radius_m;
  for (int i = 1; i <= 100; ++i) {
    const float s = static_cast<float>(i) / 100.0F;
    const Point2 p{at.x_m + s * (t.x_m - at.x_m), at.y_m + s * (t.y_m - at.y_m)};
    if (boticelli::core::distance_m(p, at) < own) continue;
    CHECK_TEXT(planner.nav().passable(p), "the step crosses a cell within the clearance");
  }
}
