// Tests of the planner in a small 2-D world: rewards, value iteration, policy and safe steps.
#include <array>
#include <cmath>
#include <cstddef>
#include <cstdint>

#include "algo/core/fixed_vector.h"
#include "algo/mapping/extraction.h"
#include "algo/mapping/map_points.h"
#include "algo/mapping/polygon_ops.h"
#include "algo/mapping/star_polygon.h"
#include "algo/planning/planner.h"
#include "algo/planning/rewards.h"
#include "algo/planning/value_iteration.h"
#include "polygon_fixtures.h"

#include "CppUTest/TestHarness.h"
#include "alloc_guard.h"

using boticelli::core::FixedVector;
using boticelli::core::Point2;
using boticelli::core::Pose2;
using boticelli::test::Wall;
namespace mapping = boticelli::mapping;
namespace planning = boticelli::planning;

namespace {

constexpr float kBoundM = 3.0F;
constexpr float kRobotRadiusM = 0.2F;
constexpr std::size_t kMaxWalls = 12;
constexpr std::size_t kTestStates = 100;
constexpr std::size_t kTestSweeps = 10;
constexpr std::size_t kTestFitRounds = 5;
constexpr std::size_t kTestFitPasses = 2;

// A robot in a world of wall segments: it sees the walls as the free polygon would show
// them (ray cast at the polygon's vertex angles, bounded), keeps global lists, plans and
// moves. Everything is static: the planner's objects are large.
struct TestWorld {
  std::array<Wall, kMaxWalls> walls{};
  std::size_t wall_count = 0;
  Pose2 pose{};
  mapping::StarPolygon free{360};
  mapping::StarPolygon navigable{360};
  mapping::GlobalMap global;
  mapping::MapPointParams point_params;
  FixedVector<Point2, 512> obstacles;
  FixedVector<Point2, 512> exploration;
  planning::ValueIteration value;
  planning::ValueIterationParams vi_params;
  planning::RewardParams reward_params;
  planning::StepParams step_params;
  planning::Trail trail;
  bool has_goal = false;
  Point2 goal{};
  float worst_path_clearance_m = 1e9F;  // brute force: robot disc to the walls, along steps
  bool stepped_outside_polygon = false;

  void reset(Pose2 start) {
    wall_count = 0;
    pose = start;
    global.clear();
    trail.clear();
    has_goal = false;
    worst_path_clearance_m = 1e9F;
    stepped_outside_polygon = false;
    // A lighter plan than the robot's defaults keeps the test fast under sanitizers and
    // emulation: fewer states, sweeps and fitting passes.
    vi_params = planning::ValueIterationParams{};
    vi_params.state_count = kTestStates;
    vi_params.sweeps = kTestSweeps;
    vi_params.fit_rounds = kTestFitRounds;
    vi_params.fit_passes = kTestFitPasses;
    reward_params = planning::RewardParams{};
  }
  void add_wall(Point2 a, Point2 b) { walls[wall_count++] = {a, b}; }
  // A wall 5 cm thick along x = x_m from y0 to y1 (a segment alone would vanish for rays
  // running along its own line).
  void add_thick_wall(float x_m, float y0_m, float y1_m) {
    constexpr float kHalf = 0.025F;
    add_wall({x_m - kHalf, y0_m}, {x_m + kHalf, y0_m});
    add_wall({x_m + kHalf, y0_m}, {x_m + kHalf, y1_m});
    add_wall({x_m + kHalf, y1_m}, {x_m - kHalf, y1_m});
    add_wall({x_m - kHalf, y1_m}, {x_m - kHalf, y0_m});
  }

  void observe() {
    for (std::size_t k = 0; k < free.vertex_count(); ++k) {
      const float r = boticelli::test::cast_ray_m(walls, wall_count, {pose.x_m, pose.y_m},
                                                  free.angle_rad(k) + pose.yaw_rad);
      free.set_rho_m(k, std::fmin(r, kBoundM));
    }
    // As extract_local_map does: the robot radius plus the margin for wall ends between rays.
    (void)mapping::shrink_for_robot(free, kRobotRadiusM,
                                    mapping::ExtractionParams{}.clearance_margin_m, navigable);
    obstacles.clear();
    exploration.clear();
    (void)mapping::extract_map_points(free, kBoundM, point_params, obstacles, exploration);
    (void)global.merge(pose, free, kBoundM, obstacles, exploration, point_params);
  }

  planning::RewardSources sources() const {
    return {global.obstacles().span(), global.exploration().span(), trail.points(), has_goal, goal};
  }

  planning::StepDecision plan() {
    value.start(vi_params, reward_params, sources(), {pose.x_m, pose.y_m});
    while (!value.run_unit(4096)) {
    }
    return planning::choose_step(value, navigable, pose, step_params);
  }

  // One Look-Think-Drive cycle; returns the decision taken.
  planning::StepKind cycle() {
    observe();
    trail.add({pose.x_m, pose.y_m});
    const planning::StepDecision d = plan();
    if (d.kind != planning::StepKind::kMove) {
      return d.kind;
    }
    // The step must stay in the navigation polygon (robot frame) and, by brute force, keep
    // the robot's disc off every wall all along the straight move.
    const Point2 local = boticelli::core::to_robot(pose, d.target);
    if (!navigable.contains(local) ||
        mapping::sweep_clearance_m(free, local) < kRobotRadiusM - 1e-4F) {
      stepped_outside_polygon = true;
    }
    for (int i = 0; i <= 10; ++i) {
      const float t = static_cast<float>(i) / 10.0F;
      const Point2 p{pose.x_m + t * (d.target.x_m - pose.x_m),
                     pose.y_m + t * (d.target.y_m - pose.y_m)};
      worst_path_clearance_m = std::fmin(worst_path_clearance_m,
                                         boticelli::test::wall_clearance_m(walls, wall_count, p));
    }
    pose = {d.target.x_m, d.target.y_m, d.heading_rad};
    return d.kind;
  }

  // Runs cycles until the robot arrives or gives up; returns the cycles used (max_cycles+1 if
  // it never arrived).
  int run(int max_cycles) {
    for (int c = 0; c < max_cycles; ++c) {
      const planning::StepKind k = cycle();
      if (k == planning::StepKind::kAtGoal) {
        return c;
      }
      if (k == planning::StepKind::kNoSafeAction) {
        return max_cycles + 1;
      }
    }
    return max_cycles + 1;
  }

  void add_room(float half_size) {
    add_wall({-half_size, -half_size}, {half_size, -half_size});
    add_wall({half_size, -half_size}, {half_size, half_size});
    add_wall({half_size, half_size}, {-half_size, half_size});
    add_wall({-half_size, half_size}, {-half_size, -half_size});
  }
};

TestWorld& world() {
  static TestWorld w;
  return w;
}

}  // namespace

TEST_GROUP(Rewards){};

namespace {
// Cone parameters of the reward tests (not the defaults, so the tests say what they check).
planning::RewardParams cone_params() {
  planning::RewardParams p;
  p.obstacle_apex = -1.0F;
  p.obstacle_slope_per_m = 2.5F;
  p.exploration_apex = 0.3F;
  p.exploration_slope_per_m = 0.3F;
  p.goal_apex = 3.0F;
  p.goal_slope_per_m = 0.3F;
  p.goal_clear_radius_m = 0.8F;
  return p;
}
}  // namespace

TEST(Rewards, ConesFollowEquationsFiveNineToFiveEleven) {
  const planning::RewardParams p = cone_params();
  const std::array<Point2, 1> obstacle{{{1.0F, 0.0F}}};
  const std::array<Point2, 1> exploration{{{0.0F, 3.0F}}};
  planning::RewardSources s{obstacle, exploration, {}, true, {-2.0F, 0.0F}};
  // At (1.2, 0): obstacle −1 + 2.5·0.2 = −0.5; exploration 0.3 − 0.3·√(1.44+9) < 0 → 0;
  // goal 3 − 0.3·3.2 = 2.04.
  DOUBLES_EQUAL(-0.5 + 2.04, planning::reward_at(p, s, {1.2F, 0.0F}), 1e-5);
  // At (0, 2.5): obstacle cone is 0 that far; exploration 0.3 − 0.3·0.5; goal 3 − 0.3·√10.25.
  DOUBLES_EQUAL(0.15 + 3.0 - 0.3 * std::sqrt(10.25), planning::reward_at(p, s, {0.0F, 2.5F}), 1e-5);
}

TEST(Rewards, ObstaclePointsAtTheGoalDoNotRepel) {
  // §6.4: the goal on a wall. Its wall's points within the clear radius give no penalty.
  planning::RewardParams p = cone_params();
  const std::array<Point2, 3> wall{{{2.0F, -0.15F}, {2.0F, 0.0F}, {2.0F, 0.15F}}};
  planning::RewardSources s{wall, {}, {}, true, {2.0F, 0.0F}};
  DOUBLES_EQUAL(3.0 - 0.3 * 0.2, planning::reward_at(p, s, {1.8F, 0.0F}), 1e-5);
  p.goal_clear_radius_m = 0.0F;  // the thesis's behaviour: the goal's wall repels
  CHECK_TRUE(planning::reward_at(p, s, {1.8F, 0.0F}) < 3.0F - 0.3F * 0.2F - 1.0F);
}

TEST_GROUP(Planner){};

TEST(Planner, ReachesAVisibleGoalInOpenSpaceAndStopsAtTheStandOff) {
  TestWorld& w = world();
  w.reset({0.0F, 0.0F, 0.0F});
  w.add_room(4.0F);
  w.has_goal = true;
  w.goal = {2.5F, 1.2F};
  const int cycles = w.run(30);
  CHECK_TRUE(cycles <= 30);
  const float d = boticelli::core::distance_m({w.pose.x_m, w.pose.y_m}, w.goal);
  CHECK_TRUE(d <= w.reward_params.goal_standoff_m + w.step_params.arrival_tolerance_m);
  CHECK_TRUE(d >= w.reward_params.goal_standoff_m - 1e-3F);
  CHECK_FALSE(w.stepped_outside_polygon);
  CHECK_TRUE(w.worst_path_clearance_m >= kRobotRadiusM);
}

TEST(Planner, GoesAroundAWallToAGoalBehindIt) {
  TestWorld& w = world();
  w.reset({0.0F, 0.0F, 0.0F});
  w.add_room(4.0F);
  w.add_thick_wall(1.2F, -1.2F, 1.2F);
  w.has_goal = true;
  w.goal = {2.6F, 0.0F};
  const int cycles = w.run(60);
  CHECK_TRUE(cycles <= 60);
  const float d = boticelli::core::distance_m({w.pose.x_m, w.pose.y_m}, w.goal);
  CHECK_TRUE(d <= w.reward_params.goal_standoff_m + w.step_params.arrival_tolerance_m);
  CHECK_FALSE(w.stepped_outside_polygon);
  CHECK_TRUE(w.worst_path_clearance_m >= kRobotRadiusM);
}

TEST(Planner, ApproachesAGoalOnAWallUpToTheStandOff) {
  // The goal is a mark on a wall: its own obstacle points must not keep the robot away.
  TestWorld& w = world();
  w.reset({0.0F, 0.0F, 0.0F});
  w.add_room(4.0F);
  w.add_thick_wall(2.2F, -1.0F, 1.0F);
  w.has_goal = true;
  w.goal = {2.2F, 0.3F};
  const int cycles = w.run(30);
  CHECK_TRUE(cycles <= 30);
  const float d = boticelli::core::distance_m({w.pose.x_m, w.pose.y_m}, w.goal);
  CHECK_TRUE(d <= w.reward_params.goal_standoff_m + w.step_params.arrival_tolerance_m);
  CHECK_TRUE(d >= w.reward_params.goal_standoff_m - 1e-3F);
  CHECK_FALSE(w.stepped_outside_polygon);
  CHECK_TRUE(w.worst_path_clearance_m >= kRobotRadiusM);
}

TEST(Planner, SaysSoWhenNoActionIsSafe) {
  TestWorld& w = world();
  w.reset({0.0F, 0.0F, 0.0F});
  // A tight box: the robot's disc fits, but no step of 5 cm does in any direction.
  w.add_room(0.23F);
  w.has_goal = true;
  w.goal = {2.0F, 0.0F};
  CHECK_TRUE(w.cycle() == planning::StepKind::kNoSafeAction);
  LONGS_EQUAL(0, w.pose.x_m);
}

TEST(Planner, CutsTheStepToTheNavigationPolygon) {
  mapping::StarPolygon nav(360);
  nav.fill(1.0F);
  nav.set_rho_m(0, 0.1F);  // little room straight ahead (robot frame)
  const Pose2 pose{0.0F, 0.0F, 0.5F};
  DOUBLES_EQUAL(0.1, planning::cut_step_m(nav, pose, 0.5F, 0.3F), 1e-5);
  DOUBLES_EQUAL(0.3, planning::cut_step_m(nav, pose, 0.5F + 1.5F, 0.3F), 1e-6);
}

TEST(Planner, TheStepChooserTakesOneActionPerUnitAndEndsOnTheWholeDecision) {
  TestWorld& w = world();
  w.reset({0.0F, 0.0F, 0.3F});
  w.add_room(4.0F);
  w.add_thick_wall(1.2F, -1.2F, 1.2F);
  w.has_goal = true;
  w.goal = {2.5F, 0.0F};
  w.observe();
  w.value.start(w.vi_params, w.reward_params, w.sources(), {w.pose.x_m, w.pose.y_m});
  while (!w.value.run_unit(4096)) {
  }
  planning::StepChooser chooser;
  chooser.start(w.value, w.navigable, w.pose, w.step_params);
  std::size_t units = 0;
  float best_q = -1e30F;
  while (!chooser.done()) {
    ++units;
    (void)chooser.run_unit();
    // The running best never gets worse as more actions are evaluated.
    if (chooser.decision().kind == planning::StepKind::kMove) {
      CHECK(chooser.decision().q_value >= best_q);
      best_q = chooser.decision().q_value;
    }
  }
  CHECK_EQUAL(planning::kActionCount, units);
  CHECK(chooser.run_unit());  // done stays done
  const planning::StepDecision& d = chooser.decision();
  CHECK(d.kind == planning::StepKind::kMove);
  // With the wall ahead the best move goes round it, not into it.
  CHECK(std::fabs(d.target.y_m - w.pose.y_m) > 0.05F);
  // At the goal's stand-off nothing is left to evaluate.
  w.pose = {2.5F - w.reward_params.goal_standoff_m, 0.0F, 0.0F};
  chooser.start(w.value, w.navigable, w.pose, w.step_params);
  CHECK(chooser.done());
  CHECK(chooser.decision().kind == planning::StepKind::kAtGoal);
}

// Room to move only in a wedge at 18-27° (a doorway askew to the frame): none of the eight
// actions has a step there, sixteen headings have one at 22.5°.
TEST(Planner, SixteenStepHeadingsFindAWayBetweenTheEightActions) {
  TestWorld& w = world();
  w.reset({0.0F, 0.0F, 0.0F});
  w.add_room(4.0F);
  constexpr float kWay_rad = 22.5F * 3.14159265F / 180.0F;
  w.has_goal = true;
  w.goal = {2.5F * std::cos(kWay_rad), 2.5F * std::sin(kWay_rad)};
  w.value.start(w.vi_params, w.reward_params, w.sources(), {w.pose.x_m, w.pose.y_m});
  while (!w.value.run_unit(4096)) {
  }
  mapping::StarPolygon nav(360);
  nav.fill(0.02F);
  for (std::size_t k = 18; k <= 27; ++k) nav.set_rho_m(k, 1.0F);
  planning::StepParams params = w.step_params;
  CHECK(planning::choose_step(w.value, nav, w.pose, params).kind ==
        planning::StepKind::kNoSafeAction);
  params.step_headings = 16;
  const planning::StepDecision d = planning::choose_step(w.value, nav, w.pose, params);
  CHECK(d.kind == planning::StepKind::kMove);
  DOUBLES_EQUAL(kWay_rad, d.heading_rad, 1e-5);
  CHECK_EQUAL(1U, d.action);
  DOUBLES_EQUAL(w.vi_params.step_m, d.distance_m, 1e-5);
  // One heading per unit.
  planning::StepChooser chooser;
  chooser.start(w.value, nav, w.pose, params);
  std::size_t units = 0;
  while (!chooser.done()) {
    ++units;
    (void)chooser.run_unit();
  }
  CHECK_EQUAL(16U, units);
}

TEST(Planner, SlicedValueIterationEqualsOneShot) {
  static planning::ValueIteration sliced;
  static planning::ValueIteration whole;
  const std::array<Point2, 4> obstacles{
      {{1.0F, 0.0F}, {1.0F, 0.15F}, {1.0F, 0.3F}, {1.0F, -0.15F}}};
  const std::array<Point2, 2> exploration{{{-2.0F, 1.0F}, {0.0F, 3.0F}}};
  const planning::RewardSources s{obstacles, exploration, {}, true, {2.0F, 0.5F}};
  planning::ValueIterationParams p;
  p.state_count = 120;
  p.sweeps = 6;
  sliced.start(p, planning::RewardParams{}, s, {0.0F, 0.0F});
  whole.start(p, planning::RewardParams{}, s, {0.0F, 0.0F});
  int slices = 0;
  while (!sliced.run_unit(37)) {
    ++slices;
  }
  CHECK_TRUE(whole.run_unit(1000000000));
  CHECK_TRUE(slices > 20);
  LONGS_EQUAL(6, whole.sweeps_done());
  for (float x = -3.0F; x <= 3.0F; x += 0.5F) {
    for (float y = -3.0F; y <= 3.0F; y += 0.5F) {
      DOUBLES_EQUAL(whole.value({x, y}), sliced.value({x, y}), 0.0);
    }
  }
  // The value function rises towards the goal.
  CHECK_TRUE(whole.value({1.8F, 0.8F}) > whole.value({-2.5F, -2.5F}));
}

TEST(Planner, ValueIterationAndStepSelectionDoNotAllocate) {
  TestWorld& w = world();
  w.reset({0.0F, 0.0F, 0.0F});
  w.add_room(4.0F);
  w.add_thick_wall(1.2F, -1.2F, 1.2F);
  w.has_goal = true;
  w.goal = {2.6F, 0.0F};
  planning::StepDecision d;
  CHECK_NO_ALLOCATION({
    w.observe();
    d = w.plan();
  });
  CHECK_TRUE(d.kind == planning::StepKind::kMove);
}
