// Policy (Eq 5.12) and step selection: the best action whose step, cut to the navigation polygon,
// is safe.
#pragma once

#include <cstddef>

#include "algo/core/geometry.h"
#include "algo/mapping/star_polygon.h"
#include "algo/planning/rewards.h"
#include "algo/planning/value_iteration.h"

namespace boticelli::planning {

struct StepParams {
  float min_step_m = 0.05F;  // a step cut shorter than this is not worth taking: unsafe
  // The robot counts as arrived within the stand-off plus this [m] (a shorter step to the
  // stand-off would be below min_step_m anyway).
  float arrival_tolerance_m = 0.05F;
  // Bellman backups unrolled at the policy (≥ 1; 1 is Eq 5.12 as written): V(s') is
  // replaced by max_a' (r(s', a') + γ V(s'')) over clear moves, depth − 1 times. The ALN
  // smooths V across walls; a few exact backups at the robot see around a corner.
  std::size_t lookahead_depth = 4;
  // Headings the first step is chosen from, evenly spaced from 0 (world frame), clamped to
  // [kActionCount, kMaxStepHeadings]; the backups behind it keep the eight actions. With eight
  // a doorway whose axis lies between two of them is crossed askew, with up to 22.5° less of
  // its width to spare; sixteen halve that.
  std::size_t step_headings = kActionCount;
};

inline constexpr std::size_t kMaxStepHeadings = 32;

enum class StepKind { kMove, kAtGoal, kNoSafeAction };

struct StepDecision {
  StepKind kind = StepKind::kNoSafeAction;
  std::size_t action = 0;    // index of the chosen heading of step_headings (kMove)
  float heading_rad = 0.0F;  // world-frame direction of the step
  float distance_m = 0.0F;   // cut step length
  core::Point2 target{};     // world-frame end of the step
  float q_value = 0.0F;      // r(s, a) + γ V(s') at the cut end (Eq 5.12)
};

// Longest straight move [m] from the robot's centre along `heading_rad` (world) that stays in
// `navigable` (the shrunk polygon of the robot's current pose, robot frame), capped at
// `step_m`. The polygon is star-shaped about the centre, so the whole segment is inside.
float cut_step_m(const mapping::StarPolygon& navigable, const core::Pose2& pose, float heading_rad,
                 float step_m);

// Eq 5.12: π(s) = argmax_a (r(s, a) + γ V(s')) over the step headings (V(s') expanded by
// lookahead_depth − 1 exact Bellman backups, Eq 5.8), each step first cut
// to stay inside `navigable` and to stop at the goal's stand-off; actions whose cut step is
// below min_step_m are unsafe and skipped. If the robot is within the stand-off of the goal
// it has arrived; if no action is safe it says so instead of moving.
StepDecision choose_step(const ValueIteration& value, const mapping::StarPolygon& navigable,
                         const core::Pose2& pose, const StepParams& params);

// choose_step cut into units of one heading each (one costs 8^(lookahead − 1) backups,
// each over the obstacle points), so a background slice never has to hold all eight. The
// value function and the polygon must stay unchanged until done(); the decision is the one
// choose_step returns.
class StepChooser {
 public:
  void start(const ValueIteration& value, const mapping::StarPolygon& navigable,
             const core::Pose2& pose, const StepParams& params);
  // Evaluates the next heading; true once every one has been (decision() is then final).
  bool run_unit();
  [[nodiscard]] bool done() const { return next_action_ >= headings_; }
  [[nodiscard]] const StepDecision& decision() const { return best_; }

 private:
  const ValueIteration* value_ = nullptr;
  const mapping::StarPolygon* navigable_ = nullptr;
  core::Pose2 pose_{};
  StepParams params_{};
  std::size_t headings_ = kActionCount;
  std::size_t next_action_ = kActionCount;
  float best_q_ = 0.0F;
  StepDecision best_{};
};

}  // namespace boticelli::planning
