// StepPlanner: value iteration, the step and its outcome (see step_planner.h).
#include "firmware/mission/plan/step_planner.h"

#include <cmath>

namespace boticelli::firmware::mission {

void StepPlanner::clear() {
  nav_.reset();
  nav_choice_ = {};
  trail_.clear();
  failed_cycles_ = 0;
  turned_round_ = false;
}

void StepPlanner::start_value(const mapping::GlobalMap& map, const worldmap::GridMap& grid,
                              const core::Point2* goal, core::Point2 centre, std::uint32_t seed,
                              bool provisional) {
  has_goal_ = goal != nullptr;
  provisional_ = has_goal_ && provisional;
  if (has_goal_) goal_ = *goal;
  path_mode_ = !params_.thesis_planner;
  // The wavefront: for the frontier planner, and for the thesis's too once the target is
  // confirmed (its stand-off is then reached by path where the grid shows one).
  nav_needed_ = !params_.thesis_planner || (has_goal_ && params_.target_by_path);
  nav_choice_ = {};
  if (nav_needed_) nav_.start(grid, centre, params_.nav);
  if (!params_.thesis_planner) return;
  planning::RewardSources sources;
  sources.obstacles = map.obstacles().span();
  sources.exploration = map.exploration().span();
  sources.visited = trail_.points();
  sources.has_goal = has_goal_ && !provisional_;
  if (sources.has_goal) sources.goal = *goal;
  planning::ValueIterationParams vp = params_.value;
  vp.seed = seed;
  value_.start(vp, params_.rewards, sources, centre);
}

StepOutcome StepPlanner::begin_choice(const core::Pose2& here,
                                      const mapping::StarPolygon& navigable, bool has_exploration,
                                      bool has_goal) {
  if (!params_.thesis_planner) {
    nav_choice_ = nav_.choose(has_goal_ ? &goal_ : nullptr, params_.rewards.goal_standoff_m);
    has_exploration = nav_choice_.kind == worldmap::NavGoalKind::kFrontier;
    has_goal = nav_choice_.kind == worldmap::NavGoalKind::kTarget;
  } else if (nav_needed_) {
    // The thesis's planner with a confirmed target: by path when the grid has one to a cell
    // at the stand-off, else by the value function's cones as before.
    nav_choice_ = nav_.choose_target(goal_, params_.rewards.goal_standoff_m);
    path_mode_ = nav_choice_.kind == worldmap::NavGoalKind::kTarget;
  }
  // A candidate with no way to its stand-off is no goal: explore as without one.
  if (params_.thesis_planner && provisional_ && !path_mode_) has_goal = false;
  if (!has_exploration && !has_goal) {
    // Turn round and look once more before giving up: the sector behind the robot is seen
    // only by the image's edges at the PTU's pan limits (or not at all, if the pans and the
    // field of view leave a gap), and a fresh look refits the model.
    const bool turned_here =
        turned_round_ && core::distance_m({here.x_m, here.y_m}, turned_round_at_) < 0.5F;
    return turned_here ? StepOutcome::kNothingLeft : StepOutcome::kTurnRound;
  }
  if (!path_mode_) chooser_.start(value_, navigable, here, params_.step);
  return StepOutcome::kChoosing;
}

planning::StepDecision StepPlanner::step_on_path(const core::Pose2& here,
                                                 const core::Pose2& look_pose,
                                                 const mapping::StarPolygon& navigable) {
  planning::StepDecision d;
  final_approach_ = false;
  const std::span<const core::Point2> path = nav_.path();
  const core::Point2 at{here.x_m, here.y_m};
  std::size_t nearest = 0;
  for (std::size_t i = 1; i < path.size(); ++i) {
    if (core::distance_m(at, path[i]) < core::distance_m(at, path[nearest])) nearest = i;
  }
  // The robot's own disc may overlap the clearance of an occupied cell: samples this near it
  // are the place it stands on, not the way ahead.
  const float own = params_.nav.robot_radius_m * 0.5F;
  for (std::size_t j = nearest + 1; j < path.size(); ++j) {
    const float dist = core::distance_m(at, path[j]);
    if (dist > params_.nav_step_m) break;
    if (dist < params_.step.min_step_m) continue;
    bool clear = true;
    for (int i = 1; i <= 20 && clear; ++i) {
      const float t = static_cast<float>(i) / 20.0F;
      const core::Point2 p{at.x_m + t * (path[j].x_m - at.x_m),
                           at.y_m + t * (path[j].y_m - at.y_m)};
      clear = navigable.contains(core::to_robot(look_pose, p)) &&
              (nav_.passable(p) || core::distance_m(p, at) < own);
    }
    if (!clear) continue;
    d.kind = planning::StepKind::kMove;
    d.target = path[j];
    d.distance_m = dist;
    d.heading_rad = std::atan2(path[j].y_m - at.y_m, path[j].x_m - at.x_m);
  }
  // The final approach: the stand-off goal (the path's end) near, the way there passable.
  const bool reaches_end = d.kind == planning::StepKind::kMove && !path.empty() &&
                           d.target.x_m == path.back().x_m && d.target.y_m == path.back().y_m;
  if (reaches_end || !has_goal_ || path.empty() ||
      nav_choice_.kind != worldmap::NavGoalKind::kTarget) {
    return d;
  }
  const core::Point2 end = path.back();
  const float dist = core::distance_m(at, end);
  if (dist > params_.final_approach_m || dist < params_.step.min_step_m) return d;
  for (int i = 1; i <= 20; ++i) {
    const float t = static_cast<float>(i) / 20.0F;
    const core::Point2 p{at.x_m + t * (end.x_m - at.x_m), at.y_m + t * (end.y_m - at.y_m)};
    if (!nav_.passable(p) && core::distance_m(p, at) >= own) return d;
  }
  d.kind = planning::StepKind::kMove;
  d.target = end;
  d.distance_m = dist;
  d.heading_rad = std::atan2(end.y_m - at.y_m, end.x_m - at.x_m);
  final_approach_ = true;
  return d;
}

StepOutcome StepPlanner::end_choice(const core::Pose2& here, const core::Pose2& look_pose,
                                    const mapping::StarPolygon& navigable,
                                    Breadcrumbs& breadcrumbs) {
  final_approach_ = false;
  if (!path_mode_) {
    decision_ = chooser_.decision();
  } else if (has_goal_ && core::distance_m({here.x_m, here.y_m}, goal_) <=
                              params_.rewards.goal_standoff_m + params_.step.arrival_tolerance_m) {
    decision_ = {};
    decision_.kind = planning::StepKind::kAtGoal;
  } else {
    decision_ = step_on_path(here, look_pose, navigable);
  }
  if (decision_.kind == planning::StepKind::kAtGoal) return StepOutcome::kAtGoal;
  if (decision_.kind == planning::StepKind::kMove) {
    // The thesis's consistency check: the whole step must lie in this look's polygon.
    bool inside = true;
    for (int i = 1; i <= 20 && inside; ++i) {
      const float t = static_cast<float>(i) / 20.0F;
      const core::Point2 p{here.x_m + t * (decision_.target.x_m - here.x_m),
                           here.y_m + t * (decision_.target.y_m - here.y_m)};
      inside = navigable.contains(core::to_robot(look_pose, p));
    }
    if (inside || final_approach_) {
      failed_cycles_ = 0;
      return StepOutcome::kMove;
    }
  }
  // No safe step (an obstacle close by, or a poor fit, can leave no room in this look's
  // polygon): the place counts as visited once more and the robot looks again; from the
  // second such cycle in a row it first backs off along the step that brought it here. It
  // gives up after a few such cycles in a row.
  ++failed_cycles_;
  trail_.add({here.x_m, here.y_m});
  if (failed_cycles_ >= params_.back_off_after_failed_cycles &&
      failed_cycles_ < params_.max_failed_cycles) {
    // The step back to the last breadcrumb: the robot's disc swept that segment on the way
    // here, so it is driven without this look's polygon (which may hold no room at all).
    core::Point2 back{};
    if (breadcrumbs.back_target({here.x_m, here.y_m}, params_.step.min_step_m, back)) {
      decision_ = {};
      decision_.kind = planning::StepKind::kMove;
      decision_.target = back;
      return StepOutcome::kBackOff;
    }
  }
  return StepOutcome::kNoSafeStep;
}

bool StepPlanner::begin_next_on_look(const core::Pose2& here, const core::Pose2& look_pose,
                                     const mapping::StarPolygon& navigable) {
  if (!navigable.contains(core::to_robot(look_pose, {here.x_m, here.y_m}))) return false;
  if (path_mode_) {
    decision_ = step_on_path(here, look_pose, navigable);
    return true;
  }
  from_here_.set_vertex_count(navigable.vertex_count());
  const float reach = params_.value.step_m;
  constexpr int kSamples = 20;
  for (std::size_t k = 0; k < from_here_.vertex_count(); ++k) {
    const float a = from_here_.angle_rad(k) + here.yaw_rad;
    float rho = 0.0F;
    for (int i = 1; i <= kSamples; ++i) {
      const float t = reach * static_cast<float>(i) / kSamples;
      const core::Point2 p{here.x_m + t * std::cos(a), here.y_m + t * std::sin(a)};
      if (!navigable.contains(core::to_robot(look_pose, p))) break;
      rho = t;
    }
    from_here_.set_rho_m(k, rho);
  }
  chooser_.start(value_, from_here_, here, params_.step);
  return true;
}

StepOutcome StepPlanner::end_next_on_look() {
  if (!path_mode_) decision_ = chooser_.decision();
  return decision_.kind == planning::StepKind::kMove ? StepOutcome::kMove
                                                     : StepOutcome::kNoSafeStep;
}

}  // namespace boticelli::firmware::mission
