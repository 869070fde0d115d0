// Reward cones (Eqs 5.9–5.11) summed at an arrival state.
#include "algo/planning/rewards.h"

#include <algorithm>
#include <cmath>

namespace boticelli::planning {
namespace {
float distance(core::Point2 a, core::Point2 b) {
  const float dx = a.x_m - b.x_m;
  const float dy = a.y_m - b.y_m;
  return std::sqrt(dx * dx + dy * dy);
}
}  // namespace

float reward_at(const RewardParams& params, const RewardSources& sources, core::Point2 arrival) {
  float reward = 0.0F;
  for (const core::Point2& p : sources.obstacles) {
    if (sources.has_goal && distance(p, sources.goal) < params.goal_clear_radius_m) {
      continue;  // §6.4 fix: the goal's own wall does not repel
    }
    // Eq 5.9: min{0, V_obs + S_obs ‖s' − p‖}
    reward +=
        std::min(0.0F, params.obstacle_apex + params.obstacle_slope_per_m * distance(arrival, p));
  }
  for (const core::Point2& q : sources.exploration) {
    // Eq 5.10: max{0, V_exp − S_exp ‖s' − q‖}
    reward += std::max(
        0.0F, params.exploration_apex - params.exploration_slope_per_m * distance(arrival, q));
  }
  for (const core::Point2& v : sources.visited) {
    reward +=
        std::min(0.0F, params.visited_apex + params.visited_slope_per_m * distance(arrival, v));
  }
  if (sources.has_goal) {
    // Eq 5.11: max{0, V_goal − S_goal ‖s' − g‖}
    reward += std::max(
        0.0F, params.goal_apex - params.goal_slope_per_m * distance(arrival, sources.goal));
  }
  return reward;
}

}  // namespace boticelli::planning
