// Reward cones around obstacle points, exploration points and the goal (Eqs 5.9–5.11), parameters
// in one place.
#pragma once

#include <span>

#include "algo/core/geometry.h"

namespace boticelli::planning {

// Every planning constant the thesis left ad hoc (§6.4), in one place. A cone has its apex
// value V [reward] at the point and changes by S [reward/m] per metre from it.
struct RewardParams {
  float obstacle_apex = -1.0F;           // V_obs < 0 (Eq 5.9)
  float obstacle_slope_per_m = 2.5F;     // S_obs: the cone is 0 beyond 0.4 m
  float exploration_apex = 0.3F;         // V_exp (Eq 5.10)
  float exploration_slope_per_m = 0.3F;  // S_exp: felt within 1 m
  float goal_apex = 10.0F;               // V_goal (Eq 5.11)
  float goal_slope_per_m = 8.0F;         // S_goal: felt within 1.25 m
  // §6.4: the goal is seen on a wall, so its own obstacle points repelled the thesis's
  // robot at close range. Obstacle points this close to the goal give no negative reward
  // (they still block motion: the navigation polygon keeps the robot off them).
  float goal_clear_radius_m = 0.8F;
  float goal_standoff_m = 0.5F;  // the robot stops this far from the goal
};

// What the planner currently knows, in the world frame. The spans must stay valid while a
// value iteration that uses them runs (they are the global lists).
struct RewardSources {
  std::span<const core::Point2> obstacles;
  std::span<const core::Point2> exploration;
  bool has_goal = false;
  core::Point2 goal{};
};

// r(s, a) of Eqs 5.8, 5.12: the sum of all cones at the arrival state s' [world, m].
float reward_at(const RewardParams& params, const RewardSources& sources, core::Point2 arrival);

}  // namespace boticelli::planning
