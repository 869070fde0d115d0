// Mission: the Look–Think–Drive phases and their dispatch over the mission's parts (mission.h).
#include "firmware/mission/mission.h"

#include <algorithm>
#include <cmath>
#include <ctime>
#include <limits>

#include "algo/aln/text_format.h"
#include "algo/core/angles.h"
#include "firmware/common/text_buffer.h"
#include "firmware/mission/snapshot_builder.h"
#include "firmware/telemetry/snapshot.h"
#include "firmware/telemetry/trace_writer.h"

namespace boticelli::firmware::mission {
namespace {

double thread_cpu_s() {
  timespec ts{};
  ::clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
  return static_cast<double>(ts.tv_sec) + static_cast<double>(ts.tv_nsec) * 1e-9;
}

// Adds the CPU time of one unit of work to a stage counter (if any) and keeps the longest.
class CpuScope {
 public:
  CpuScope(double* total, double& longest)
      : total_(total), longest_(longest), start_(thread_cpu_s()) {}
  ~CpuScope() {
    const double d = thread_cpu_s() - start_;
    if (total_ != nullptr) *total_ += d;
    longest_ = std::max(longest_, d);
  }
  CpuScope(const CpuScope&) = delete;
  CpuScope& operator=(const CpuScope&) = delete;

 private:
  double* total_;
  double& longest_;
  double start_;
};

}  // namespace

const char* result_name(Result result) {
  switch (result) {
    case Result::kRunning:
      return "running";
    case Result::kFound:
      return "found";
    case Result::kNotFound:
      return "not_found";
    case Result::kAborted:
      return "aborted";
  }
  return "unknown";
}

const char* unit_name(Unit unit) {
  switch (unit) {
    case Unit::kView:
      return "view";
    case Unit::kModel:
      return "model";
    case Unit::kMap:
      return "map";
    case Unit::kRegister:
      return "register";
    case Unit::kPlanStart:
      return "plan_start";
    case Unit::kValue:
      return "value";
    case Unit::kStep:
      return "step";
    case Unit::kSnapshot:
      return "snapshot";
    case Unit::kTask:
      return "task";
    case Unit::kCount:
      break;
  }
  return "unknown";
}

const char* phase_name(Phase phase) {
  switch (phase) {
    case Phase::kStart:
      return "start";
    case Phase::kLook:
      return "look";
    case Phase::kThink:
      return "think";
    case Phase::kPlan:
      return "plan";
    case Phase::kDrive:
      return "drive";
    case Phase::kHold:
      return "hold";
    case Phase::kDone:
      return "done";
  }
  return "unknown";
}

Mission::Mission(const MissionContext& c)
    : hal_(c.hal),
      config_(c.config),
      safety_(c.safety),
      executive_(c.executive),
      state_(c.state),
      saver_(c.saver),
      truth_(c.truth),
      watchdog_(c.watchdog),
      trace_(c.trace),
      snapshots_(c.snapshots),
      params_(make_mission_params(c.config)),
      pose_(c.hal.base),
      scan_(params_),
      look_(params_.rig, params_.stereo, params_.model.close_blocked_rays),
      planner_(params_) {
  tracker_.configure(params_.target);
  driver_.configure(params_.drive);
}

void Mission::start(std::uint64_t now_us) {
  now_us_ = now_us;
  next_trace_us_ = now_us;
  wheels_wait_since_us_ = 0;
  last_drive_status_ = DriveStatus::kIdle;
  phase_ = Phase::kStart;
  result_ = Result::kRunning;
  end_reason_.clear();
  device_hold_ = false;
  device_trouble_since_us_ = 0;
  gave_up_on_device_ = false;
  ended_before_start_ = state_.finished();
  if (ended_before_start_) {
    // A mission that ended for good is not carried on: it stays ended, the base stopped.
    phase_ = Phase::kDone;
    result_ = state_.end == MissionEnd::kFound      ? Result::kFound
              : state_.end == MissionEnd::kNotFound ? Result::kNotFound
                                                    : Result::kAborted;
    end_reason_.append(state_.end_reason.data());
  }
  cycles_this_run_ = 0;
  planner_.clear();
  map_.start(state_, params_.grid);
  look_.restore_inverse_range_bias(state_.stereo_bias_per_m);
  pose_.anchor(state_.pose);
  tracker_.clear();
  if (state_.has_goal) {
    // A resumed goal was confirmed before the restart: it stands as confirmed.
    tracker_.restore(Eigen::Vector3f(state_.goal.x_m, state_.goal.y_m, state_.goal_height_m));
  }
  // A resumed mission shows its saved model until the first look is fitted.
  model_text_.clear();
  const std::string_view saved = state_.model_text();
  std::copy(saved.begin(), saved.end(), model_text_.back().begin());
  model_text_.publish(saved.size());
  path_.clear();
  breadcrumbs_.clear();
  pending_move_ = move_ = Move::kNone;
  snapshot_step_ = SnapshotStep::kIdle;
  look_lists_stale_ = false;
}

core::Pose2 Mission::pose() const {
  return pose_.pose();
}

float Mission::pan_rad() const {
  return hal_.pan_tilt.state().pan_rad;
}

MapCounts Mission::map_counts() const {
  MapCounts m;
  m.polygon_vertices = static_cast<std::uint32_t>(map_.local().free.vertex_count());
  m.obstacle_points = static_cast<std::uint32_t>(map_.global().obstacles().size());
  m.exploration_points = static_cast<std::uint32_t>(map_.global().exploration().size());
  const worldmap::GridMap& grid = map_.grid();
  const float cell_m2 = grid.cell_m() * grid.cell_m();
  m.grid_tiles = static_cast<std::uint32_t>(grid.tiles_used());
  m.grid_bytes = static_cast<std::uint32_t>(grid.bytes());
  m.free_m2 = static_cast<float>(grid.free_cells()) * cell_m2;
  m.occupied_m2 = static_cast<float>(grid.occupied_cells()) * cell_m2;
  m.grid_dropped = static_cast<std::uint32_t>(grid.dropped());
  m.frontiers = static_cast<std::uint32_t>(planner_.nav().frontiers().size());
  m.blacklisted = static_cast<std::uint32_t>(planner_.blacklisted());
  const worldmap::NavChoice& choice = planner_.nav_choice();
  m.goal = choice.kind == worldmap::NavGoalKind::kFrontier ? GoalKind::kFrontier
           : choice.kind == worldmap::NavGoalKind::kTarget ? GoalKind::kTarget
                                                           : GoalKind::kNone;
  m.goal_x_m = choice.goal.x_m;
  m.goal_y_m = choice.goal.y_m;
  m.goal_path_m = choice.path_m;
  return m;
}

TargetEstimate Mission::target() const {
  TargetEstimate t;
  t.sightings = static_cast<std::uint32_t>(tracker_.sightings());
  if (t.sightings == 0) return t;
  t.status = tracker_.confirmed() ? TargetStatus::kConfirmed : TargetStatus::kSeen;
  const Eigen::Vector3f& p = tracker_.confirmed() ? tracker_.estimate_m() : tracker_.candidate_m();
  t.x_m = p.x();
  t.y_m = p.y();
  t.z_m = p.z();
  return t;
}

float Mission::target_error_m() const {
  if (truth_ == nullptr || !tracker_.confirmed()) return std::numeric_limits<float>::quiet_NaN();
  // The estimate is in the mission frame; the truth knows where the odometry frame lies.
  const core::Pose2 o = pose_.frame_origin_in_world(truth_->odometry_origin());
  const Eigen::Vector3f& e = tracker_.estimate_m();
  const core::Point2 w = core::to_world(o, {e.x(), e.y()});
  const Eigen::Vector3f world(w.x_m, w.y_m, e.z());
  return (world - truth_->target_m()).norm();
}

void Mission::finish(Result result, const char* why, Ending ending) {
  if (result_ != Result::kRunning) return;
  if (ending == Ending::kFinal) {
    state_.set_end(result == Result::kFound      ? MissionEnd::kFound
                   : result == Result::kNotFound ? MissionEnd::kNotFound
                                                 : MissionEnd::kAborted,
                   why);
  }
  result_ = result;
  end_reason_.clear();
  end_reason_.append(why);
  phase_ = Phase::kDone;
  scan_.stop_frames();
  driver_.reset();
  hal_.base.set_velocity(0.0F, 0.0F);
  TextBuffer<MissionLogEntry::kMaxTextBytes + 1> line;
  line.appendf("mission %s: %s", result_name(result), why);
  state_.add_log(state_.cycle, line.view());
  if (saver_ != nullptr) submit_pending_ = !saver_->submit(state_);
}

void Mission::hold_for_device(const char* why, const char* device_error, std::uint64_t now_us) {
  device_reason_.clear();
  device_reason_.append(why);
  if (device_error != nullptr && device_error[0] != '\0')
    device_reason_.appendf(": %s", device_error);
  if (device_trouble_since_us_ == 0) {
    device_trouble_since_us_ = now_us != 0 ? now_us : 1;
    frames_at_trouble_ = scan_.frames_grabbed();
    TextBuffer<MissionLogEntry::kMaxTextBytes + 1> line;
    line.appendf("held: %s", device_reason_.c_str());
    state_.add_log(state_.cycle, line.view());
  }
  device_hold_ = true;
  device_retry_at_us_ = now_us + params_.device_retry_interval_us;
  if (phase_ != Phase::kHold) {
    held_phase_ = phase_;
    phase_ = Phase::kHold;
  }
  scan_.stop_frames();
  if (driver_.busy()) driver_.abort("held");
  hal_.base.set_velocity(0.0F, 0.0F);
}

// ---------------------------------------------------------------- control (mission task)

bool Mission::hold_needed() {
  return safety_.holds() || executive_.background_paused();
}

void Mission::control(std::uint64_t now_us) {
  CpuScope cpu(nullptr, longest_s_[static_cast<std::size_t>(Unit::kTask)]);
  now_us_ = now_us;
  write_trace(now_us);
  if (submit_pending_ && saver_ != nullptr && saver_->submit(state_)) submit_pending_ = false;
  if (phase_ == Phase::kDone) {
    hal_.base.set_velocity(0.0F, 0.0F);
    return;
  }
  if (device_trouble_since_us_ != 0 && scan_.frames_grabbed() != frames_at_trouble_) {
    // A frame again: the PTU reached its view and the camera delivered; the base was ready.
    TextBuffer<MissionLogEntry::kMaxTextBytes + 1> line;
    line.appendf("devices back after %.1f s",
                 static_cast<double>(now_us - device_trouble_since_us_) * 1e-6);
    state_.add_log(state_.cycle, line.view());
    device_trouble_since_us_ = 0;
  }
  if (safety_.engaged() && safety_.cause() == StopCause::kBumper) {
    // The robot touched something its map did not hold: the operator looks before another
    // mission; a restart does not carry this one on.
    finish(Result::kAborted, "bumper contact", Ending::kFinal);
    return;
  }
  if (watchdog_ != nullptr && !watchdog_->healthy() && phase_ != Phase::kHold) {
    return hold_for_device("watchdog refusing keep-alives (a reset may come)",
                           watchdog_->health_reason(), now_us);
  }
  if (hold_needed() && phase_ != Phase::kHold) {
    held_phase_ = phase_;
    phase_ = Phase::kHold;
    scan_.stop_frames();
    if (driver_.busy()) driver_.abort("held");
  }
  switch (phase_) {
    case Phase::kStart: {
      const hal::PanTiltState ptu = hal_.pan_tilt.state();
      if (ptu.fault) return hold_for_device("pan-tilt unit fault", hal_.pan_tilt.error(), now_us);
      if (hal_.base.health() == hal::BaseHealth::kReady && !ptu.moving) {
        if (!resume_from_wheels(now_us)) return;  // the wheel counters are not in yet
        pose_.anchor(state_.pose);                // the odometry as the base reports it once ready
        begin_look(now_us);
      }
      return;
    }
    case Phase::kLook:
      control_look(now_us);
      return;
    case Phase::kThink:
    case Phase::kPlan:
      hal_.base.set_velocity(0.0F, 0.0F);
      return;
    case Phase::kDrive:
      control_drive(now_us);
      return;
    case Phase::kHold:
      control_hold(now_us);
      return;
    case Phase::kDone:
      return;
  }
}

void Mission::control_hold(std::uint64_t now_us) {
  hal_.base.set_velocity(0.0F, 0.0F);
  if (driver_.busy()) {
    const hal::Odometry o = hal_.base.odometry();
    (void)driver_.update(pose_.pose(), o.v_m_s, o.omega_rad_s, now_us);
  }
  if (device_hold_) {
    // The device retry time without a frame since the fault began: give up (the firmware
    // exits for a restart, which re-opens every device; the state keeps the mission running).
    if (now_us - device_trouble_since_us_ >= params_.device_retry_us) {
      TextBuffer<MissionLogEntry::kMaxTextBytes + 1> why;
      why.appendf("gave up after %.0f s: %s",
                  static_cast<double>(now_us - device_trouble_since_us_) * 1e-6,
                  device_reason_.c_str());
      gave_up_on_device_ = true;
      return finish(Result::kAborted, why.c_str(), Ending::kResumable);
    }
    // Try again once a retry interval has passed and the devices report no fault (the PTU's
    // and the camera's drivers re-open by themselves; the base task restarts the base).
    if (now_us < device_retry_at_us_ || hal_.pan_tilt.state().fault) return;
    if (hal_.base.health() != hal::BaseHealth::kReady) return;
    if (watchdog_ != nullptr && !watchdog_->healthy()) return;
    device_hold_ = false;
  }
  // Latched, or reset and waiting for the console's `resume`: only the operator ends it (a
  // released button or a line that comes back does not).
  if (safety_.holds()) return;
  if (executive_.background_paused()) return;
  if (hal_.base.health() != hal::BaseHealth::kReady) return;
  // Carry on. An interrupted step is not resumed blind: the robot looks again first.
  if (held_phase_ == Phase::kDrive) {
    end_cycle("step interrupted");
    if (phase_ != Phase::kDone) begin_look(now_us);
    return;
  }
  phase_ = held_phase_;
  if (phase_ == Phase::kLook) scan_.resume();  // re-issue the interrupted move and wait again
}

void Mission::begin_look(std::uint64_t now_us, bool glance) {
  phase_ = Phase::kLook;
  // A planned move not begun is void.
  pending_move_ = move_ = Move::kNone;
  look_lists_stale_ = true;  // cleared by the background before the first view
  view_part_ = 0;
  look_pose_ = pose_.pose();
  const AimedPair aimed = aim_at_target();
  glance_ = glance && aimed.aimed;
  look_saw_target_ = false;
  look_missed_target_ = false;
  scan_.begin(now_us, aimed, glance_);
  think_step_ = ThinkStep::kBegin;
  plan_step_ = PlanStep::kValueStart;
}

AimedPair Mission::aim_at_target() const {
  if (tracker_.sightings() == 0) return {};
  const Eigen::Vector3f& c = tracker_.confirmed() ? tracker_.estimate_m() : tracker_.candidate_m();
  const core::Point2 q = core::to_robot(look_pose_, {c.x(), c.y()});
  return aim_pair_at({q.x_m, q.y_m, c.z()}, params_.rig.ptu_height_m, params_.rig.tilt_step_rad,
                     params_.limits.max_range_m, hal_.pan_tilt.limits());
}

void Mission::control_look(std::uint64_t now_us) {
  hal_.base.set_velocity(0.0F, 0.0F);
  switch (scan_.control(now_us, hal_.pan_tilt)) {
    case ScanEvent::kBusy:
      return;
    case ScanEvent::kDone:
      if (glance_) return at_standoff(now_us, false);
      phase_ = Phase::kThink;
      return;
    case ScanEvent::kPtuFault:
      return hold_for_device("pan-tilt unit fault", hal_.pan_tilt.error(), now_us);
    case ScanEvent::kPtuRefused:
      return hold_for_device("pan-tilt unit refused a move", hal_.pan_tilt.error(), now_us);
    case ScanEvent::kPtuTimeout:
      return hold_for_device("pan-tilt move did not complete", nullptr, now_us);
    case ScanEvent::kNoFrame:
      return hold_for_device("no camera frame", hal_.camera.error(), now_us);
  }
}

void Mission::at_standoff(std::uint64_t now_us, bool planner_at_goal) {
  const core::Pose2 here = pose_.pose();
  const Eigen::Vector3f& g = tracker_.estimate_m();
  const bool near =
      planner_at_goal || core::distance_m({here.x_m, here.y_m}, {g.x(), g.y()}) <=
                             params_.rewards.goal_standoff_m + params_.step.arrival_tolerance_m;
  if (tracker_.confirmed() && near && look_saw_target_) {
    return finish(Result::kFound, "within the stand-off of the target, seen from there",
                  Ending::kFinal);
  }
  // A candidate gone to before it was confirmed, not seen from its stand-off: a false
  // detection seen twice from one place; it is never a goal again unless two places agree.
  if (!tracker_.confirmed() && tracker_.dismiss_candidate()) {
    end_cycle("target candidate not seen from its stand-off: dismissed");
    if (phase_ != Phase::kDone) begin_look(now_us);
    return;
  }
  // Not seen from its stand-off: a miss (unless the aimed pair counted it already).
  const bool revoked = !look_missed_target_ && tracker_.missed();
  end_cycle(revoked ? "target revoked: not seen from its stand-off"
                    : "target not seen from its stand-off");
  if (phase_ != Phase::kDone) begin_look(now_us);
}

void Mission::drive(Move move) {
  pending_move_ = move;
  phase_ = Phase::kDrive;
}

void Mission::control_drive(std::uint64_t now_us) {
  if (pending_move_ != Move::kNone) {
    move_ = pending_move_;
    pending_move_ = Move::kNone;
    const core::Pose2 from = pose_.pose();
    drive_from_ = from;
    if (move_ == Move::kTurnRound) {
      driver_.start_turn(from, core::wrap_pi(from.yaw_rad + core::kPi<float>), now_us);
    } else {
      if (move_ != Move::kBackOff) breadcrumbs_.step_started({from.x_m, from.y_m});
      driver_.start(from, planner_.target(), now_us);
    }
    next_pose_save_us_ = now_us + params_.pose_save_period_us;
  }
  const hal::Odometry o = hal_.base.odometry();
  const DriveCommand cmd = driver_.update(pose_.pose(), o.v_m_s, o.omega_rad_s, now_us);
  hal_.base.set_velocity(cmd.v_m_s, cmd.omega_rad_s);
  if (hal_.base.health() == hal::BaseHealth::kStopped && !safety_.engaged()) {
    return hold_for_device("base stopped by itself", hal_.base.error(), now_us);
  }
  if (driver_.busy()) {
    // At least every second while driving, and where the turn ends and the straight begins:
    // a firmware killed mid-step resumes near here, and from here the wheel counters'
    // single arc describes what the robot does until it stops.
    const DriveStatus status = driver_.status();
    if (now_us >= next_pose_save_us_ ||
        (status != last_drive_status_ && last_drive_status_ == DriveStatus::kTurning)) {
      save_pose(now_us);
    }
    last_drive_status_ = status;
    return;
  }
  last_drive_status_ = DriveStatus::kIdle;
  const bool ok = driver_.status() == DriveStatus::kDone;
  const core::Pose2 here = pose_.pose();
  planner_.visited({here.x_m, here.y_m});
  pose_.moved(drive_from_, here);  // the odometry's uncertainty grows
  // The robot's disc stood everywhere along the move: nothing stands there.
  (void)map_.swept({drive_from_.x_m, drive_from_.y_m}, {here.x_m, here.y_m},
                   config_.robot_radius_m);
  core::Point2 g{};
  if (target_goal(g)) {
    if (core::distance_m({here.x_m, here.y_m}, g) <=
        params_.rewards.goal_standoff_m + params_.step.arrival_tolerance_m) {
      // Found only once it is seen again from here: a glance at it first.
      end_cycle("at the target's stand-off");
      move_ = Move::kNone;
      return begin_look(now_us, true);
    }
  }
  const Move done = move_;
  move_ = Move::kNone;
  switch (done) {
    case Move::kBackOff:
      if (ok) breadcrumbs_.reached();
      end_cycle(ok ? "no safe step, backed off" : driver_.failure());
      if (phase_ != Phase::kDone) begin_look(now_us);
      return;
    case Move::kTurnRound:
      // Only a finished turn counts: an interrupted one is tried again at the next dead end.
      if (ok) planner_.turned_round_at({here.x_m, here.y_m});
      end_cycle(ok ? "turned round" : driver_.failure());
      if (phase_ != Phase::kDone) begin_look(now_us);
      return;
    case Move::kStep:
    case Move::kNone:
      break;
  }
  if (ok && ++steps_this_look_ < params_.steps_per_look) {
    save_pose(now_us);  // the step's end (the other ends end the cycle, which saves)
    // Another step on the same look is worked out by the background (a unit of its own).
    plan_step_ = PlanStep::kNextOnLook;
    phase_ = Phase::kPlan;
    return;
  }
  end_cycle(ok ? "step done" : driver_.failure());
  if (phase_ != Phase::kDone) begin_look(now_us);
}

void Mission::take_pose() {
  state_.pose = pose_.pose();
  state_.pose_time_ms = hal_.clock.wall_time_ms();
  // The wheel counters of the same moment (PoseKeeper reads the same odometry).
  const hal::Odometry o = hal_.base.odometry();
  state_.wheels_known = o.wheels_known;
  state_.wheel_left_m = o.wheel_left_m;
  state_.wheel_right_m = o.wheel_right_m;
}

bool Mission::resume_from_wheels(std::uint64_t now_us) {
  if (!state_.wheels_known) return true;  // a new mission, or a state without the counters
  const hal::Odometry o = hal_.base.odometry();
  if (!o.wheels_known) {
    // The motor controllers report their counters within a few frames of being ready.
    if (wheels_wait_since_us_ == 0) wheels_wait_since_us_ = now_us != 0 ? now_us : 1;
    if (now_us - wheels_wait_since_us_ < params_.resume_wheels_wait_us) return false;
    state_.add_log(state_.cycle, "resumed at the saved pose: the base reports no wheel counters");
    state_.wheels_known = false;
    return true;
  }
  const double left_m = o.wheel_left_m - state_.wheel_left_m;
  const double right_m = o.wheel_right_m - state_.wheel_right_m;
  TextBuffer<MissionLogEntry::kMaxTextBytes + 1> line;
  if (std::fabs(left_m) > static_cast<double>(params_.resume_max_roll_m) ||
      std::fabs(right_m) > static_cast<double>(params_.resume_max_roll_m)) {
    // More than a robot rolls by itself: the controllers restarted (their counters begin
    // again) or someone pushed it far. The saved pose is all there is.
    line.appendf("resumed at the saved pose: the wheel counters moved %.2f m and %.2f m since",
                 left_m, right_m);
  } else {
    // What the robot did while no firmware ran (the last step's end, the ODrives' watchdog
    // stopping it), from the counters the controllers kept (at the nominal wheels: the base's
    // calibration, [base] odometry_*, applies here as it does to the odometry).
    const core::Pose2 moved =
        core::arc_motion(left_m * static_cast<double>(config_.odometry_left_scale()),
                         right_m * static_cast<double>(config_.odometry_right_scale()),
                         static_cast<double>(config_.odometry_track_m()));
    state_.pose = core::compose(state_.pose, moved);
    line.appendf("resumed pose moved on by the wheels: %.3f m, %.1f deg",
                 static_cast<double>(std::hypot(moved.x_m, moved.y_m)),
                 static_cast<double>(moved.yaw_rad) * 180.0 / 3.14159265358979323846);
  }
  state_.add_log(state_.cycle, line.view());
  state_.wheels_known = false;  // used: a later anchor (after a hold) keeps the pose
  return true;
}

void Mission::save_pose(std::uint64_t now_us) {
  take_pose();
  next_pose_save_us_ = now_us + params_.pose_save_period_us;
  if (saver_ != nullptr) submit_pending_ = !saver_->submit(state_);
}

void Mission::end_cycle(const char* what) {
  ++state_.cycle;
  ++cycles_this_run_;
  take_pose();
  map_.save(state_);
  state_.stereo_bias_per_m = look_.stereo().inverse_range_bias();
  state_.has_goal = tracker_.confirmed();
  if (state_.has_goal) {
    state_.goal = {tracker_.estimate_m().x(), tracker_.estimate_m().y()};
    state_.goal_height_m = tracker_.estimate_m().z();
  }
  TextBuffer<MissionLogEntry::kMaxTextBytes + 1> line;
  line.appendf("cycle %s x_m=%.2f y_m=%.2f pieces=%u features=%u obst=%u expl=%u", what,
               static_cast<double>(state_.pose.x_m), static_cast<double>(state_.pose.y_m),
               last_pieces_, look_.last_features(),
               static_cast<unsigned>(map_.global().obstacles().size()),
               static_cast<unsigned>(map_.global().exploration().size()));
  state_.add_log(state_.cycle, line.view());
  if (saver_ != nullptr) submit_pending_ = !saver_->submit(state_);
  if (snapshots_ != nullptr) {
    snapshot_step_ = SnapshotStep::kPending;
    snapshot_state_ = phase_name(phase_);
    snapshot_look_pose_ = look_pose_;
  }
  // When full, every other point goes: the path stays whole at half the resolution.
  (void)path_.push_back_thinning({state_.pose.x_m, state_.pose.y_m});
}

void Mission::write_trace(std::uint64_t now_us) {
  if (trace_ == nullptr || now_us < next_trace_us_) return;
  next_trace_us_ += params_.trace_period_us;
  if (next_trace_us_ <= now_us) next_trace_us_ = now_us + params_.trace_period_us;
  const core::Pose2 estimate = pose_.pose();
  const core::Pose2 truth = truth_ != nullptr ? truth_->robot_pose() : estimate;
  const hal::PanTiltState ptu = hal_.pan_tilt.state();
  trace_->row(static_cast<double>(now_us) * 1e-6, truth, ptu.pan_rad, ptu.tilt_rad,
              phase_name(phase_), pose_.odometry_pose(), estimate);
}

// ---------------------------------------------------------------- background

SliceResult Mission::run_slice(SliceBudget& budget) {
  // The last cycle's picture first: it shows that cycle's readings, model and value function.
  if (snapshot_step_ != SnapshotStep::kIdle) {
    if (!budget.next_unit()) return SliceResult::kMore;
    CpuScope cpu(nullptr, longest(Unit::kSnapshot));
    snapshot_unit();
    return SliceResult::kMore;
  }
  if (phase_ == Phase::kDone) return SliceResult::kMore;
  // The view just grabbed: stereo, target, floor cue on each frame (a unit each).
  if (phase_ == Phase::kLook && scan_.view_ready()) {
    if (!budget.next_unit()) return SliceResult::kMore;
    if (look_lists_stale_) {
      look_.begin_look();  // frames kept from the last look were seen from elsewhere
      look_lists_stale_ = false;
    }
    if (process_view(static_cast<ViewPart>(view_part_++))) {
      view_part_ = 0;
      scan_.view_processed();
    }
    return SliceResult::kMore;
  }
  if (phase_ == Phase::kThink) return think_slice(budget);
  if (phase_ == Phase::kPlan) return plan_slice(budget);
  return SliceResult::kMore;
}

SliceResult Mission::think_slice(SliceBudget& budget) {
  double* const think_cpu = &cpu_s_[1];
  if (think_step_ == ThinkStep::kBegin) {
    if (!budget.next_unit()) return SliceResult::kMore;
    CpuScope cpu(think_cpu, longest(Unit::kModel));
    begin_think();
  }
  while (!map_.done()) {
    if (!budget.next_unit()) return SliceResult::kMore;
    CpuScope cpu(think_cpu, longest(Unit::kModel));
    map_.run_unit();
  }
  // The look registered against the grid before anything of it is fused (register_looks).
  if (think_step_ == ThinkStep::kModel) {
    if (params_.register_looks) {
      if (!budget.next_unit()) return SliceResult::kMore;
      CpuScope cpu(&register_cpu_s_, longest(Unit::kRegister));
      map_.begin_register(look_pose_, params_.registration);
    }
    think_step_ = ThinkStep::kRegister;
  }
  while (params_.register_looks && !map_.register_done()) {
    if (!budget.next_unit()) return SliceResult::kMore;
    CpuScope cpu(&register_cpu_s_, longest(Unit::kRegister));
    map_.register_unit();
  }
  if (think_step_ == ThinkStep::kRegister) {
    if (!budget.next_unit()) return SliceResult::kMore;
    CpuScope cpu(think_cpu, longest(Unit::kMap));
    if (params_.register_looks) localize();
    after_think();
    think_step_ = ThinkStep::kGrid;
  }
  // The look into the world memory's grid.
  while (!map_.grid_done()) {
    if (!budget.next_unit()) return SliceResult::kMore;
    CpuScope cpu(think_cpu, longest(Unit::kMap));
    map_.grid_unit();
  }
  phase_ = Phase::kPlan;
  return SliceResult::kMore;
}

SliceResult Mission::plan_slice(SliceBudget& budget) {
  double* const plan_cpu = &cpu_s_[2];
  switch (plan_step_) {
    case PlanStep::kChoose:
    case PlanStep::kChooseNextOnLook: {
      // The step on the value function, one action per unit.
      while (!planner_.choice_done()) {
        if (!budget.next_unit()) return SliceResult::kMore;
        CpuScope cpu(plan_cpu, longest(Unit::kStep));
        planner_.choose_heading();
      }
      if (!budget.next_unit()) return SliceResult::kMore;
      CpuScope cpu(plan_cpu, longest(Unit::kStep));
      if (plan_step_ == PlanStep::kChooseNextOnLook) {
        finish_next_step_on_look();
      } else {
        after_step_choice();
      }
      return SliceResult::kDone;
    }
    case PlanStep::kNextOnLook: {
      if (!budget.next_unit()) return SliceResult::kMore;
      CpuScope cpu(plan_cpu, longest(Unit::kStep));
      if (planner_.begin_next_on_look(pose_.pose(), look_pose_, map_.local().navigable)) {
        plan_step_ = PlanStep::kChooseNextOnLook;
        return SliceResult::kMore;
      }
      end_cycle("step done");
      if (phase_ != Phase::kDone) begin_look(now_us_);
      return SliceResult::kDone;
    }
    case PlanStep::kValueStart:
    case PlanStep::kValue:
      break;
  }
  if (plan_step_ == PlanStep::kValueStart) {
    if (!budget.next_unit()) return SliceResult::kMore;
    CpuScope cpu(plan_cpu, longest(Unit::kPlanStart));
    begin_plan();
  }
  while (!planner_.value_done()) {
    if (!budget.next_unit()) return SliceResult::kMore;
    CpuScope cpu(plan_cpu, longest(Unit::kValue));
    planner_.value_unit();
  }
  if (!budget.next_unit()) return SliceResult::kMore;
  CpuScope cpu(plan_cpu, longest(Unit::kStep));
  if (start_step_choice()) {
    plan_step_ = PlanStep::kChoose;
    return SliceResult::kMore;
  }
  return SliceResult::kDone;
}

bool Mission::process_view(ViewPart part) {
  CpuScope cpu(&cpu_s_[0], longest(Unit::kView));
  const GrabbedView view = scan_.view();
  TargetFixes fixes;
  const bool done = look_.process(part, view, fixes);
  if (part == ViewPart::kTarget) {
    const auto id = static_cast<std::uint32_t>(state_.cycle * 256U + view.index);
    const bool confirmed = tracker_.confirmed();
    const bool saw_pair = add_target_fix(fixes.pair, id);
    const bool saw_across = add_target_fix(fixes.across, id);
    const bool saw = saw_pair || saw_across;
    look_saw_target_ = look_saw_target_ || saw;
    // The pair aimed at the confirmed target, in range, with a line of sight the map does
    // not block, that did not see it: a miss.
    if (view.aimed && confirmed && !saw && target_in_clear_sight()) {
      look_missed_target_ = true;
      if (tracker_.missed()) {
        state_.add_log(state_.cycle, "target revoked: missing where it should be seen");
      }
    }
  }
  return done;
}

bool Mission::target_in_clear_sight() const {
  const Eigen::Vector3f& g = tracker_.estimate_m();
  // The target hangs on a surface: the map's last cells before it may be that surface.
  return map_.grid().sight_clear({look_pose_.x_m, look_pose_.y_m}, {g.x(), g.y()},
                                 params_.target_surface_margin_m);
}

bool Mission::add_target_fix(const stereo::TargetFix& fix, std::uint32_t view) {
  if (!fix.found) return false;
  const Eigen::Vector3f p = fix_in_world(look_pose_, fix, params_.rig.ptu_height_m);
  tracker_.add(p, fix.confidence, view, fix.range_error_m, {look_pose_.x_m, look_pose_.y_m});
  return tracker_.is_target(p);
}

void Mission::begin_think() {
  think_step_ = ThinkStep::kModel;
  look_.end_look(params_.limits);
  check_calibration();
  map_.begin(params_.model, look_.readings(), look_pose_);
}

void Mission::check_calibration() {
  // A look with enough obstacle bases seen by both the stereo and the floor cue: the running
  // ratio is the latest such look's, weighed with the ones before by their counts.
  float ratio = 0.0F;
  std::size_t n = 0;
  if (!look_.range_check().median(ratio, n) || n < kCalibrationMinBases) return;
  const auto bases = static_cast<std::uint32_t>(n);
  const float before = static_cast<float>(calibration_bases_);
  calibration_ratio_ = (calibration_ratio_ * before + ratio * static_cast<float>(bases)) /
                       (before + static_cast<float>(bases));
  calibration_bases_ += bases;
  if (calibration_warned_ || std::fabs(ratio - 1.0F) <= kCalibrationTolerance) return;
  calibration_warned_ = true;
  calibration_text_.clear();
  calibration_text_.appendf(
      "calibration suspect: stereo distances %.3f of the floor's at %u obstacle bases "
      "(1 +- %.2f expected); check camera.focal_px and the lens",
      static_cast<double>(ratio), static_cast<unsigned>(bases),
      static_cast<double>(kCalibrationTolerance));
  state_.add_log(state_.cycle, calibration_text_.view());
}

void Mission::localize() {
  const worldmap::Registration& r = map_.registration();
  if (!r.matched) return;
  look_pose_ = pose_.correct(look_pose_, r);
  ++registered_looks_;
}

void Mission::after_think() {
  const mapping::LocalModelBuilder& builder = map_.builder();
  last_pieces_ = static_cast<std::uint32_t>(builder.stats().pieces);
  if (builder.stats().guard_dropped > 0 || builder.stats().guard_points_full) {
    ++guard_truncated_looks_;
  }
  FuseParams fuse;
  fuse.points = params_.points;
  fuse.robot_radius_m = params_.value.robot_radius_m;
  fuse.goal_standoff_m = params_.rewards.goal_standoff_m;
  const bool lone_sighting = !tracker_.confirmed() && tracker_.sightings() > 0;
  map_.fuse(look_pose_, fuse, lone_sighting ? &tracker_.candidate_m() : nullptr);
  // The model in the text format, for the console and the state file.
  const std::span<char> text = model_text_.back();
  const std::size_t n = aln::write_text(builder.model(), text.data(), text.size());
  if (n > 0 && state_.set_model({text.data(), n})) model_text_.publish(n);
  map_.begin_grid(look_pose_, params_.fusion);
}

void Mission::begin_plan() {
  plan_step_ = PlanStep::kValue;
  core::Point2 goal{};
  const bool has_goal = target_goal(goal);
  planner_.start_value(map_.global(), map_.grid(), has_goal ? &goal : nullptr,
                       {look_pose_.x_m, look_pose_.y_m},
                       static_cast<std::uint32_t>(state_.seed * 7919U + state_.cycle),
                       has_goal && !tracker_.confirmed());
}

bool Mission::target_goal(core::Point2& goal) const {
  const bool candidate = params_.candidate_as_goal && tracker_.provisional();
  if (!tracker_.confirmed() && !candidate) return false;
  const Eigen::Vector3f& g = tracker_.confirmed() ? tracker_.estimate_m() : tracker_.candidate_m();
  goal = {g.x(), g.y()};
  return true;
}

bool Mission::start_step_choice() {
  const core::Pose2 here = pose_.pose();
  core::Point2 goal{};
  switch (planner_.begin_choice(here, map_.local().navigable,
                                map_.global().exploration().size() != 0, target_goal(goal))) {
    case StepOutcome::kChoosing:
      return true;
    case StepOutcome::kNothingLeft:
      end_cycle("nothing left to explore");
      finish(Result::kNotFound, "nothing left to explore", Ending::kFinal);
      return false;
    default:  // kTurnRound
      drive(Move::kTurnRound);
      return false;
  }
}

void Mission::after_step_choice() {
  const core::Pose2 here = pose_.pose();
  switch (planner_.end_choice(here, look_pose_, map_.local().navigable, breadcrumbs_)) {
    case StepOutcome::kAtGoal:
      // This look was taken here: it saw the target afresh, or that is a miss.
      return at_standoff(now_us_, true);
    case StepOutcome::kMove:
      steps_this_look_ = 0;
      return drive(Move::kStep);
    case StepOutcome::kBackOff:
      return drive(Move::kBackOff);
    default:  // kNoSafeStep
      break;
  }
  end_cycle("no safe step");
  if (planner_.gave_up())
    return finish(Result::kNotFound, "no safe step in several looks", Ending::kFinal);
  begin_look(now_us_);
}

void Mission::finish_next_step_on_look() {
  if (planner_.end_next_on_look() == StepOutcome::kMove) return drive(Move::kStep);
  end_cycle("step done");
  if (phase_ != Phase::kDone) begin_look(now_us_);
}

// One unit of the cycle's picture: set it up (the first), then a panel or a band of rows.
void Mission::snapshot_unit() {
  if (snapshot_step_ == SnapshotStep::kPending) {
    SnapshotInputs in;
    in.cycle = static_cast<std::uint32_t>(state_.cycle);
    in.state = snapshot_state_;
    in.robot = state_.pose;
    in.robot_radius_m = config_.robot_radius_m;
    in.look_pose = snapshot_look_pose_;
    in.readings = &look_.readings();
    in.builder = &map_.builder();
    in.map = &map_.global();
    core::Point2 goal{};
    if (tracker_.confirmed()) {
      goal = {tracker_.estimate_m().x(), tracker_.estimate_m().y()};
      in.goal = &goal;
    }
    in.path = path_.span();
    in.grid = &map_.grid();
    core::Point2 grid_goal{};
    if (planner_.nav_choice().kind != worldmap::NavGoalKind::kNone) {
      grid_goal = planner_.nav_choice().goal;
      in.grid_goal = &grid_goal;
    }
    in.value = &planner_.value();
    in.decision = &planner_.decision();
    in.truth = truth_;
    if (truth_ != nullptr)
      in.frame_origin_in_world = pose_.frame_origin_in_world(truth_->odometry_origin());
    begin_snapshot(in, *snapshots_);
    snapshot_step_ = SnapshotStep::kWriting;
    return;
  }
  if (!snapshots_->run_unit()) return;
  snapshot_step_ = SnapshotStep::kIdle;
  if (!snapshots_->ok()) {
    TextBuffer<MissionLogEntry::kMaxTextBytes + 1> line;
    line.appendf("snapshot: %s", snapshots_->error());
    state_.add_log(state_.cycle, line.view());
  }
}

void Mission::finish_saving() {
  while (snapshot_step_ != SnapshotStep::kIdle) snapshot_unit();  // the last cycle's picture
  if (saver_ == nullptr) return;
  // Where the base came to rest, not where the last cycle ended: it may still have rolled a
  // few millimetres after its step was done, or been stopped mid-drive.
  take_pose();
  submit_pending_ = true;
  while (submit_pending_) submit_pending_ = !saver_->submit(state_);
  saver_->flush();
}

}  // namespace boticelli::firmware::mission
