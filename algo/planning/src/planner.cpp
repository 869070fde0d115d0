// Policy (Eq 5.12) and step selection cut to the navigation polygon and the goal's stand-off.
#include "algo/planning/planner.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "algo/core/angles.h"

namespace boticelli::planning {
namespace {

// V(s) with `depth` Bellman backups (Eq 5.8) over the moves that keep clear of obstacle
// points; the ALN's V at the leaves. Recursion depth is lookahead_depth (small).
float backed_up_value(const ValueIteration& value, core::Point2 s, std::size_t depth) {
  if (depth == 0) {
    return value.value(s);
  }
  const float step = value.params().step_m;
  const float gamma = value.params().discount;
  float best = -std::numeric_limits<float>::infinity();
  for (std::size_t a = 0; a < kActionCount; ++a) {
    const float h = action_heading_rad(a);
    const core::Point2 next{s.x_m + step * std::cos(h), s.y_m + step * std::sin(h)};
    if (!value.move_clear(s, next)) {
      continue;
    }
    best = std::max(best, reward_at(value.rewards(), value.sources(), next) +
                              gamma * backed_up_value(value, next, depth - 1));
  }
  return best > -std::numeric_limits<float>::infinity() ? best : value.value(s);
}

}  // namespace

float cut_step_m(const mapping::StarPolygon& navigable, const core::Pose2& pose, float heading_rad,
                 float step_m) {
  // A hair inside the exact boundary so float rounding never puts the end outside it.
  const float room = navigable.radius_at_m(heading_rad - pose.yaw_rad) * (1.0F - 1e-5F);
  return std::clamp(std::min(step_m, room), 0.0F, step_m);
}

StepDecision choose_step(const ValueIteration& value, const mapping::StarPolygon& navigable,
                         const core::Pose2& pose, const StepParams& params) {
  StepChooser chooser;
  chooser.start(value, navigable, pose, params);
  while (!chooser.run_unit()) {
  }
  return chooser.decision();
}

void StepChooser::start(const ValueIteration& value, const mapping::StarPolygon& navigable,
                        const core::Pose2& pose, const StepParams& params) {
  value_ = &value;
  navigable_ = &navigable;
  pose_ = pose;
  params_ = params;
  best_ = StepDecision{};
  best_q_ = -std::numeric_limits<float>::infinity();
  headings_ = std::clamp(params.step_headings, kActionCount, kMaxStepHeadings);
  next_action_ = 0;
  const RewardSources& sources = value.sources();
  if (sources.has_goal && core::distance_m({pose.x_m, pose.y_m}, sources.goal) <=
                              value.rewards().goal_standoff_m + params.arrival_tolerance_m) {
    best_.kind = StepKind::kAtGoal;
    next_action_ = headings_;
  }
}

bool StepChooser::run_unit() {
  if (done()) return true;
  const std::size_t a = next_action_++;
  const ValueIteration& value = *value_;
  const RewardSources& sources = value.sources();
  const RewardParams& rewards = value.rewards();
  const core::Point2 here{pose_.x_m, pose_.y_m};
  const float standoff = rewards.goal_standoff_m;
  const float heading = static_cast<float>(a) * core::kTwoPi<float> / static_cast<float>(headings_);
  const float ux = std::cos(heading);
  const float uy = std::sin(heading);
  float step = cut_step_m(*navigable_, pose_, heading, value.params().step_m);
  if (sources.has_goal) {
    // Stop at the stand-off: the first t with ‖here + t·u − g‖ = stand-off.
    const float dx = sources.goal.x_m - here.x_m;
    const float dy = sources.goal.y_m - here.y_m;
    const float ud = ux * dx + uy * dy;
    const float disc = ud * ud - (dx * dx + dy * dy) + standoff * standoff;
    if (disc > 0.0F) {
      const float t = ud - std::sqrt(disc);
      if (t >= 0.0F) {
        step = std::min(step, t);
      }
    }
  }
  if (step < params_.min_step_m) {
    return done();  // unsafe: the polygon (or the stand-off) leaves no room this way
  }
  const core::Point2 next{here.x_m + step * ux, here.y_m + step * uy};
  const std::size_t depth = params_.lookahead_depth > 0 ? params_.lookahead_depth - 1 : 0;
  const float q = reward_at(rewards, sources, next) +
                  value.params().discount * backed_up_value(value, next, depth);
  if (q > best_q_) {
    best_q_ = q;
    best_.kind = StepKind::kMove;
    best_.action = a;
    best_.heading_rad = heading;
    best_.distance_m = step;
    best_.target = next;
    best_.q_value = q;
  }
  return done();
}

}  // namespace boticelli::planning
