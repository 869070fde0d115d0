// Mission: Look–Think–Drive (thesis ch. 6) — its phases, holds and end over the parts along the
// data path (look scan and processing, pose, map, step planner, drive), behind MissionView,
// BackgroundWork and FrameConsumer (docs/mission.md).
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>

#include "algo/core/fixed_vector.h"
#include "algo/core/geometry.h"
#include "algo/stereo/range_check.h"
#include "firmware/common/board_config.h"
#include "firmware/common/text_buffer.h"
#include "firmware/executive/executive.h"
#include "firmware/executive/frame_consumer.h"
#include "firmware/mission/drive/breadcrumbs.h"
#include "firmware/mission/drive/drive_controller.h"
#include "firmware/mission/localize/pose_keeper.h"
#include "firmware/mission/look/look_processor.h"
#include "firmware/mission/look/look_scan.h"
#include "firmware/mission/map/map_stage.h"
#include "firmware/mission/params/mission_params.h"
#include "firmware/mission/plan/step_planner.h"
#include "firmware/mission/target/target_tracker.h"
#include "firmware/safety/safety.h"
#include "firmware/state/mission_state.h"
#include "firmware/state/state_saver.h"
#include "firmware/telemetry/mission_view.h"
#include "firmware/telemetry/model_text.h"
#include "firmware/telemetry/truth_source.h"
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
  kRegister,   // one unit of a look's registration against the grid
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
  // The watchdog task: while the hardware watchdog refuses keep-alives the board may reset
  // any moment, so the mission holds the robot stopped (a reset mid-drive would let it coast).
  const Task* watchdog = nullptr;
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
  SliceResult run_slice(SliceBudget& budget) override;
  // Camera task: keeps a settled frame when the look wants one.
  void on_frame(const hal::Frame& frame) override { scan_.on_frame(frame); }
  bool wants_frames() const override { return scan_.wants_frames(); }

  // MissionView.
  const char* state_name() const override { return phase_name(phase_); }
  core::Pose2 pose() const override;
  float pan_rad() const override;
  std::uint32_t features() const override { return look_.last_features(); }
  std::uint32_t pieces() const override { return last_pieces_; }
  std::uint64_t cycles() const override { return state_.cycle; }
  std::string_view model_text() override { return model_text_.hold(); }
  void release_model_text() override { model_text_.release(); }
  std::uint64_t mission_log_begin() const override { return state_.log_dropped; }
  std::uint64_t mission_log_end() const override { return state_.log_dropped + state_.log.size(); }
  const MissionLogEntry* mission_log_line(std::uint64_t number) const override {
    if (number < mission_log_begin() || number >= mission_log_end()) return nullptr;
    return &state_.log[static_cast<std::size_t>(number - state_.log_dropped)];
  }
  MapCounts map_counts() const override;
  // The world memory (the grid of everything seen) and the planner that plans on it.
  [[nodiscard]] const worldmap::GridMap& grid() const { return map_.grid(); }
  [[nodiscard]] const char* planner_name() const {
    return params_.thesis_planner ? "thesis" : "frontier";
  }
  TargetEstimate target() const override;
  CameraCalibration camera_calibration() const override {
    CameraCalibration c;
    c.bases = calibration_bases_;
    c.stereo_to_floor = calibration_ratio_;
    c.self_calibrating = params_.stereo.self_calibration;
    c.inverse_range_bias_per_m = look_.stereo().inverse_range_bias();
    c.focal_scale = stereo::bias_as_focal_scale(c.inverse_range_bias_per_m, params_.rig);
    c.tilt_step_error_rad =
        stereo::bias_as_tilt_step_error_rad(c.inverse_range_bias_per_m, params_.rig);
    return c;
  }
  OdometryCalibration odometry_calibration() const override {
    const BaseCalibration e = pose_.calibrator().estimate();
    OdometryCalibration c;
    c.valid = e.valid;
    c.intervals = e.intervals;
    c.turned_rad = e.turned_rad;
    c.driven_m = e.driven_m;
    if (e.valid) {
      c.track_scale = e.track_m / config_.track_width_m;
      c.track_scale_sd = e.track_sd_m / config_.track_width_m;
      c.diameter_ratio = e.diameter_ratio;
      c.diameter_ratio_sd = e.diameter_ratio_sd;
    }
    return c;
  }

  [[nodiscard]] Result result() const { return result_; }
  [[nodiscard]] bool finished() const { return result_ != Result::kRunning; }
  [[nodiscard]] const char* end_reason() const { return end_reason_.c_str(); }
  [[nodiscard]] std::uint64_t cycles_this_run() const { return cycles_this_run_; }
  // Distance between the target estimate and the true target (NaN without either).
  [[nodiscard]] float target_error_m() const;
  // True when the resumed state's mission had already ended (found, nothing left, aborted
  // for good): start() keeps it ended, the robot stopped, and result() and end_reason() are
  // the saved ones.
  [[nodiscard]] bool ended_before_start() const { return ended_before_start_; }
  // The mission gave up on a device it held for (no frame grabbed for the device retry time
  // since the fault began): it ended aborted, and a restart may cure it (kExitFailure).
  [[nodiscard]] bool gave_up_on_device() const { return gave_up_on_device_; }
  // Ends the mission from outside: a signal or the console's shutdown (aborted) or
  // --max-cycles (not found). The state keeps the mission running: a later --resume
  // carries it on.
  void abort(const char* why) { finish(Result::kAborted, why, Ending::kResumable); }
  void finish_not_found(const char* why) { finish(Result::kNotFound, why, Ending::kResumable); }
  // Shutdown: saves the pose where the base came to rest and waits until the state is written.
  void finish_saving();
  // Per-stage host CPU time so far [s] (the benchmark's split).
  [[nodiscard]] double look_cpu_s() const { return cpu_s_[0]; }
  [[nodiscard]] double think_cpu_s() const { return cpu_s_[1]; }
  [[nodiscard]] double plan_cpu_s() const { return cpu_s_[2]; }
  // Looks registered against the grid (a correction applied) and their host CPU time [s].
  [[nodiscard]] std::uint32_t registered_looks() const { return registered_looks_; }
  [[nodiscard]] double register_cpu_s() const { return register_cpu_s_; }
  // Looks whose feature guard dropped readings because a fixed list was full (0 expected).
  [[nodiscard]] std::uint32_t guard_truncated_looks() const { return guard_truncated_looks_; }
  // The calibration self-check (stereo::RangeCheck): the median ratio of stereo to floor-cue
  // distances at obstacle bases over the looks that had enough of them, and how many ratios
  // that is of (0: none yet).
  [[nodiscard]] float calibration_ratio() const { return calibration_ratio_; }
  [[nodiscard]] std::uint32_t calibration_bases() const { return calibration_bases_; }
  // The stereo's self-calibration in use: the inverse-range bias removed [1/m].
  [[nodiscard]] float stereo_inverse_range_bias() const {
    return look_.stereo().inverse_range_bias();
  }
  // Set once a look's ratio lay beyond 1 ± kCalibrationTolerance: what the mission log says.
  [[nodiscard]] bool calibration_suspect() const { return calibration_warned_; }
  [[nodiscard]] const char* calibration_warning() const { return calibration_text_.c_str(); }
  // The longest single unit of each kind so far [s of host thread CPU].
  [[nodiscard]] double longest_unit_s(Unit unit) const {
    return longest_s_[static_cast<std::size_t>(unit)];
  }

 private:
  // The Think phase's background work: the local model's set-up, then its units.
  enum class ThinkStep : std::uint8_t { kBegin, kModel, kRegister, kGrid };
  // The Plan phase's background work.
  enum class PlanStep : std::uint8_t {
    kValueStart,        // the value iteration set up on the global lists
    kValue,             // its slices, then the choice of the step begins
    kChoose,            // the step chosen on the value function
    kNextOnLook,        // another step on the same look is due (after a step driven)
    kChooseNextOnLook,  // ... and being chosen
  };
  // A move of the Drive phase (the one pending, then the one under way).
  enum class Move : std::uint8_t { kNone, kStep, kTurnRound, kBackOff };
  // The cycle's picture (--snapshots): set up, then drawn and encoded a unit at a time.
  enum class SnapshotStep : std::uint8_t { kIdle, kPending, kWriting };

  // A look: every view and then the aimed pair; a glance (`glance`, when the target can be
  // aimed at): the aimed pair alone, to see the target afresh from its stand-off.
  void begin_look(std::uint64_t now_us, bool glance = false);
  void control_look(std::uint64_t now_us);
  // At the stand-off of the confirmed target (by the planner's judgement, or by distance):
  // found when this look saw the target afresh; else a miss (the target may be revoked) and
  // the mission goes on with a full look.
  void at_standoff(std::uint64_t now_us, bool planner_at_goal);
  void control_drive(std::uint64_t now_us);
  bool hold_needed();
  void control_hold(std::uint64_t now_us);
  // kFinal is saved in the state (a resumed run does not carry the mission on); kResumable
  // ends this run only.
  enum class Ending : std::uint8_t { kFinal, kResumable };
  void finish(Result result, const char* why, Ending ending);
  // A device fault (docs/reliability.md, "Fault policy"): the robot held stopped as for the
  // e-stop, the device tried again every retry interval (the look's move and frame, once the
  // PTU reports no fault and the base is ready), until a frame is grabbed again or, after
  // the device retry time, the mission gives up. `why` and the device's own words
  // ("WHY: DEVICE_ERROR") are the mission log's and the give-up's reason.
  void hold_for_device(const char* why, const char* device_error, std::uint64_t now_us);
  void end_cycle(const char* what);
  // The pose and its wall-clock time into the state (take_pose), and the state to the writer
  // (save_pose: a copy into its hand-over buffer, no I/O here with a writer thread).
  void take_pose();
  void save_pose(std::uint64_t now_us);
  // A resumed mission's pose carried on by the wheel counters the motor controllers kept
  // while no firmware ran (saved with the pose); false while it waits for them.
  bool resume_from_wheels(std::uint64_t now_us);
  // A part of the grabbed view's processing (a unit); true when the view is done.
  bool process_view(ViewPart part);
  // The pair aimed at the target's estimate (or its unconfirmed candidate) after the scan.
  [[nodiscard]] AimedPair aim_at_target() const;
  // Adds a fix to the tracker (none when !fix.found); true when it is the confirmed target.
  bool add_target_fix(const stereo::TargetFix& fix, std::uint32_t view);
  // Whether the map leaves the line of sight from the look's pose to the target clear.
  [[nodiscard]] bool target_in_clear_sight() const;
  SliceResult think_slice(SliceBudget& budget);
  SliceResult plan_slice(SliceBudget& budget);
  void begin_think();
  // The look's registration applied: the look's pose, and the mission's from now on.
  void localize();
  void after_think();
  // The target's place as the plan's goal: the confirmed estimate, else a provisional
  // candidate (MissionParams::candidate_as_goal). False when there is neither.
  [[nodiscard]] bool target_goal(core::Point2& goal) const;
  void begin_plan();
  // After the value iteration: gives up or turns round when nothing is left to explore, else
  // starts choosing the step (true).
  bool start_step_choice();
  void after_step_choice();
  void finish_next_step_on_look();
  // Starts a move in the Drive phase (the mission task begins it in its next frame).
  void drive(Move move);
  void write_trace(std::uint64_t now_us);
  void snapshot_unit();
  double& longest(Unit unit) { return longest_s_[static_cast<std::size_t>(unit)]; }

  hal::Hal& hal_;
  const BoardConfig& config_;
  Safety& safety_;
  const Executive& executive_;
  MissionState& state_;
  StateSaver* saver_;
  const TruthSource* truth_;
  const Task* watchdog_;
  TraceWriter* trace_;
  SnapshotWriter* snapshots_;
  MissionParams params_;

  core::Pose2 drive_from_{};  // where the move under way began (the swept disc)
  Phase phase_ = Phase::kStart;
  Phase held_phase_ = Phase::kStart;
  Result result_ = Result::kRunning;
  bool ended_before_start_ = false;
  bool device_hold_ = false;                   // held for a device, not (only) for the latch
  std::uint64_t device_trouble_since_us_ = 0;  // first device hold since the last frame; 0: none
  std::uint64_t device_retry_at_us_ = 0;
  std::uint64_t frames_at_trouble_ = 0;  // scan_.frames_grabbed() when the trouble began
  TextBuffer<160> device_reason_;
  bool gave_up_on_device_ = false;
  std::uint64_t next_pose_save_us_ = 0;  // while driving
  DriveStatus last_drive_status_ = DriveStatus::kIdle;
  std::uint64_t wheels_wait_since_us_ = 0;  // waiting for the wheel counters at the start
  TextBuffer<160> end_reason_;              // a copy: a device's reason may change after the end
  std::uint64_t now_us_ = 0;
  std::uint64_t cycles_this_run_ = 0;
  std::uint64_t next_trace_us_ = 0;
  bool submit_pending_ = false;

  // Pose.
  PoseKeeper pose_;

  // Look.
  LookScan scan_;
  LookProcessor look_;
  core::Pose2 look_pose_{};
  std::uint8_t view_part_ = 0;     // the next part of the grabbed view's processing
  bool look_lists_stale_ = false;  // the last look's readings wait for the picture
  TargetTracker tracker_;
  bool glance_ = false;              // this look is a glance at the target (begin_look)
  bool look_saw_target_ = false;     // a fix of this look was the confirmed target
  bool look_missed_target_ = false;  // the aimed pair should have seen it and did not
  std::uint32_t last_pieces_ = 0;
  std::uint32_t guard_truncated_looks_ = 0;
  // A look's range check counts from this many ratios; beyond 1 ± the tolerance the
  // calibration is reported once (a focal length 1 % off gives about 0.94 or 1.08).
  static constexpr std::size_t kCalibrationMinBases = 30;
  static constexpr float kCalibrationTolerance = 0.03F;
  void check_calibration();
  float calibration_ratio_ = 0.0F;
  std::uint32_t calibration_bases_ = 0;
  bool calibration_warned_ = false;
  TextBuffer<MissionLogEntry::kMaxTextBytes + 1> calibration_text_;

  // Think and plan.
  MapStage map_;
  ThinkStep think_step_ = ThinkStep::kBegin;
  StepPlanner planner_;
  PlanStep plan_step_ = PlanStep::kValueStart;
  ModelText model_text_;  // the last fitted model's text (console `model`)

  // Drive.
  DriveController driver_;
  Move pending_move_ = Move::kNone;  // chosen; the mission task starts it
  Move move_ = Move::kNone;          // under way
  std::uint32_t steps_this_look_ = 0;
  core::FixedVector<core::Point2, 1024> path_;  // where the robot has been (snapshots)
  // When a look finds no safe step the robot backs off along the way it came.
  Breadcrumbs breadcrumbs_;

  // The cycle's picture is drawn in background units of its own, before the next look's first
  // view is processed: what it shows is kept until then.
  SnapshotStep snapshot_step_ = SnapshotStep::kIdle;
  const char* snapshot_state_ = "";
  core::Pose2 snapshot_look_pose_{};

  double cpu_s_[3] = {0.0, 0.0, 0.0};
  double register_cpu_s_ = 0.0;
  std::uint32_t registered_looks_ = 0;
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
