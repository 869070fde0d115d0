// Mission: the Look–Think–Drive state machine (see mission.h).
#include "firmware/mission/mission.h"

#include <algorithm>
#include <cmath>
#include <ctime>
#include <limits>

#include "algo/aln/text_format.h"
#include "algo/core/angles.h"
#include "algo/image/low_res_frame.h"
#include "firmware/mission/trace_writer.h"
#include "firmware/snapshot.h"
#include "firmware/text_buffer.h"

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

// Model text buffer: the text format of the last fitted model (console `model`, state file).
char g_model_text[MissionState::kMaxModelBytes];

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
      trace_(c.trace),
      snapshots_(c.snapshots),
      params_(make_mission_params(c.config)),
      rig_(params_.rig),
      stereo_(rig_, params_.stereo),
      floor_cue_(rig_) {
  tracker_.configure(params_.target);
  driver_.configure(params_.drive);
}

void Mission::start(std::uint64_t now_us) {
  now_us_ = now_us;
  next_trace_us_ = now_us;
  phase_ = Phase::kStart;
  result_ = Result::kRunning;
  end_reason_.clear();
  cycles_this_run_ = 0;
  failed_cycles_ = 0;
  turned_round_ = false;
  map_.clear();
  for (const core::Point2& p : state_.obstacles) (void)map_.obstacles().push_back(p);
  for (const core::Point2& p : state_.exploration) (void)map_.exploration().push_back(p);
  anchor_frame();
  tracker_.clear();
  if (state_.has_goal) {
    // A resumed goal was confirmed before the restart: it stands as two agreeing views.
    const Eigen::Vector3f g(state_.goal.x_m, state_.goal.y_m, state_.goal_height_m);
    tracker_.add(g, 1.0F, 0xFFFFFFF0U);
    tracker_.add(g, 1.0F, 0xFFFFFFF1U);
  }
  trail_.clear();
  path_.clear();
  breadcrumbs_.clear();
  has_prior_look_ = false;  // a resumed mission's first look has none
  retreating_ = false;
  snapshot_pending_ = false;
  snapshot_writing_ = false;
  look_lists_stale_ = false;
}

core::Pose2 Mission::odometry_pose() const {
  const hal::Odometry o = hal_.base.odometry();
  return core::compose(frame_from_odometry_, {static_cast<float>(o.x_m), static_cast<float>(o.y_m),
                                              static_cast<float>(o.yaw_rad)});
}

void Mission::anchor_frame() {
  const hal::Odometry o = hal_.base.odometry();
  const core::Pose2 odometry{static_cast<float>(o.x_m), static_cast<float>(o.y_m),
                             static_cast<float>(o.yaw_rad)};
  frame_from_odometry_ = core::compose(state_.pose, core::inverse(odometry));
}

core::Pose2 Mission::frame_origin_in_world() const {
  return core::compose(truth_->odometry_origin(), core::inverse(frame_from_odometry_));
}

core::Pose2 Mission::pose() const {
  return odometry_pose();
}

float Mission::pan_rad() const {
  return hal_.pan_tilt.state().pan_rad;
}

MapCounts Mission::map_counts() const {
  MapCounts m;
  m.polygon_vertices = static_cast<std::uint32_t>(builder_.map().free.vertex_count());
  m.obstacle_points = static_cast<std::uint32_t>(map_.obstacles().size());
  m.exploration_points = static_cast<std::uint32_t>(map_.exploration().size());
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
  const core::Pose2 o = frame_origin_in_world();
  const Eigen::Vector3f& e = tracker_.estimate_m();
  const core::Point2 w = core::to_world(o, {e.x(), e.y()});
  const Eigen::Vector3f world(w.x_m, w.y_m, e.z());
  return (world - truth_->target_m()).norm();
}

void Mission::view_angles(std::size_t view, float& pan_rad, float& tilt_rad, bool& pair) const {
  if (view >= scan_views()) {
    pan_rad = aimed_pan_rad_;
    tilt_rad = aimed_tilt_rad_;
    pair = true;
    return;
  }
  const LookView v = scan_view(params_, hal_.pan_tilt.limits(), view);
  pan_rad = v.pan_rad;
  tilt_rad = v.tilt_rad;
  pair = v.pair;
}

void Mission::finish(Result result, const char* why) {
  if (result_ != Result::kRunning) return;
  result_ = result;
  end_reason_.clear();
  end_reason_.append(why);
  phase_ = Phase::kDone;
  want_frame_ = false;
  driver_.reset();
  hal_.base.set_velocity(0.0F, 0.0F);
  TextBuffer<MissionLogEntry::kMaxTextBytes + 1> line;
  line.appendf("mission %s: %s", result_name(result), why);
  state_.add_log(state_.cycle, line.view());
  if (saver_ != nullptr) submit_pending_ = !saver_->submit(state_);
}

void Mission::abort(const char* why) {
  finish(Result::kAborted, why);
}

void Mission::abort_with(const char* why, const char* device_error) {
  if (device_error == nullptr || device_error[0] == '\0') return abort(why);
  TextBuffer<160> text;
  text.appendf("%s: %s", why, device_error);
  abort(text.c_str());
}

// ---------------------------------------------------------------- control (mission task)

bool Mission::hold_needed() {
  return safety_.engaged() || executive_.background_paused();
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
  if (safety_.engaged() && safety_.cause() == StopCause::kBumper) {
    abort("bumper contact");
    return;
  }
  if (hold_needed() && phase_ != Phase::kHold) {
    held_phase_ = phase_;
    phase_ = Phase::kHold;
    want_frame_ = false;
    released_ = false;
    if (driver_.busy()) driver_.abort("held");
  }
  switch (phase_) {
    case Phase::kStart: {
      const hal::PanTiltState ptu = hal_.pan_tilt.state();
      if (ptu.fault) return abort_with("pan-tilt unit fault", hal_.pan_tilt.error());
      if (hal_.base.health() == hal::BaseHealth::kReady && !ptu.moving) {
        anchor_frame();  // the odometry as the base reports it once ready
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
    (void)driver_.update(odometry_pose(), o.v_m_s, o.omega_rad_s, now_us);
  }
  if (safety_.engaged()) {
    // A button stop is cleared once the button has been released for a while; a console
    // stop waits for the console's `clear`.
    if (safety_.cause() == StopCause::kButton && !hal_.estop.read()) {
      if (!released_) {
        released_ = true;
        released_since_us_ = now_us;
      } else if (now_us - released_since_us_ >= params_.release_hold_us) {
        (void)safety_.clear();
      }
    } else {
      released_ = false;
    }
    return;
  }
  if (executive_.background_paused()) return;
  if (hal_.base.health() != hal::BaseHealth::kReady) return;
  // Carry on. An interrupted step is not resumed blind: the robot looks again first.
  if (held_phase_ == Phase::kDrive) {
    end_cycle("step interrupted");
    if (phase_ != Phase::kDone) begin_look(now_us);
    return;
  }
  phase_ = held_phase_;
  if (phase_ == Phase::kLook && look_step_ != LookStep::kProcess) {
    look_step_ = LookStep::kMove;  // re-issue the interrupted move and wait again
  }
}

void Mission::begin_look(std::uint64_t now_us) {
  phase_ = Phase::kLook;
  // A planned move not begun is void.
  drive_pending_ = turn_pending_ = turning_round_ = retreating_ = next_step_pending_ = false;
  choosing_ = false;
  view_ = 0;
  second_frame_ = false;
  look_step_ = LookStep::kMove;
  look_lists_stale_ = true;  // cleared by the background before the first view
  view_ready_ = false;
  view_part_ = 0;
  look_pose_ = odometry_pose();
  last_sighting_ = {};  // the robot has moved: no earlier frame pairs with this look's
  aim_at_target();
  step_deadline_us_ = now_us + params_.ptu_timeout_us;
  think_started_ = false;
  plan_started_ = false;
}

void Mission::aim_at_target() {
  aimed_ = false;
  if (tracker_.sightings() == 0) return;
  const Eigen::Vector3f& c = tracker_.confirmed() ? tracker_.estimate_m() : tracker_.candidate_m();
  const core::Point2 q = core::to_robot(look_pose_, {c.x(), c.y()});
  const float d = std::hypot(q.x_m, q.y_m);
  const hal::PanTiltLimits lim = hal_.pan_tilt.limits();
  const float pan = std::atan2(q.y_m, q.x_m);
  if (d > params_.limits.max_range_m || pan < lim.pan_min_rad || pan > lim.pan_max_rad) return;
  // The vertex midway between the pair's two tilts, so both frames hold it.
  const float elevation = std::atan2(c.z() - params_.rig.ptu_height_m, d);
  const float phi = params_.rig.tilt_step_rad;
  aimed_pan_rad_ = pan;
  aimed_tilt_rad_ = std::clamp(elevation + 0.5F * phi, lim.tilt_min_rad + phi, lim.tilt_max_rad);
  aimed_ = true;
}

void Mission::control_look(std::uint64_t now_us) {
  hal_.base.set_velocity(0.0F, 0.0F);
  const hal::PanTiltState ptu = hal_.pan_tilt.state();
  if (ptu.fault) return abort_with("pan-tilt unit fault", hal_.pan_tilt.error());
  switch (look_step_) {
    case LookStep::kMove: {
      view_angles(view_, view_pan_rad_, view_tilt_rad_, view_pair_);
      const float tilt =
          second_frame_ ? view_tilt_rad_ - params_.rig.tilt_step_rad : view_tilt_rad_;
      if (!hal_.pan_tilt.move_to(view_pan_rad_, tilt)) {
        return abort_with("pan-tilt unit refused a move", hal_.pan_tilt.error());
      }
      step_deadline_us_ = now_us + params_.ptu_timeout_us;
      look_step_ = LookStep::kSettle;
      settle_until_us_ = 0;
      return;
    }
    case LookStep::kSettle:
      if (ptu.moving) {
        if (now_us > step_deadline_us_) abort("pan-tilt move did not complete");
        return;
      }
      if (settle_until_us_ == 0) settle_until_us_ = now_us + params_.settle_us;
      if (now_us < settle_until_us_) return;
      frame_ready_ = false;
      want_frame_ = true;
      step_deadline_us_ = now_us + params_.frame_timeout_us;
      look_step_ = LookStep::kGrab;
      return;
    case LookStep::kGrab:
      if (!frame_ready_) {
        if (now_us > step_deadline_us_) abort_with("no camera frame", hal_.camera.error());
        return;
      }
      want_frame_ = false;
      if (!second_frame_) {
        pair_pose_.pan_rad = ptu.pan_rad;
        pair_pose_.first_tilt_rad = ptu.tilt_rad;
      } else {
        pair_pose_.second_tilt_rad = ptu.tilt_rad;
      }
      if (view_pair_ && !second_frame_) {
        second_frame_ = true;
        look_step_ = LookStep::kMove;
        return;
      }
      view_ready_ = true;
      look_step_ = LookStep::kProcess;
      return;
    case LookStep::kProcess:
      if (view_ready_) return;  // the background has not taken the view yet
      second_frame_ = false;
      if (++view_ < view_count()) {
        look_step_ = LookStep::kMove;
        return;
      }
      // Look complete: park the camera level and think.
      (void)hal_.pan_tilt.move_to(0.0F, 0.0F);
      phase_ = Phase::kThink;
      return;
  }
}

void Mission::on_frame(const hal::Frame& frame) {
  if (!want_frame_ || frame_ready_ || frame.timestamp_us < settle_until_us_) return;
  image::LowResFrame& into = second_frame_ ? second_ : first_;
  if (!image::downsample_yuyv(frame.data, frame.width_px, frame.height_px, frame.stride_bytes,
                              params_.rig.downsample_factor, into)) {
    return;
  }
  frame_ready_ = true;
}

void Mission::control_drive(std::uint64_t now_us) {
  if (drive_pending_) {
    drive_pending_ = false;
    const core::Pose2 from = odometry_pose();
    if (turn_pending_) {
      turn_pending_ = false;
      turning_round_ = true;
      driver_.start_turn(from, core::wrap_pi(from.yaw_rad + core::kPi<float>), now_us);
    } else {
      if (!retreating_) breadcrumbs_.step_started({from.x_m, from.y_m});
      driver_.start(from, decision_.target, now_us);
    }
  }
  const hal::Odometry o = hal_.base.odometry();
  const DriveCommand cmd = driver_.update(odometry_pose(), o.v_m_s, o.omega_rad_s, now_us);
  hal_.base.set_velocity(cmd.v_m_s, cmd.omega_rad_s);
  if (hal_.base.health() == hal::BaseHealth::kStopped && !safety_.engaged()) {
    return abort_with("base stopped by itself", hal_.base.error());
  }
  if (driver_.busy()) return;
  const bool ok = driver_.status() == DriveStatus::kDone;
  const core::Pose2 here = odometry_pose();
  trail_.add({here.x_m, here.y_m});
  if (tracker_.confirmed()) {
    const Eigen::Vector3f& g = tracker_.estimate_m();
    if (core::distance_m({here.x_m, here.y_m}, {g.x(), g.y()}) <=
        params_.rewards.goal_standoff_m + params_.step.arrival_tolerance_m) {
      end_cycle("at the target");
      return finish(Result::kFound, "within the stand-off of the target");
    }
  }
  if (retreating_) {
    retreating_ = false;
    if (ok) breadcrumbs_.reached();
    end_cycle(ok ? "no safe step, backed off" : driver_.failure());
    if (phase_ != Phase::kDone) begin_look(now_us);
    return;
  }
  if (turning_round_) {
    // Only a finished turn counts: an interrupted one is tried again at the next dead end.
    turning_round_ = false;
    if (ok) {
      turned_round_ = true;
      turned_round_at_ = {here.x_m, here.y_m};
    }
    end_cycle(ok ? "turned round" : driver_.failure());
    if (phase_ != Phase::kDone) begin_look(now_us);
    return;
  }
  if (ok && ++steps_this_look_ < params_.steps_per_look) {
    // Another step on the same look is worked out by the background (a unit of its own).
    next_step_pending_ = true;
    phase_ = Phase::kPlan;
    return;
  }
  end_cycle(ok ? "step done" : driver_.failure());
  if (phase_ != Phase::kDone) begin_look(now_us);
}

// Another step on the same look: the look's navigable polygon as seen from where the robot
// is now (each ray as far as the straight move stays inside it), and the same value function.
bool Mission::start_next_step_on_look() {
  const core::Pose2 here = odometry_pose();
  const mapping::StarPolygon& nav = builder_.map().navigable;
  if (!nav.contains(core::to_robot(look_pose_, {here.x_m, here.y_m}))) return false;
  from_here_.set_vertex_count(nav.vertex_count());
  const float reach = params_.value.step_m;
  constexpr int kSamples = 20;
  for (std::size_t k = 0; k < from_here_.vertex_count(); ++k) {
    const float a = from_here_.angle_rad(k) + here.yaw_rad;
    float rho = 0.0F;
    for (int i = 1; i <= kSamples; ++i) {
      const float t = reach * static_cast<float>(i) / kSamples;
      const core::Point2 p{here.x_m + t * std::cos(a), here.y_m + t * std::sin(a)};
      if (!nav.contains(core::to_robot(look_pose_, p))) break;
      rho = t;
    }
    from_here_.set_rho_m(k, rho);
  }
  chooser_.start(value_, from_here_, here, params_.step);
  return true;
}

void Mission::finish_next_step_on_look() {
  if (decision_.kind == planning::StepKind::kMove) {
    drive_pending_ = true;
    phase_ = Phase::kDrive;
    return;
  }
  end_cycle("step done");
  if (phase_ != Phase::kDone) begin_look(now_us_);
}

void Mission::end_cycle(const char* what) {
  ++state_.cycle;
  ++cycles_this_run_;
  state_.pose = odometry_pose();
  state_.obstacles.clear();
  for (const core::Point2& p : map_.obstacles()) {
    if (!state_.obstacles.push_back(p)) break;
  }
  state_.exploration.clear();
  for (const core::Point2& p : map_.exploration()) {
    if (!state_.exploration.push_back(p)) break;
  }
  state_.has_goal = tracker_.confirmed();
  if (state_.has_goal) {
    state_.goal = {tracker_.estimate_m().x(), tracker_.estimate_m().y()};
    state_.goal_height_m = tracker_.estimate_m().z();
  }
  TextBuffer<MissionLogEntry::kMaxTextBytes + 1> line;
  line.appendf("cycle %s x_m=%.2f y_m=%.2f pieces=%u features=%u obst=%u expl=%u", what,
               static_cast<double>(state_.pose.x_m), static_cast<double>(state_.pose.y_m),
               last_pieces_, last_features_, static_cast<unsigned>(map_.obstacles().size()),
               static_cast<unsigned>(map_.exploration().size()));
  state_.add_log(state_.cycle, line.view());
  if (saver_ != nullptr) submit_pending_ = !saver_->submit(state_);
  if (snapshots_ != nullptr) {
    snapshot_pending_ = true;
    snapshot_state_ = phase_name(phase_);
    snapshot_look_pose_ = look_pose_;
  }
  if (path_.size() == path_.capacity()) {
    // Keep every other point: the path stays whole at half the resolution.
    std::size_t kept = 0;
    for (std::size_t i = 0; i < path_.size(); i += 2) path_[kept++] = path_[i];
    path_.resize(kept);
  }
  (void)path_.push_back({state_.pose.x_m, state_.pose.y_m});
}

void Mission::write_trace(std::uint64_t now_us) {
  if (trace_ == nullptr || now_us < next_trace_us_) return;
  next_trace_us_ += params_.trace_period_us;
  if (next_trace_us_ <= now_us) next_trace_us_ = now_us + params_.trace_period_us;
  const core::Pose2 odo = odometry_pose();
  const core::Pose2 truth = truth_ != nullptr ? truth_->robot_pose() : odo;
  const hal::PanTiltState ptu = hal_.pan_tilt.state();
  trace_->row(static_cast<double>(now_us) * 1e-6, truth, ptu.pan_rad, ptu.tilt_rad,
              phase_name(phase_), odo);
}

// ---------------------------------------------------------------- background

StepResult Mission::step(SliceBudget& budget) {
  // The last cycle's picture first: it shows that cycle's readings, model and value function.
  if (snapshot_pending_ || snapshot_writing_) {
    if (!budget.next_unit()) return StepResult::kMore;
    CpuScope cpu(nullptr, longest(Unit::kSnapshot));
    snapshot_step();
    return StepResult::kMore;
  }
  if (phase_ == Phase::kDone) return StepResult::kMore;
  // The view just grabbed: stereo, target, floor cue on each frame (a unit each).
  if (phase_ == Phase::kLook && view_ready_) {
    if (!budget.next_unit()) return StepResult::kMore;
    if (look_lists_stale_) {
      features_.clear();
      floor_obstacles_.clear();
      floor_free_.clear();
      floor_free_near_.clear();
      floor_blocked_.clear();
      floor_cue_.begin_look();  // frames kept from the last look were seen from elsewhere
      look_lists_stale_ = false;
    }
    if (process_view(view_part_++)) {
      view_part_ = 0;
      view_ready_ = false;
    }
    return StepResult::kMore;
  }
  double* const think_cpu = &cpu_s_[1];
  double* const plan_cpu = &cpu_s_[2];
  if (phase_ == Phase::kThink) {
    if (!think_started_) {
      if (!budget.next_unit()) return StepResult::kMore;
      CpuScope cpu(think_cpu, longest(Unit::kModel));
      begin_think();
    }
    while (!builder_.done()) {
      if (!budget.next_unit()) return StepResult::kMore;
      CpuScope cpu(think_cpu, longest(Unit::kModel));
      (void)builder_.step();
    }
    if (!budget.next_unit()) return StepResult::kMore;
    CpuScope cpu(think_cpu, longest(Unit::kMap));
    after_think();
    return StepResult::kMore;
  }
  if (phase_ == Phase::kPlan && choosing_) {
    // The step on the value function, one action per unit.
    while (!chooser_.done()) {
      if (!budget.next_unit()) return StepResult::kMore;
      CpuScope cpu(plan_cpu, longest(Unit::kStep));
      (void)chooser_.step();
    }
    if (!budget.next_unit()) return StepResult::kMore;
    CpuScope cpu(plan_cpu, longest(Unit::kStep));
    choosing_ = false;
    decision_ = chooser_.decision();
    if (choosing_on_look_) {
      finish_next_step_on_look();
    } else {
      after_step_choice();
    }
    return StepResult::kDone;
  }
  if (phase_ == Phase::kPlan && next_step_pending_) {
    if (!budget.next_unit()) return StepResult::kMore;
    CpuScope cpu(plan_cpu, longest(Unit::kStep));
    next_step_pending_ = false;
    if (start_next_step_on_look()) {
      choosing_ = true;
      choosing_on_look_ = true;
      return StepResult::kMore;
    }
    end_cycle("step done");
    if (phase_ != Phase::kDone) begin_look(now_us_);
    return StepResult::kDone;
  }
  if (phase_ == Phase::kPlan) {
    if (!plan_started_) {
      if (!budget.next_unit()) return StepResult::kMore;
      CpuScope cpu(plan_cpu, longest(Unit::kPlanStart));
      begin_plan();
    }
    while (!value_.done()) {
      if (!budget.next_unit()) return StepResult::kMore;
      CpuScope cpu(plan_cpu, longest(Unit::kValue));
      (void)value_.step(params_.vi_work_per_unit);
    }
    if (!budget.next_unit()) return StepResult::kMore;
    CpuScope cpu(plan_cpu, longest(Unit::kStep));
    if (start_step_choice()) {
      choosing_ = true;
      choosing_on_look_ = false;
      return StepResult::kMore;
    }
    return StepResult::kDone;
  }
  return StepResult::kMore;
}

bool Mission::process_view(std::uint8_t part) {
  CpuScope cpu(&cpu_s_[0], longest(Unit::kView));
  switch (part) {
    case 0:
      if (view_pair_) {
        (void)stereo_.process(first_, second_, pair_pose_, features_);
        last_features_ = static_cast<std::uint32_t>(stereo_.points().size());
      }
      return false;
    case 1:
      if (view_pair_) {
        const stereo::TargetFix fix = stereo_.locate_target(first_, second_, pair_pose_);
        const auto view = static_cast<std::uint32_t>(state_.cycle * 256U + view_);
        add_target_fix(fix, view);
        // The vertex in this first frame and in the look's last one at another pan: a pair
        // with a longer baseline than the tilt's (the later view's sighting).
        if (fix.first.found) {
          const stereo::TargetSighting here{fix.first, pair_pose_.pan_rad,
                                            pair_pose_.first_tilt_rad};
          add_target_fix(stereo_.locate_target_across(last_sighting_, here), view);
          last_sighting_ = here;
        }
      }
      // The aimed pair looks up at the target, not at the floor.
      return view_ >= scan_views();
    case 2:
      // The floor cue: learn from the frames that see the floor close in front, then walk
      // the columns; a low pair's second frame sees nearer floor than its first.
      (void)floor_cue_.learn(first_, pair_pose_.pan_rad, pair_pose_.first_tilt_rad);
      (void)floor_cue_.process(first_, pair_pose_.pan_rad, pair_pose_.first_tilt_rad,
                               floor_obstacles_, floor_free_, &floor_free_near_, blocked_output());
      return !(view_pair_ && pair_pose_.second_tilt_rad < -0.3F);
    default:
      (void)floor_cue_.learn(second_, pair_pose_.pan_rad, pair_pose_.second_tilt_rad);
      (void)floor_cue_.process(second_, pair_pose_.pan_rad, pair_pose_.second_tilt_rad,
                               floor_obstacles_, floor_free_, &floor_free_near_, blocked_output());
      return true;
  }
}

void Mission::add_target_fix(const stereo::TargetFix& fix, std::uint32_t view) {
  if (!fix.found) return;
  // PTU frame → robot → world (odometry); the PTU centre is on the robot's axis.
  const core::Point2 w = core::to_world(look_pose_, {fix.point_ptu_m.x(), fix.point_ptu_m.y()});
  const Eigen::Vector3f world(w.x_m, w.y_m, fix.point_ptu_m.z() + params_.rig.ptu_height_m);
  tracker_.add(world, fix.confidence, view, fix.range_error_m);
}

void Mission::begin_think() {
  think_started_ = true;
  (void)evidence::filter_readings(features_, params_.limits);
  // The last look's free polygon, from where it stood as seen from here: what it saw free
  // keeps rays whose walks this look finds blocked open that far.
  mapping::PriorLook prior;
  if (has_prior_look_) {
    prior.free = &prior_look_free_;
    prior.pose = prior_look_pose_;
    prior.here = look_pose_;
  }
  builder_.start(params_.model, features_.span(), floor_obstacles_.span(), floor_free_.span(),
                 floor_free_near_.span(), floor_blocked_.span(), prior);
}

void Mission::after_think() {
  const mapping::LocalMap& local = builder_.map();
  last_pieces_ = static_cast<std::uint32_t>(builder_.stats().pieces);
  if (builder_.stats().guard_dropped > 0 || builder_.stats().guard_points_full) {
    ++guard_truncated_looks_;
  }
  // Map points (§5.4.4): obstacles where evidence backs the polygon's boundary; exploration
  // points on the bounding circle and where only the lack of seen floor cuts it.
  cycle_obstacles_.clear();
  cycle_exploration_.clear();
  const float radius = params_.model.extraction.bounding_radius_m;
  (void)builder_.map_points(params_.points, cycle_obstacles_, cycle_exploration_);
  // Known exploration points this look saw are explored; then this look's points go in.
  (void)map_.mark_explored(look_pose_, builder_.seen_free(), radius, params_.points);
  (void)map_.merge(look_pose_, local.free, radius, cycle_obstacles_, cycle_exploration_,
                   params_.points);
  prior_look_free_ = local.free;
  prior_look_pose_ = look_pose_;
  has_prior_look_ = true;
  // A sighting no second view has confirmed yet: look at it again from the stand-off (the
  // detector may miss it near the image's edge), unless the robot already looked from there.
  if (!tracker_.confirmed() && tracker_.sightings() > 0) {
    const Eigen::Vector3f& c = tracker_.candidate_m();
    const float dx = look_pose_.x_m - c.x();
    const float dy = look_pose_.y_m - c.y();
    const float d = std::hypot(dx, dy);
    if (d > params_.points.explored_look_radius_m + params_.rewards.goal_standoff_m) {
      const float s = params_.rewards.goal_standoff_m / d;
      const core::Point2 p{c.x() + s * dx, c.y() + s * dy};
      bool known = false;
      for (const core::Point2& q : map_.exploration()) {
        known = known || core::distance_m(p, q) < params_.points.exploration_merge_radius_m;
      }
      if (!known) (void)map_.exploration().push_back(p);
    }
  }
  // An exploration point the robot's disc cannot reach (it touches a known obstacle) would
  // only draw the robot into a corner: move it clear, toward where the robot looked from.
  (void)map_.clear_exploration({look_pose_.x_m, look_pose_.y_m}, params_.value.robot_radius_m,
                               radius, params_.points);
  // The model in the text format, for the console and the state file.
  const std::size_t n = aln::write_text(builder_.model(), g_model_text, sizeof g_model_text);
  if (n > 0) (void)state_.set_model({g_model_text, n});
  phase_ = Phase::kPlan;
}

void Mission::begin_plan() {
  plan_started_ = true;
  planning::RewardSources sources;
  sources.obstacles = map_.obstacles().span();
  sources.exploration = map_.exploration().span();
  sources.visited = trail_.points();
  sources.has_goal = tracker_.confirmed();
  if (sources.has_goal) sources.goal = {tracker_.estimate_m().x(), tracker_.estimate_m().y()};
  planning::ValueIterationParams vp = params_.value;
  vp.seed = static_cast<std::uint32_t>(state_.seed * 7919U + state_.cycle);
  value_.start(vp, params_.rewards, sources, {look_pose_.x_m, look_pose_.y_m});
}

bool Mission::start_step_choice() {
  const core::Pose2 here = odometry_pose();
  if (map_.exploration().size() == 0 && !tracker_.confirmed()) {
    // Turn round and look once more before giving up: the sector behind the robot is seen
    // only by the image's edges at the PTU's pan limits (or not at all, if the pans and the
    // field of view leave a gap), and a fresh look refits the model.
    const bool turned_here =
        turned_round_ && core::distance_m({here.x_m, here.y_m}, turned_round_at_) < 0.5F;
    if (turned_here) {
      end_cycle("nothing left to explore");
      finish(Result::kNotFound, "nothing left to explore");
      return false;
    }
    turn_pending_ = true;
    drive_pending_ = true;
    phase_ = Phase::kDrive;
    return false;
  }
  chooser_.start(value_, builder_.map().navigable, here, params_.step);
  return true;
}

void Mission::after_step_choice() {
  const core::Pose2 here = odometry_pose();
  if (decision_.kind == planning::StepKind::kAtGoal) {
    end_cycle("at the target");
    return finish(Result::kFound, "within the stand-off of the target");
  }
  if (decision_.kind == planning::StepKind::kMove) {
    // The thesis's consistency check: the whole step must lie in this look's polygon.
    const mapping::StarPolygon& nav = builder_.map().navigable;
    bool inside = true;
    for (int i = 1; i <= 20 && inside; ++i) {
      const float t = static_cast<float>(i) / 20.0F;
      const core::Point2 p{here.x_m + t * (decision_.target.x_m - here.x_m),
                           here.y_m + t * (decision_.target.y_m - here.y_m)};
      inside = nav.contains(core::to_robot(look_pose_, p));
    }
    if (inside) {
      failed_cycles_ = 0;
      steps_this_look_ = 0;
      drive_pending_ = true;
      phase_ = Phase::kDrive;
      return;
    }
  }
  // No safe step (an obstacle close by, or a poor fit, can leave no room in this look's
  // polygon): the place counts as visited once more and the robot looks again; from the
  // second such cycle in a row it first backs off along the step that brought it here. It
  // gives up after a few such cycles in a row.
  ++failed_cycles_;
  trail_.add({here.x_m, here.y_m});
  if (failed_cycles_ >= params_.back_off_after_failed_cycles &&
      failed_cycles_ < params_.max_failed_cycles && back_off()) {
    return;
  }
  end_cycle("no safe step");
  if (failed_cycles_ >= params_.max_failed_cycles) {
    return finish(Result::kNotFound, "no safe step in several looks");
  }
  begin_look(now_us_);
}

// The step back to the last breadcrumb: the robot's disc swept that segment on the way here, so
// it is driven without this look's polygon (which may hold no room at all).
bool Mission::back_off() {
  const core::Pose2 here = odometry_pose();
  core::Point2 back{};
  if (!breadcrumbs_.back_target({here.x_m, here.y_m}, params_.step.min_step_m, back)) return false;
  decision_ = {};
  decision_.kind = planning::StepKind::kMove;
  decision_.target = back;
  retreating_ = true;
  drive_pending_ = true;
  phase_ = Phase::kDrive;
  return true;
}

namespace {

// Working storage of the pictures (static: they are large).
core::FixedVector<SnapshotReading, kMaxLookFeatures + kMaxLookFloorObstacles> g_snap_readings;
std::array<core::Point2, mapping::kMaxPolygonVertices> g_snap_free;
std::array<core::Point2, mapping::kMaxPolygonVertices> g_snap_navigable;
std::array<core::Point2, 2048> g_snap_outline_points;
std::array<std::span<const core::Point2>, 256> g_snap_outlines;
std::array<SnapshotCircle, 256> g_snap_circles;

struct OccupancyView {
  const mapping::LocalModelBuilder* builder;
  core::Pose2 pose;
};
OccupancyView g_snap_occupancy{};  // the picture's occupancy field, read until it is done

// The occupancy model sliced at the robot's heights: the highest occupancy over the slices.
float occupancy_at(const void* context, float x_m, float y_m) {
  const auto& v = *static_cast<const OccupancyView*>(context);
  const core::Point2 q = core::to_robot(v.pose, {x_m, y_m});
  const float rho = std::hypot(q.x_m, q.y_m);
  const float alpha = core::wrap_two_pi(std::atan2(q.y_m, q.x_m));
  const mapping::ExtractionParams& p = v.builder->params().extraction;
  float m = 0.0F;
  for (std::size_t i = 0; i < p.height_count; ++i) {
    const float h = mapping::slice_height_m(p, i);
    m = std::max(m, v.builder->occupancy(alpha, h, std::sqrt(rho * rho + h * h)));
  }
  return std::clamp(m, 0.0F, 1.0F);
}

float value_at(const void* context, float x_m, float y_m) {
  return static_cast<const planning::ValueIteration*>(context)->value({x_m, y_m});
}

void to_world(const mapping::StarPolygon& poly, const core::Pose2& pose,
              std::array<core::Point2, mapping::kMaxPolygonVertices>& out) {
  for (std::size_t k = 0; k < poly.vertex_count(); ++k)
    out[k] = core::to_world(pose, poly.vertex(k));
}

}  // namespace

void Mission::begin_snapshot() {
  if (snapshots_ == nullptr) return;
  g_snap_readings.clear();
  auto add = [&](const evidence::Reading& r) {
    const core::Point2 w = core::to_world(snapshot_look_pose_, evidence::floor_point_m(r));
    (void)g_snap_readings.push_back({w.x_m, w.y_m, r.m});
  };
  for (const evidence::Reading& r : features_) add(r);
  for (const evidence::Reading& r : floor_obstacles_) add(r);
  const mapping::LocalMap& local = builder_.map();
  to_world(local.free, snapshot_look_pose_, g_snap_free);
  to_world(local.navigable, snapshot_look_pose_, g_snap_navigable);
  SnapshotFrame f;
  // The cycle's count and pose stand until the next cycle ends, after this picture.
  f.cycle = static_cast<std::uint32_t>(state_.cycle);
  f.state = snapshot_state_;
  f.robot = state_.pose;
  f.robot_radius_m = config_.robot_radius_m;
  // The view: the room so far (path, points) and 3.5 m around the robot.
  float x0 = f.robot.x_m - 3.5F, x1 = f.robot.x_m + 3.5F;
  float y0 = f.robot.y_m - 3.5F, y1 = f.robot.y_m + 3.5F;
  for (const core::Point2& p : path_) {
    x0 = std::min(x0, p.x_m - 1.0F);
    x1 = std::max(x1, p.x_m + 1.0F);
    y0 = std::min(y0, p.y_m - 1.0F);
    y1 = std::max(y1, p.y_m + 1.0F);
  }
  f.view = {x0, y0, x1, y1};
  f.readings = g_snap_readings.span();
  g_snap_occupancy = {&builder_, snapshot_look_pose_};
  f.occupancy = &occupancy_at;
  f.occupancy_context = &g_snap_occupancy;
  f.occupancy_threshold = params_.model.extraction.safe_occupancy;
  f.free_polygon = {g_snap_free.data(), local.free.vertex_count()};
  f.navigable_polygon = {g_snap_navigable.data(), local.navigable.vertex_count()};
  f.obstacle_points = map_.obstacles().span();
  f.exploration_points = map_.exploration().span();
  if (tracker_.confirmed())
    f.goal = core::Point2{tracker_.estimate_m().x(), tracker_.estimate_m().y()};
  f.path = path_.span();
  f.value = &value_at;
  f.value_context = &value_;
  if (decision_.kind == planning::StepKind::kMove) f.step_end = decision_.target;
  if (truth_ != nullptr) {
    // The truth is in the world frame; the pictures are in the mission frame.
    const core::Pose2 origin = frame_origin_in_world();
    std::size_t used = 0;
    std::size_t count = 0;
    for (const std::span<const core::Point2> outline : truth_->outlines()) {
      if (count == g_snap_outlines.size() || used + outline.size() > g_snap_outline_points.size()) {
        break;
      }
      for (std::size_t i = 0; i < outline.size(); ++i) {
        g_snap_outline_points[used + i] = core::to_robot(origin, outline[i]);
      }
      g_snap_outlines[count++] = {g_snap_outline_points.data() + used, outline.size()};
      used += outline.size();
    }
    std::size_t circles = 0;
    for (const SnapshotCircle& c : truth_->circles()) {
      if (circles == g_snap_circles.size()) break;
      g_snap_circles[circles++] = {core::to_robot(origin, c.centre), c.radius_m};
    }
    f.truth_polygons = {g_snap_outlines.data(), count};
    f.truth_circles = {g_snap_circles.data(), circles};
  }
  snapshots_->begin(f);
}

// One unit of the cycle's picture: set it up (the first), then a panel or a band of rows.
void Mission::snapshot_step() {
  if (snapshot_pending_) {
    begin_snapshot();
    snapshot_pending_ = false;
    snapshot_writing_ = true;
    return;
  }
  if (!snapshots_->step()) return;
  snapshot_writing_ = false;
  if (!snapshots_->ok()) {
    TextBuffer<MissionLogEntry::kMaxTextBytes + 1> line;
    line.appendf("snapshot: %s", snapshots_->error());
    state_.add_log(state_.cycle, line.view());
  }
}

void Mission::finish_saving() {
  while (snapshot_pending_ || snapshot_writing_) snapshot_step();  // the last cycle's picture
  if (saver_ == nullptr) return;
  // Where the base came to rest, not where the last cycle ended: it may still have rolled a
  // few millimetres after its step was done, or been stopped mid-drive.
  state_.pose = odometry_pose();
  submit_pending_ = true;
  while (submit_pending_) submit_pending_ = !saver_->submit(state_);
  saver_->flush();
}

}  // namespace boticelli::firmware::mission
