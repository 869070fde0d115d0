// StepPlanner: where the robot moves next: by default a goal on the world memory's grid (the
// target's stand-off, else the frontier worth most for its path cost) and the step along the
// path to it; with MissionParams::thesis_planner value iteration over the global map's reward
// cones (thesis ch. 5.5) and the step on the value function. Either step is checked against
// the look's navigable polygon; each decision is an explicit StepOutcome.
#pragma once

#include <cstddef>
#include <cstdint>

#include "algo/core/geometry.h"
#include "algo/mapping/map_points.h"
#include "algo/mapping/star_polygon.h"
#include "algo/planning/planner.h"
#include "algo/planning/rewards.h"
#include "algo/planning/value_iteration.h"
#include "algo/worldmap/grid_map.h"
#include "algo/worldmap/nav_planner.h"
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

  // A run starts: no trail, no failed cycles, not turned round anywhere, no goal kept.
  void clear();
  // The plan's groundwork around `centre` (mission frame; where the robot looked from) with
  // the target's estimate as the goal (nullptr: none): the wavefront on `grid`, or
  // (thesis planner) value iteration on the global lists, the trail and the goal, its random
  // states drawn from `seed`. A `provisional` goal (a candidate not yet confirmed) is a goal
  // only by path: when the grid shows no way to its stand-off it draws no cone and counts as
  // no goal (the thesis planner explores; the frontier planner picks a frontier).
  void start_value(const mapping::GlobalMap& map, const worldmap::GridMap& grid,
                   const core::Point2* goal, core::Point2 centre, std::uint32_t seed,
                   bool provisional = false);
  [[nodiscard]] bool value_done() const {
    return (!params_.thesis_planner || value_.done()) && (!nav_needed_ || nav_.done());
  }
  void value_unit() {
    if (nav_needed_ && !nav_.done()) {
      (void)nav_.run_unit();
    } else if (params_.thesis_planner) {
      (void)value_.run_unit(params_.vi_work_per_unit);
    }
  }

  // After the groundwork: kChoosing, or kTurnRound / kNothingLeft when there is nothing to
  // explore and no goal (the thesis planner: no exploration points; else no reachable
  // frontier and no reachable stand-off).
  StepOutcome begin_choice(const core::Pose2& here, const mapping::StarPolygon& navigable,
                           bool has_exploration, bool has_goal);
  // One heading of the choice per call, until choice_done() (the thesis planner; the path's
  // step is found in end_choice()).
  void choose_heading() {
    if (!path_mode_) (void)chooser_.run_unit();
  }
  [[nodiscard]] bool choice_done() const { return path_mode_ || chooser_.done(); }
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
  [[nodiscard]] const worldmap::NavPlanner& nav() const { return nav_; }
  [[nodiscard]] const worldmap::NavChoice& nav_choice() const { return nav_choice_; }
  // Frontier goals blacklisted so far (they stopped getting nearer).
  [[nodiscard]] std::size_t blacklisted() const { return nav_.blacklist().size(); }

 private:
  // The step along the nav planner's path from `here`: the farthest path point within
  // nav_step_m whose straight segment stays in the look's navigable polygon and on passable
  // cells (kMove), else the final approach to a stand-off goal (final_approach_m), else
  // kNoSafeAction.
  [[nodiscard]] planning::StepDecision step_on_path(const core::Pose2& here,
                                                    const core::Pose2& look_pose,
                                                    const mapping::StarPolygon& navigable);

  const MissionParams& params_;
  planning::ValueIteration value_;
  worldmap::NavPlanner nav_;
  worldmap::NavChoice nav_choice_{};
  bool nav_needed_ = false;      // this plan runs the wavefront
  bool path_mode_ = false;       // this plan's step follows the wavefront's path
  bool final_approach_ = false;  // the step is the final approach (grid only) to the stand-off
  bool has_goal_ = false;        // the target's estimate, for the nav planner
  bool provisional_ = false;     // ... a candidate not yet confirmed: a goal only by path
  core::Point2 goal_{};
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
