// StepPlanner: where the robot moves next (thesis ch. 5.5): value iteration over the global
// map's reward cones, the step on the value function checked against the look's navigable
// polygon, and what to do when there is none; each decision an explicit StepOutcome.
#pragma once

#include <cstddef>
#include <cstdint>

#include "algo/core/geometry.h"
#include "algo/mapping/map_points.h"
#include "algo/mapping/star_polygon.h"
#include "algo/planning/planner.h"
#include "algo/planning/rewards.h"
#include "algo/planning/value_iteration.h"
#include "firmware/mission/drive/breadcrumbs.h"
#include "firmware/mission/params/mission_params.h"

namespace boticelli::firmware::mission {

enum class StepOutcome : std::uint8_t {
  kChoosing,     // the step is being chosen on the value function: choose() until done
  kMove,         // drive straight to target()
  kTurnRound,    // nothing left in front: turn in place by π and look again
  kBackOff,      // back off to target() along the way the robot came
  kAtGoal,       // within the stand-off of the target
  kNoSafeStep,   // no step lies in the look's polygon: look again (gave_up() after several)
  kNothingLeft,  // nothing left to explore, and the robot already turned round here
};

class StepPlanner {
 public:
  explicit StepPlanner(const MissionParams& params) : params_(params) {}
  StepPlanner(const StepPlanner&) = delete;
  StepPlanner& operator=(const StepPlanner&) = delete;

  // A run starts: no trail, no failed cycles, not turned round anywhere.
  void clear();
  // Value iteration on the global lists, the trail and the goal (nullptr: none yet) around
  // `centre` (mission frame), its random states drawn from `seed`.
  void start_value(const mapping::GlobalMap& map, const core::Point2* goal, core::Point2 centre,
                   std::uint32_t seed);
  [[nodiscard]] bool value_done() const { return value_.done(); }
  void value_unit() { (void)value_.run_unit(params_.vi_work_per_unit); }

  // After the value iteration: kChoosing, or kTurnRound / kNothingLeft when there is nothing
  // to explore and no goal.
  StepOutcome begin_choice(const core::Pose2& here, const mapping::StarPolygon& navigable,
                           bool has_exploration, bool has_goal);
  // One heading of the choice per call, until choice_done().
  void choose_heading() { (void)chooser_.run_unit(); }
  [[nodiscard]] bool choice_done() const { return chooser_.done(); }
  // The chosen step: kAtGoal, kMove when the whole step lies in the look's navigable polygon
  // (seen from `look_pose`), else the place counts as visited once more and the robot backs off
  // along its breadcrumbs (kBackOff) from the second such cycle in a row, or looks again
  // (kNoSafeStep).
  StepOutcome end_choice(const core::Pose2& here, const core::Pose2& look_pose,
                         const mapping::StarPolygon& navigable, Breadcrumbs& breadcrumbs);
  // Another step on the same look: its navigable polygon as seen from where the robot is now
  // (each ray as far as the straight move stays inside it), the same value function. False
  // when the robot stands outside the polygon (no step).
  bool begin_next_on_look(const core::Pose2& here, const core::Pose2& look_pose,
                          const mapping::StarPolygon& navigable);
  // kMove, or kNoSafeStep when no step was found.
  StepOutcome end_next_on_look();

  // The robot has stood here (the trail repels the value function).
  void visited(core::Point2 here) { trail_.add(here); }
  // A turn round finished here.
  void turned_round_at(core::Point2 here) {
    turned_round_ = true;
    turned_round_at_ = here;
  }
  // Too many cycles in a row without a safe step: the mission gives up.
  [[nodiscard]] bool gave_up() const { return failed_cycles_ >= params_.max_failed_cycles; }
  [[nodiscard]] const planning::StepDecision& decision() const { return decision_; }
  [[nodiscard]] const core::Point2& target() const { return decision_.target; }
  [[nodiscard]] const planning::ValueIteration& value() const { return value_; }

 private:
  const MissionParams& params_;
  planning::ValueIteration value_;
  planning::Trail trail_;
  planning::StepChooser chooser_;
  planning::StepDecision decision_{};
  mapping::StarPolygon from_here_{};  // the look's navigable polygon seen from the robot now
  std::size_t failed_cycles_ = 0;     // cycles in a row with no safe step
  // The PTU's pan range leaves a sector behind the robot unseen: before giving up at a place,
  // the robot turns round once and looks again (where it did).
  bool turned_round_ = false;
  core::Point2 turned_round_at_{};
};

}  // namespace boticelli::firmware::mission
