// Mission: Look–Think–Drive (thesis ch. 6) — the PTU scan and frames, the local model and global
// map, value iteration and the driven step, behind MissionView and BackgroundWork.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>

#include "algo/core/fixed_vector.h"
#include "algo/evidence/reading.h"
#include "algo/image/low_res_frame.h"
#include "algo/mapping/local_model_builder.h"
#include "algo/mapping/map_points.h"
#include "algo/planning/planner.h"
#include "algo/planning/value_iteration.h"
#include "algo/stereo/floor_cue.h"
#include "algo/stereo/rig.h"
#include "algo/stereo/stereo_processor.h"
#include "firmware/board.h"
#include "firmware/device_tasks.h"
#include "firmware/executive.h"
#include "firmware/mission/breadcrumbs.h"
#include "firmware/mission/drive_controller.h"
#include "firmware/mission/mission_params.h"
#include "firmware/mission/target_tracker.h"
#include "firmware/mission_state.h"
#include "firmware/mission_view.h"
#include "firmware/safety.h"
#include "firmware/state_saver.h"
#include "hal/hal.h"

namespace boticelli::firmware {
class SnapshotWriter;
}

namespace boticelli::firmware::mission {

enum class Result : std::uint8_t { kRunning, kFound, kNotFound, kAborted };
const char* result_name(Result result);

// The mission's units of work, for the longest-unit measurement (host thread CPU): a
// background unit must fit one slice and the mission task its budget on the robot.
enum class Unit : std::uint8_t {
  kView,       // stereo, target and floor cue of one view
  kModel,      // one step of the local model (samples, training, guard, polygon)
  kMap,        // the map points of a look merged into the global lists
  kPlanStart,  // the value iteration set up on the global lists
  kValue,      // one slice of value iteration work
  kStep,       // the step chosen on the value function and checked against the polygon
  kSnapshot,   // one cycle's picture drawn and written
  kTask,       // the mission task's body in one frame (PTU, frames, driving)
  kCount,
};
const char* unit_name(Unit unit);

class TraceWriter;

// The stages' phases, as the console and the trace name them.
enum class Phase : std::uint8_t {
  kStart,  // waiting for the base and the PTU
  kLook,   // PTU scan: move, settle, grab; the background runs the stereo per view
  kThink,  // background: samples, fit, guard, polygon, map points
  kPlan,   // background: value iteration and the step
  kDrive,  // turn in place, then straight, on odometry
  kHold,   // e-stop / bumper / pause: base stopped, waiting
  kDone,   // found, not found or aborted
};
const char* phase_name(Phase phase);

// Readings of one look (robot frame): stereo features and the floor cue's output.
inline constexpr std::size_t kMaxLookFeatures = 16384;
inline constexpr std::size_t kMaxLookFloorObstacles = 12288;
inline constexpr std::size_t kMaxLookFloorFree = 8192;
// Walks blocked at their bottom row: at most one per column walked, 80 columns a frame.
inline constexpr std::size_t kMaxLookFloorBlocked = 4096;

// What the mission needs from around it (references valid for its lifetime).
struct MissionContext {
  hal::Hal& hal;
  const BoardConfig& config;
  Safety& safety;
  const Executive& executive;  // background pause flag
  MissionState& state;
  StateSaver* saver = nullptr;          // --state
  const TruthSource* truth = nullptr;   // sim ground truth (trace, target error)
  TraceWriter* trace = nullptr;         // --trace
  SnapshotWriter* snapshots = nullptr;  // --snapshots
};

class Mission final : public MissionView, public BackgroundWork, public FrameConsumer {
 public:
  explicit Mission(const MissionContext& context);
  Mission(const Mission&) = delete;
  Mission& operator=(const Mission&) = delete;

  // Anchors the mission at now (a resumed state keeps its cycle count, lists and goal).
  void start(std::uint64_t now_us);
  // The mission task's body, every minor frame: PTU scan, frames, driving, holds, trace.
  void control(std::uint64_t now_us);
  // Background slices: stereo per view, Think, Plan.
  StepResult step(SliceBudget& budget) override;
  // Camera task: keeps a settled frame when the look wants one.
  void on_frame(const hal::Frame& frame) override;
  bool wants_frames() const override { return want_frame_; }

  // MissionView.
  const char* state_name() const override { return phase_name(phase_); }
  core::Pose2 pose() const override;
  float pan_rad() const override;
  std::uint32_t features() const override { return last_features_; }
  std::uint32_t pieces() const override { return last_pieces_; }
  std::uint64_t cycles() const override { return state_.cycle; }
  std::string_view model_text() const override { return state_.model_text(); }
  std::uint64_t mission_log_begin() const override { return state_.log_dropped; }
  std::uint64_t mission_log_end() const override { return state_.log_dropped + state_.log.size(); }
  const MissionLogEntry* mission_log_line(std::uint64_t number) const override {
    if (number < mission_log_begin() || number >= mission_log_end()) return nullptr;
    return &state_.log[static_cast<std::size_t>(number - state_.log_dropped)];
  }
  MapCounts map_counts() const override;
  TargetEstimate target() const override;

  [[nodiscard]] Result result() const { return result_; }
  [[nodiscard]] bool finished() const { return result_ != Result::kRunning; }
  [[nodiscard]] const char* end_reason() const { return end_reason_.c_str(); }
  [[nodiscard]] std::uint64_t cycles_this_run() const { return cycles_this_run_; }
  // Distance between the target estimate and the true target (NaN without either).
  [[nodiscard]] float target_error_m() const;
  // Ends the mission from outside: shutdown (aborted) or --max-cycles (not found).
  void abort(const char* why);
  // abort() with the device's own words: "WHY: DEVICE_ERROR" (just WHY when it gave none).
  void abort_with(const char* why, const char* device_error);
  void finish_not_found(const char* why) { finish(Result::kNotFound, why); }
  // Shutdown: saves the pose where the base came to rest and waits until the state is written.
  void finish_saving();
  // Per-stage host CPU time so far [s] (the benchmark's split).
  [[nodiscard]] double look_cpu_s() const { return cpu_s_[0]; }
  [[nodiscard]] double think_cpu_s() const { return cpu_s_[1]; }
  [[nodiscard]] double plan_cpu_s() const { return cpu_s_[2]; }
  // Looks whose feature guard dropped readings because a fixed list was full (0 expected).
  [[nodiscard]] std::uint32_t guard_truncated_looks() const { return guard_truncated_looks_; }
  // The longest single unit of each kind so far [s of host thread CPU].
  [[nodiscard]] double longest_unit_s(Unit unit) const {
    return longest_s_[static_cast<std::size_t>(unit)];
  }

 private:
  enum class LookStep : std::uint8_t { kMove, kSettle, kGrab, kProcess };

  void begin_look(std::uint64_t now_us);
  void control_look(std::uint64_t now_us);
  void control_drive(std::uint64_t now_us);
  bool hold_needed();
  void control_hold(std::uint64_t now_us);
  void finish(Result result, const char* why);
  void end_cycle(const char* what);
  // One part of the grabbed view's processing: 0 stereo, 1 target, 2 and 3 the floor cue on
  // the first and second frame. True when the view is done.
  bool process_view(std::uint8_t part);
  // Where the floor cue reports walks blocked at their bottom row: nowhere unless the
  // Think stage closes their rays (LocalModelParams::close_blocked_rays).
  core::FixedVectorBase<evidence::Reading>* blocked_output() {
    return params_.model.close_blocked_rays ? &floor_blocked_ : nullptr;
  }
  // A fix (found or not) into the tracker, in the world frame of this look's pose.
  void add_target_fix(const stereo::TargetFix& fix, std::uint32_t view);
  void begin_think();
  void after_think();
  void begin_plan();
  // After the value iteration: gives up or turns round when nothing is left to explore, else
  // starts choosing the step (true).
  bool start_step_choice();
  void after_step_choice();
  // Another step on the same look's polygon, as seen from where the robot is now.
  bool start_next_step_on_look();
  void finish_next_step_on_look();
  bool back_off();
  void write_trace(std::uint64_t now_us);
  void begin_snapshot();
  void snapshot_step();
  // The robot's pose in the mission's frame: odometry carried on from a resumed state's pose.
  [[nodiscard]] core::Pose2 odometry_pose() const;
  // Fixes the mission frame against the odometry so that the robot stands at state_.pose.
  void anchor_frame();
  // The world pose of the mission frame's origin (sim ground truth only).
  [[nodiscard]] core::Pose2 frame_origin_in_world() const;
  // The scan's views (pans × rows), then the aimed pair when there is one.
  [[nodiscard]] std::size_t scan_views() const { return params_.pan_positions * params_.row_count; }
  [[nodiscard]] std::size_t view_count() const { return scan_views() + (aimed_ ? 1U : 0U); }
  void aim_at_target();
  double& longest(Unit unit) { return longest_s_[static_cast<std::size_t>(unit)]; }
  void view_angles(std::size_t view, float& pan_rad, float& tilt_rad, bool& pair) const;

  hal::Hal& hal_;
  const BoardConfig& config_;
  Safety& safety_;
  const Executive& executive_;
  MissionState& state_;
  StateSaver* saver_;
  const TruthSource* truth_;
  TraceWriter* trace_;
  SnapshotWriter* snapshots_;
  MissionParams params_;

  // Mission frame from odometry frame: identity for a new mission; a resumed one continues
  // in the frame its lists and goal were saved in, while the odometry restarts at zero.
  core::Pose2 frame_from_odometry_{};
  Phase phase_ = Phase::kStart;
  Phase held_phase_ = Phase::kStart;
  Result result_ = Result::kRunning;
  TextBuffer<160> end_reason_;  // a copy: a device's reason may change after the end
  std::uint64_t now_us_ = 0;
  std::uint64_t cycles_this_run_ = 0;
  std::uint64_t next_trace_us_ = 0;
  std::uint64_t released_since_us_ = 0;
  bool released_ = false;
  bool submit_pending_ = false;
  std::size_t failed_cycles_ = 0;
  // The PTU's pan range leaves a sector behind the robot unseen: before giving up at a place,
  // the robot turns round once and looks again (where it did, and whether the turn is due).
  bool turned_round_ = false;
  core::Point2 turned_round_at_{};
  bool turn_pending_ = false;   // the next drive is the turn round, not a step
  bool turning_round_ = false;  // the drive under way is the turn round

  // Look.
  stereo::RigModel rig_;
  stereo::StereoProcessor stereo_;
  stereo::FloorCue floor_cue_;
  std::size_t view_ = 0;
  LookStep look_step_ = LookStep::kMove;
  bool second_frame_ = false;  // grabbing the pair's second frame
  float view_pan_rad_ = 0.0F;
  float view_tilt_rad_ = 0.0F;
  bool view_pair_ = false;
  // After the scan, one stereo pair aimed at the target's estimate (or its unconfirmed
  // candidate), so each look nearer to it refines the estimate with a closer fix.
  bool aimed_ = false;
  float aimed_pan_rad_ = 0.0F;
  float aimed_tilt_rad_ = 0.0F;
  stereo::PairPose pair_pose_{};
  std::uint64_t step_deadline_us_ = 0;
  std::uint64_t settle_until_us_ = 0;
  bool want_frame_ = false;
  bool frame_ready_ = false;
  bool view_ready_ = false;     // both frames in; the background's turn
  std::uint8_t view_part_ = 0;  // the next part of its processing
  image::LowResFrame first_{};
  image::LowResFrame second_{};
  core::Pose2 look_pose_{};
  core::FixedVector<evidence::Reading, kMaxLookFeatures> features_;
  core::FixedVector<evidence::Reading, kMaxLookFloorObstacles> floor_obstacles_;
  core::FixedVector<evidence::Reading, kMaxLookFloorFree> floor_free_;
  core::FixedVector<float, kMaxLookFloorFree> floor_free_near_;  // each walk's near end [m]
  core::FixedVector<evidence::Reading, kMaxLookFloorBlocked> floor_blocked_;
  TargetTracker tracker_;
  stereo::TargetSighting last_sighting_{};  // this look's latest first frame with the target
  std::uint32_t last_features_ = 0;
  std::uint32_t last_pieces_ = 0;
  std::uint32_t guard_truncated_looks_ = 0;

  // Think and plan.
  mapping::LocalModelBuilder builder_;
  // The last look's free polygon and pose (mission frame), the next look's prior.
  mapping::StarPolygon prior_look_free_{};
  core::Pose2 prior_look_pose_{};
  bool has_prior_look_ = false;
  mapping::GlobalMap map_;
  core::FixedVector<core::Point2, mapping::kMaxObstaclePoints> cycle_obstacles_;
  core::FixedVector<core::Point2, mapping::kMaxExplorationPoints> cycle_exploration_;
  planning::ValueIteration value_;
  planning::Trail trail_;
  planning::StepDecision decision_{};
  bool think_started_ = false;
  bool plan_started_ = false;

  // Drive.
  DriveController driver_;
  bool drive_pending_ = false;      // a step was chosen; control starts it
  bool next_step_pending_ = false;  // the background chooses another step on this look
  planning::StepChooser chooser_;
  bool choosing_ = false;          // the chooser is under way ...
  bool choosing_on_look_ = false;  // ... for another step on this look (not after a plan)
  std::uint32_t steps_this_look_ = 0;
  mapping::StarPolygon from_here_{};  // the look's navigable polygon seen from the robot now
  core::FixedVector<core::Point2, 1024> path_;  // where the robot has been (snapshots)
  // When a look finds no safe step the robot backs off along the way it came.
  Breadcrumbs breadcrumbs_;
  bool retreating_ = false;  // the drive under way backs off to the last breadcrumb

  // The cycle's picture (--snapshots) is drawn in a background unit of its own, before the
  // next look's first view is processed: what it shows is kept until then.
  bool snapshot_pending_ = false;
  bool snapshot_writing_ = false;  // the writer is drawing or encoding it, a unit at a time
  bool look_lists_stale_ = false;  // the last look's readings wait for the picture
  const char* snapshot_state_ = "";
  core::Pose2 snapshot_look_pose_{};

  double cpu_s_[3] = {0.0, 0.0, 0.0};
  double longest_s_[static_cast<std::size_t>(Unit::kCount)] = {};
};

// The executive's mission task: calls Mission::control every frame; unhealthy when the
// mission ended aborted by a device fault.
class MissionTask final : public Task {
 public:
  explicit MissionTask(Mission& mission) : mission_(mission) {}
  void run(std::uint64_t now_us) override { mission_.control(now_us); }

 private:
  Mission& mission_;
};

}  // namespace boticelli::firmware::mission
