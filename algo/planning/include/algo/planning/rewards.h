// Reward cones around obstacle points, exploration points and the goal (Eqs 5.9–5.11), parameters
// in one place.
#pragma once

#include <array>
#include <cstddef>
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
  // Not in the thesis: a small negative cone (Eq 5.9 form) at each place the robot has
  // been. Re-planned approximate value functions can make two neighbouring places point
  // at each other; each visit deepens the cone until the robot moves on.
  float visited_apex = -2.0F;
  float visited_slope_per_m = 10.0F;  // 0.2 m radius
};

// What the planner currently knows, in the world frame. The spans must stay valid while a
// value iteration that uses them runs (they are the global lists).
struct RewardSources {
  std::span<const core::Point2> obstacles;
  std::span<const core::Point2> exploration;
  std::span<const core::Point2> visited;  // the robot's recent positions (a Trail)
  bool has_goal = false;
  core::Point2 goal{};
};

// The robot's recent positions [world, m], oldest overwritten first.
class Trail {
 public:
  static constexpr std::size_t kCapacity = 64;
  void add(core::Point2 p) {
    points_[next_] = p;
    next_ = (next_ + 1) % kCapacity;
    if (count_ < kCapacity) {
      ++count_;
    }
  }
  void clear() { count_ = next_ = 0; }
  [[nodiscard]] std::span<const core::Point2> points() const { return {points_.data(), count_}; }

 private:
  std::array<core::Point2, kCapacity> points_{};
  std::size_t next_ = 0;
  std::size_t count_ = 0;
};

// r(s, a) of Eqs 5.8, 5.12: the sum of all cones at the arrival state s' [world, m].
float reward_at(const RewardParams& params, const RewardSources& sources, core::Point2 arrival);

}  // namespace boticelli::planning
