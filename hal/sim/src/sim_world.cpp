// SimWorld: fixed-step integration of the differential-drive base and the PTU axes, contacts of
// the robot's cylinder with the world's obstacles, scripted e-stop, watchdog stand-in.
#include "hal/sim/sim_world.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>

namespace boticelli::hal::sim {

namespace {

// Distance [m] from a point to a convex counter-clockwise polygon (negative inside: minus the
// distance to the nearest edge).
float distance_to_hull(const Collider& c, float px, float py) {
  if (c.hull_size == 1) return std::hypot(px - c.hull[0].x_m, py - c.hull[0].y_m);
  bool inside = c.hull_size >= 3;
  float best = std::numeric_limits<float>::infinity();
  for (std::size_t i = 0; i < c.hull_size; ++i) {
    const core::Point2 a = c.hull[i];
    const core::Point2 b = c.hull[(i + 1) % c.hull_size];
    const float ex = b.x_m - a.x_m;
    const float ey = b.y_m - a.y_m;
    const float len2 = ex * ex + ey * ey;
    const float t =
        len2 > 0.0F ? std::clamp(((px - a.x_m) * ex + (py - a.y_m) * ey) / len2, 0.0F, 1.0F) : 0.0F;
    best = std::min(best, std::hypot(px - a.x_m - t * ex, py - a.y_m - t * ey));
    if (ex * (py - a.y_m) - ey * (px - a.x_m) < 0.0F) inside = false;  // right of an edge
  }
  return inside ? -best : best;
}

}  // namespace

bool SimWorld::init(const World& world, const stereo::RigModel& rig, const SimParams& params,
                    char* error, std::size_t error_size) {
  world_ = &world;
  rig_ = &rig;
  params_ = params;
  if (params_.physics_step_us == 0) params_.physics_step_us = 1000;
  // The unit's limits are whole steps: round them inwards.
  PanTiltLimits& l = params_.ptu.limits;
  if (l.pan_resolution_rad > 0.0F) {
    l.pan_min_rad = std::ceil(l.pan_min_rad / l.pan_resolution_rad) * l.pan_resolution_rad;
    l.pan_max_rad = std::floor(l.pan_max_rad / l.pan_resolution_rad) * l.pan_resolution_rad;
  }
  if (l.tilt_resolution_rad > 0.0F) {
    l.tilt_min_rad = std::ceil(l.tilt_min_rad / l.tilt_resolution_rad) * l.tilt_resolution_rad;
    l.tilt_max_rad = std::floor(l.tilt_max_rad / l.tilt_resolution_rad) * l.tilt_resolution_rad;
  }
  now_us_ = 0;
  rng_state_ = params.seed * 0x9E3779B97F4A7C15ULL + 0x632BE59BD9B4E019ULL;
  x_m_ = world.start.x_m;
  y_m_ = world.start.y_m;
  yaw_rad_ = world.start.yaw_rad;
  wheel_left_m_s_ = wheel_right_m_s_ = target_left_m_s_ = target_right_m_s_ = 0.0F;
  base_health_ = BaseHealth::kStopped;
  base_error_ = "not started";
  base_started_ = false;
  odometry_ = Odometry{};
  wheel_count_left_m_ = wheel_count_right_m_ = 0.0;
  in_place_turn_ = false;
  turn_scrub_factor_ = 1.0;
  collisions_ = 0;
  contacts_ = 0;
  last_collision_model_ = "";
  pan_ = PtuAxis{};
  tilt_ = PtuAxis{};
  pan_.speed_rad_s = tilt_.speed_rad_s = params_.ptu.speed_rad_s;
  estop_ = estop_scripted_ = false;
  estop_presses_ = 0;
  led_ = false;
  led_changes_ = 0;
  watchdog_armed_ = false;
  watchdog_expirations_ = 0;
  base_last_update_us_ = 0;
  last_base_stop_us_ = 0;
  braking_ = axes_idle_ = false;
  last_rest_us_ = 0;
  behind_since_us_[0] = behind_since_us_[1] = 0;
  pending_head_ = pending_count_ = 0;
  odometry_history_head_ = 0;
  for (Odometry& o : odometry_history_) o = Odometry{};
  odometry_given_us_ = 0;
  rim_travel_m_ = rim_travel_at_rest_m_ = 0.0;
  faults_.reset(params.seed);
  const char* model = "";
  const float gap = clearance_m(x_m_, y_m_, &model);
  if (gap < 0.0F) {
    std::snprintf(error, error_size,
                  "the robot's start (%.2f, %.2f) overlaps model '%s' (robot radius %.2f m)",
                  static_cast<double>(x_m_), static_cast<double>(y_m_), model,
                  static_cast<double>(params_.base.robot_radius_m));
    return false;
  }
  contact_ = gap <= params_.base.contact_margin_m;
  return true;
}

float SimWorld::clearance_m(double x_m, double y_m, const char** model) const {
  const float px = static_cast<float>(x_m);
  const float py = static_cast<float>(y_m);
  float best = std::numeric_limits<float>::infinity();
  for (std::size_t i = 0; i < world_->collider_count; ++i) {
    const Collider& c = world_->colliders[i];
    if (c.z_max_m <= params_.base.floor_clearance_m || c.z_min_m >= params_.base.robot_height_m) {
      continue;
    }
    const float d = c.circle ? std::hypot(px - c.centre_x_m, py - c.centre_y_m) - c.radius_m
                             : distance_to_hull(c, px, py);
    if (d < best) {
      best = d;
      if (model != nullptr) *model = c.model;
    }
  }
  return best - params_.base.robot_radius_m;
}

RigidTransform SimWorld::camera_pose(const core::Pose2& robot, float pan_rad,
                                     float tilt_rad) const {
  const stereo::CameraPose cam = rig_->camera_pose(pan_rad, tilt_rad);
  RigidTransform world_from_ptu;
  const float c = std::cos(robot.yaw_rad);
  const float s = std::sin(robot.yaw_rad);
  world_from_ptu.rotation << c, -s, 0.0F, s, c, 0.0F, 0.0F, 0.0F, 1.0F;
  world_from_ptu.translation_m = Eigen::Vector3f(robot.x_m, robot.y_m, rig_->params().ptu_height_m);
  return world_from_ptu.then(RigidTransform{cam.rotation, cam.centre_m});
}

RigidTransform SimWorld::camera_pose() const {
  const float play = 0.5F * params_.ptu.backlash_rad;
  return camera_pose(true_pose(), pan_.position_rad - play * pan_.last_direction,
                     tilt_.position_rad - play * tilt_.last_direction);
}

bool SimWorld::teleport(const core::Pose2& pose) {
  const float gap = clearance_m(pose.x_m, pose.y_m);
  if (gap < 0.0F) return false;
  x_m_ = pose.x_m;
  y_m_ = pose.y_m;
  yaw_rad_ = pose.yaw_rad;
  contact_ = gap <= params_.base.contact_margin_m;
  return true;
}

void SimWorld::advance_to(std::uint64_t deadline_us) {
  while (now_us_ < deadline_us) {
    const std::uint64_t dt =
        std::min<std::uint64_t>(params_.physics_step_us, deadline_us - now_us_);
    step(static_cast<std::uint32_t>(dt));
  }
}

void SimWorld::step(std::uint32_t dt_us) {
  const float dt_s = static_cast<float>(dt_us) * 1e-6F;
  now_us_ += dt_us;
  if (estop_scripted_) {
    if (!estop_ && now_us_ >= estop_press_us_ && now_us_ < estop_release_us_) {
      set_estop_pressed(true);
    } else if (estop_ && now_us_ >= estop_release_us_) {
      set_estop_pressed(false);
      estop_scripted_ = false;
    }
  }
  faults_.update(now_us_);
  apply_due_setpoints();
  // PTU faults that act on the axes: a move that never ends (stuck), or at a tenth of its
  // speed (slow).
  FaultType ptu_fault = FaultType::kOff;
  const bool ptu_failing = faults_.failing(FaultDevice::kPtu, ptu_fault);
  if (!(ptu_failing && (ptu_fault == FaultType::kStuck || ptu_fault == FaultType::kOff ||
                        ptu_fault == FaultType::kIntermittent))) {
    const float speed_scale = ptu_failing && ptu_fault == FaultType::kSlow ? 0.1F : 1.0F;
    step_axis(pan_, dt_s * speed_scale);
    step_axis(tilt_, dt_s * speed_scale);
  }
  if (base_started_ && base_health_ == BaseHealth::kStarting && now_us_ >= base_ready_at_us_) {
    if (const char* why = base_fault(); why != nullptr) {
      base_stop(why, StopKind::kCoast);  // the start-up fails on an axis that is not there
    } else {
      base_health_ = BaseHealth::kReady;
      base_error_ = "";
    }
  }
  if (params_.base.command_timeout_us != 0 && base_health_ == BaseHealth::kReady &&
      now_us_ - base_last_update_us_ > params_.base.command_timeout_us) {
    // The ODrive's watchdog (WATCHDOG_TIMER_EXPIRED, 0x800): no setpoint came in time, e.g.
    // the executive stalled. The driver then reports the axis error.
    base_stop("base: left axis: ODrive reports an axis error (0x00000800)", StopKind::kCoast);
  }
  if (braking_ &&
      ((wheel_left_m_s_ == 0.0F && wheel_right_m_s_ == 0.0F) || now_us_ >= brake_deadline_us_)) {
    braking_ = false;  // at rest, or the brake time is over: the driver idles the axes
    axes_idle_ = true;
  }
  step_base(dt_s);
  if (watchdog_armed_ && now_us_ - last_kick_us_ > watchdog_timeout_us_) {
    ++watchdog_expirations_;
    last_kick_us_ = now_us_;  // a real board would reset here; count and carry on
  }
}

// Trapezoidal profile: accelerate to the axis speed, brake in time to stop on the target. The
// braking speed is the one to have at the END of this step so that constant deceleration then
// stops exactly on the target (v1² = 2a(e − (v0 + v1)·dt/2)), which keeps the move time exact
// to the step (an explicit sqrt(2ae) would arrive early).
void SimWorld::step_axis(PtuAxis& axis, float dt_s) const {
  if (!axis.moving()) return;
  const float a = params_.ptu.accel_rad_s2;
  const float error = axis.target_rad - axis.position_rad;
  const float remaining =
      std::max(0.0F, std::fabs(error) - 0.5F * std::fabs(axis.velocity_rad_s) * dt_s);
  const float brake_speed =
      std::max(0.0F, 0.5F * (-a * dt_s + std::sqrt(a * a * dt_s * dt_s + 8.0F * a * remaining)));
  const float desired = std::copysign(std::min(axis.speed_rad_s, brake_speed), error);
  const float dv = std::clamp(desired - axis.velocity_rad_s, -a * dt_s, a * dt_s);
  const float v0 = axis.velocity_rad_s;
  axis.velocity_rad_s += dv;
  axis.position_rad += 0.5F * (v0 + axis.velocity_rad_s) * dt_s;
  axis.last_direction = error > 0.0F ? 1.0F : -1.0F;
  const float after = axis.target_rad - axis.position_rad;
  // Arrived (or passed the target): stop on it. Tiny remainders settle at once.
  if ((after > 0.0F) != (error > 0.0F) || after == 0.0F ||
      (std::fabs(after) < 1e-6F && std::fabs(axis.velocity_rad_s) < a * dt_s)) {
    axis.position_rad = axis.target_rad;
    axis.velocity_rad_s = 0.0F;
  }
}

float SimWorld::gaussian() {
  // splitmix64 → Box–Muller (one value per call; deterministic for the seed).
  auto next = [this]() {
    std::uint64_t z = (rng_state_ += 0x9E3779B97F4A7C15ULL);
    z = (z ^ (z >> 30U)) * 0xBF58476D1CE4E5B9ULL;
    z = (z ^ (z >> 27U)) * 0x94D049BB133111EBULL;
    z ^= z >> 31U;
    return (static_cast<double>(z >> 11U) + 0.5) * (1.0 / 9007199254740992.0);
  };
  const double u1 = next();
  const double u2 = next();
  return static_cast<float>(std::sqrt(-2.0 * std::log(u1)) * std::cos(6.283185307179586 * u2));
}

void SimWorld::step_base(float dt_s) {
  const BaseParams& b = params_.base;
  const bool was_moving = wheel_left_m_s_ != 0.0F || wheel_right_m_s_ != 0.0F;
  // Closed loop: towards the setpoint, speeding up at the ramp, slowing at the brake
  // deceleration; idle axes: the wheels coast to rest.
  // A jammed wheel (`axis-* slow`) turns at a tenth of what its motor drives it to.
  const bool jam_left = axis_failing(FaultDevice::kAxisLeft, FaultType::kSlow);
  const bool jam_right = axis_failing(FaultDevice::kAxisRight, FaultType::kSlow);
  const auto follow = [&](float& wheel, float target, bool jammed) {
    if (axes_idle_) target = 0.0F;
    if (jammed) target *= 0.1F;
    const bool slowing = std::fabs(target) < std::fabs(wheel) || target * wheel < 0.0F;
    const float rate = axes_idle_ ? b.coast_decel_m_s2
                       : slowing  ? b.brake_decel_m_s2
                                  : b.wheel_accel_m_s2;
    const float dv = rate * dt_s;
    wheel += std::clamp(target - wheel, -dv, dv);
  };
  follow(wheel_left_m_s_, target_left_m_s_, jam_left);
  follow(wheel_right_m_s_, target_right_m_s_, jam_right);
  // Frozen encoder estimates (`axis-* stuck`): the wheel turns, its encoder counts nothing.
  const bool frozen_left = axis_failing(FaultDevice::kAxisLeft, FaultType::kStuck);
  const bool frozen_right = axis_failing(FaultDevice::kAxisRight, FaultType::kStuck);
  // What the encoders count (the commanded rims at the odometry's diameters) [m].
  const double el = static_cast<double>(wheel_left_m_s_) * static_cast<double>(dt_s);
  const double er = static_cast<double>(wheel_right_m_s_) * static_cast<double>(dt_s);
  const double count_left_before = wheel_count_left_m_;
  const double count_right_before = wheel_count_right_m_;
  wheel_count_left_m_ += el;
  wheel_count_right_m_ += er;
  // Each in-place turn slips by its own random share (scrub on the floor).
  const bool turning = el * er < 0.0;
  if (turning && !in_place_turn_) {
    turn_scrub_factor_ =
        b.turn_scrub > 0.0F ? 1.0 + static_cast<double>(b.turn_scrub * gaussian()) : 1.0;
  }
  in_place_turn_ = turning;
  // What the ground does: the true diameters and track.
  const double dl = el * static_cast<double>(b.wheel_scale_left);
  const double dr = er * static_cast<double>(b.wheel_scale_right);
  rim_travel_m_ += std::max(std::fabs(dl), std::fabs(dr));
  if (was_moving && wheel_left_m_s_ == 0.0F && wheel_right_m_s_ == 0.0F) {
    last_rest_us_ = now_us_;
    rim_travel_at_rest_m_ = rim_travel_m_;
  }
  if (dl != 0.0 || dr != 0.0) {
    // Exact arc of a differential drive over the step.
    const double track = b.track_width_m;
    const double ds = 0.5 * (dl + dr);
    const double dyaw = (dr - dl) / (track * static_cast<double>(b.track_scale)) *
                        (turning ? turn_scrub_factor_ : 1.0);
    const double mid = yaw_rad_ + 0.5 * dyaw;
    const double chord = std::fabs(dyaw) > 1e-9 ? ds * std::sin(0.5 * dyaw) / (0.5 * dyaw) : ds;
    const double nx = x_m_ + chord * std::cos(mid);
    const double ny = y_m_ + chord * std::sin(mid);
    const char* model = "";
    const float gap = clearance_m(nx, ny, &model);
    if (gap < 0.0F) {
      // Collision: the robot stays where it was, the base stops, the event is counted.
      ++collisions_;
      last_collision_model_ = model;
      std::snprintf(collision_error_, sizeof collision_error_, "collision with '%s'", model);
      wheel_count_left_m_ = count_left_before;  // the wheels did not turn either
      wheel_count_right_m_ = count_right_before;
      base_stop(collision_error_, StopKind::kImmediate);
      if (!contact_) ++contacts_;
      contact_ = true;
    } else {
      x_m_ = nx;
      y_m_ = ny;
      yaw_rad_ = std::remainder(yaw_rad_ + dyaw, 6.283185307179586);
      const bool contact = gap <= b.contact_margin_m;
      if (contact && !contact_) ++contacts_;
      contact_ = contact;
      // Wheel odometry from the encoders at the nominal diameters and track (white noise
      // optional).
      double ol = frozen_left ? 0.0 : el * static_cast<double>(b.odometry_left_scale);
      double orr = frozen_right ? 0.0 : er * static_cast<double>(b.odometry_right_scale);
      if (b.odometry_noise > 0.0F) {
        ol *= 1.0 + static_cast<double>(b.odometry_noise * gaussian());
        orr *= 1.0 + static_cast<double>(b.odometry_noise * gaussian());
      }
      const double ods = 0.5 * (ol + orr);
      const double odyaw = (orr - ol) / (track * static_cast<double>(b.odometry_track_scale));
      const double omid = odometry_.yaw_rad + 0.5 * odyaw;
      const double ochord =
          std::fabs(odyaw) > 1e-9 ? ods * std::sin(0.5 * odyaw) / (0.5 * odyaw) : ods;
      odometry_.x_m += ochord * std::cos(omid);
      odometry_.y_m += ochord * std::sin(omid);
      odometry_.yaw_rad = std::remainder(odometry_.yaw_rad + odyaw, 6.283185307179586);
    }
  }
  const float ml = frozen_left ? 0.0F : wheel_left_m_s_ * b.odometry_left_scale;
  const float mr = frozen_right ? 0.0F : wheel_right_m_s_ * b.odometry_right_scale;
  odometry_.v_m_s = 0.5F * (ml + mr);
  odometry_.omega_rad_s = (mr - ml) / (b.track_width_m * b.odometry_track_scale);
  odometry_.timestamp_us = now_us_;
  odometry_.wheels_known = true;
  odometry_.wheel_left_m = wheel_count_left_m_;
  odometry_.wheel_right_m = wheel_count_right_m_;
  odometry_history_head_ = (odometry_history_head_ + 1) % kOdometryHistory;
  odometry_history_[odometry_history_head_] = odometry_;
}

SimWorld::PhysicalState SimWorld::physical_state() const {
  PhysicalState s;
  s.x_m = x_m_;
  s.y_m = y_m_;
  s.yaw_rad = yaw_rad_;
  s.wheel_left_m = wheel_count_left_m_;
  s.wheel_right_m = wheel_count_right_m_;
  s.wheel_left_m_s = wheel_left_m_s_;
  s.wheel_right_m_s = wheel_right_m_s_;
  return s;
}

bool SimWorld::restore_physical_state(const PhysicalState& state) {
  if (!std::isfinite(state.x_m) || !std::isfinite(state.y_m) || !std::isfinite(state.yaw_rad) ||
      !std::isfinite(state.wheel_left_m) || !std::isfinite(state.wheel_right_m) ||
      !std::isfinite(state.wheel_left_m_s) || !std::isfinite(state.wheel_right_m_s)) {
    return false;
  }
  if (!teleport({static_cast<float>(state.x_m), static_cast<float>(state.y_m),
                 static_cast<float>(state.yaw_rad)})) {
    return false;
  }
  x_m_ = state.x_m;  // teleport() kept floats: the double pose exactly
  y_m_ = state.y_m;
  yaw_rad_ = state.yaw_rad;
  wheel_count_left_m_ = state.wheel_left_m;
  wheel_count_right_m_ = state.wheel_right_m;
  const float limit = params_.base.max_speed_m_s +
                      0.5F * params_.base.max_turn_rate_rad_s * params_.base.track_width_m;
  wheel_left_m_s_ = target_left_m_s_ = std::clamp(state.wheel_left_m_s, -limit, limit);
  wheel_right_m_s_ = target_right_m_s_ = std::clamp(state.wheel_right_m_s, -limit, limit);
  if (wheel_left_m_s_ != 0.0F || wheel_right_m_s_ != 0.0F) {
    // The axes are still in closed loop on the last setpoint; their watchdog ends that, and
    // the wheels coast to rest with the axes idle.
    base_health_ = BaseHealth::kReady;
    base_error_ = "";
    base_last_update_us_ = now_us_;
    braking_ = axes_idle_ = false;
  }
  odometry_.wheels_known = true;
  odometry_.wheel_left_m = wheel_count_left_m_;
  odometry_.wheel_right_m = wheel_count_right_m_;
  return true;
}

void SimWorld::base_start() {
  base_started_ = true;
  base_health_ = BaseHealth::kStarting;
  base_error_ = "starting";
  base_ready_at_us_ = now_us_ + params_.base.startup_us;
  base_last_update_us_ = now_us_;
  braking_ = axes_idle_ = false;
  odometry_origin_ = true_pose();
  odometry_ = Odometry{};
  odometry_.timestamp_us = now_us_;
  // The controllers' counters are theirs: a new firmware's base start does not reset them.
  odometry_.wheels_known = true;
  odometry_.wheel_left_m = wheel_count_left_m_;
  odometry_.wheel_right_m = wheel_count_right_m_;
  for (Odometry& o : odometry_history_) o = odometry_;  // a new frame: no past in it
  odometry_given_us_ = 0;
  behind_since_us_[0] = behind_since_us_[1] = 0;
  pending_count_ = 0;
}

const char* SimWorld::base_fault() const {
  FaultType type = FaultType::kOff;
  if (faults_.failing(FaultDevice::kCan, type) && type != FaultType::kDelayed) {
    return "base: CAN bus-off (controller stopped transmitting)";
  }
  for (const FaultDevice d : {FaultDevice::kAxisLeft, FaultDevice::kAxisRight}) {
    // A frozen encoder or a jammed wheel leaves the axis up: the driver sees them only by
    // the wheel not following its setpoint (check_wheels_follow()).
    if (!faults_.failing(d, type) || type == FaultType::kStuck || type == FaultType::kSlow) {
      continue;
    }
    const bool left = d == FaultDevice::kAxisLeft;
    if (type == FaultType::kWrong) {
      // MOTOR_FAILED in the heartbeat's axis error.
      return left ? "base: left axis: ODrive reports an axis error (0x00000040)"
                  : "base: right axis: ODrive reports an axis error (0x00000040)";
    }
    return left ? "base: left axis: heartbeat lost (0x00000000)"
                : "base: right axis: heartbeat lost (0x00000000)";
  }
  return nullptr;
}

void SimWorld::base_update() {
  base_last_update_us_ = now_us_;
  // A brake under way is turned into an idle by an axis or bus fault, as the driver does.
  if (base_health_ == BaseHealth::kStopped && !braking_) return;
  const char* why = base_fault();
  if (why == nullptr) {
    if (base_health_ == BaseHealth::kReady) check_wheels_follow();
    return;
  }
  std::snprintf(base_fault_error_, sizeof base_fault_error_, "%s", why);
  base_stop(base_fault_error_, StopKind::kCoast);
}

bool SimWorld::axis_failing(FaultDevice device, FaultType type) const {
  FaultType active = FaultType::kOff;
  return faults_.failing(device, active) && active == type;
}

// As the driver's wheel_behind(): a wheel whose measured speed (what its encoder says) stays
// below follow_ratio of its setpoint for follow_timeout_us stops the base, the axes idled.
void SimWorld::check_wheels_follow() {
  const BaseParams& b = params_.base;
  const float measured[2] = {
      axis_failing(FaultDevice::kAxisLeft, FaultType::kStuck) ? 0.0F : wheel_left_m_s_,
      axis_failing(FaultDevice::kAxisRight, FaultType::kStuck) ? 0.0F : wheel_right_m_s_};
  const float setpoint[2] = {target_left_m_s_, target_right_m_s_};
  for (int k = 0; k < 2; ++k) {
    const float want = std::fabs(setpoint[k]);
    const float got = std::copysign(1.0F, setpoint[k]) * measured[k];
    if (want < b.follow_min_m_s || got >= b.follow_ratio * want) {
      behind_since_us_[k] = 0;
      continue;
    }
    if (behind_since_us_[k] == 0) behind_since_us_[k] = now_us_;
    if (now_us_ - behind_since_us_[k] > b.follow_timeout_us) {
      base_stop(k == 0 ? "base: left axis: wheel not following its setpoint (0x00000000)"
                       : "base: right axis: wheel not following its setpoint (0x00000000)",
                StopKind::kCoast);
      return;
    }
  }
}

// Setpoints that have crossed a delayed bus take effect (all at once when it is not delayed).
void SimWorld::apply_due_setpoints() {
  while (pending_count_ > 0 && pending_[pending_head_].due_us <= now_us_) {
    const PendingSetpoint& p = pending_[pending_head_];
    if (base_health_ == BaseHealth::kReady) {
      target_left_m_s_ = p.left_m_s;
      target_right_m_s_ = p.right_m_s;
    }
    pending_head_ = (pending_head_ + 1) % kPendingSetpoints;
    --pending_count_;
  }
}

Odometry SimWorld::odometry() const {
  FaultType type = FaultType::kOff;
  if (!faults_.failing(FaultDevice::kCan, type) || type != FaultType::kDelayed) {
    odometry_given_us_ = odometry_.timestamp_us;
    return odometry_;
  }
  // The newest sample at least can_delay_us old, never older than one already handed out (a
  // late estimate does not take the odometry back in time).
  const std::uint64_t want_us = std::max(
      odometry_given_us_,
      now_us_ > params_.base.can_delay_us ? now_us_ - params_.base.can_delay_us : std::uint64_t{0});
  std::size_t i = odometry_history_head_;
  for (std::size_t n = 0; n + 1 < kOdometryHistory; ++n) {
    if (odometry_history_[i].timestamp_us <= want_us) break;
    i = (i + kOdometryHistory - 1) % kOdometryHistory;
  }
  odometry_given_us_ = odometry_history_[i].timestamp_us;
  return odometry_history_[i];
}

void SimWorld::base_set_velocity(float v_m_s, float omega_rad_s) {
  if (base_health_ != BaseHealth::kReady || !std::isfinite(v_m_s) || !std::isfinite(omega_rad_s)) {
    return;
  }
  const BaseParams& b = params_.base;
  const float v = std::clamp(v_m_s, -b.max_speed_m_s, b.max_speed_m_s);
  const float w = std::clamp(omega_rad_s, -b.max_turn_rate_rad_s, b.max_turn_rate_rad_s);
  // Encoder speeds [m/s at the nominal radius] for the calibrated wheels and track.
  const float track = b.track_width_m * b.odometry_track_scale;
  const float left = (v - 0.5F * w * track) / b.odometry_left_scale;
  const float right = (v + 0.5F * w * track) / b.odometry_right_scale;
  FaultType type = FaultType::kOff;
  const bool delayed = faults_.failing(FaultDevice::kCan, type) && type == FaultType::kDelayed;
  if (!delayed && pending_count_ == 0) {
    target_left_m_s_ = left;
    target_right_m_s_ = right;
    return;
  }
  // Over a delayed bus (or behind setpoints still on their way): in order, can_delay_us late.
  if (pending_count_ == kPendingSetpoints) {  // full: the oldest arrives now
    target_left_m_s_ = pending_[pending_head_].left_m_s;
    target_right_m_s_ = pending_[pending_head_].right_m_s;
    pending_head_ = (pending_head_ + 1) % kPendingSetpoints;
    --pending_count_;
  }
  PendingSetpoint& p = pending_[(pending_head_ + pending_count_) % kPendingSetpoints];
  p.due_us = now_us_ + (delayed ? params_.base.can_delay_us : 0U);
  p.left_m_s = left;
  p.right_m_s = right;
  ++pending_count_;
}

void SimWorld::base_stop(const char* reason, StopKind kind) {
  const bool was_running = base_health_ != BaseHealth::kStopped;
  if (was_running) last_base_stop_us_ = now_us_;
  target_left_m_s_ = target_right_m_s_ = 0.0F;
  pending_count_ = 0;  // setpoints still on their way are dropped (the sim does not delay a stop)
  if (kind == StopKind::kImmediate) {
    if (wheel_left_m_s_ != 0.0F || wheel_right_m_s_ != 0.0F) {
      last_rest_us_ = now_us_;
      rim_travel_at_rest_m_ = rim_travel_m_;
    }
    wheel_left_m_s_ = wheel_right_m_s_ = 0.0F;
    braking_ = false;
    axes_idle_ = true;
  } else if (kind == StopKind::kCoast) {
    braking_ = false;
    axes_idle_ = true;
  } else if (was_running && base_health_ == BaseHealth::kReady) {
    braking_ = true;  // the wheels slow in closed loop (step_base), then the axes idle
    brake_deadline_us_ = now_us_ + params_.base.brake_timeout_us;
  } else if (was_running) {
    axes_idle_ = true;  // stopped while starting: nothing to brake
  }
  base_health_ = BaseHealth::kStopped;
  base_error_ = reason;
}

bool SimWorld::base_resume() {
  if (!base_started_) return false;
  if (base_fault() != nullptr) return false;  // the axis or the bus is still gone
  if (base_health_ == BaseHealth::kStopped) {
    braking_ = axes_idle_ = false;  // closed loop again (from the wheels' speed now)
    behind_since_us_[0] = behind_since_us_[1] = 0;
    base_health_ = now_us_ >= base_ready_at_us_ ? BaseHealth::kReady : BaseHealth::kStarting;
    base_error_ = base_health_ == BaseHealth::kReady ? "" : "starting";
  }
  return true;
}

void SimWorld::set_estop_pressed(bool pressed) {
  if (pressed && !estop_) ++estop_presses_;
  estop_ = pressed;
}

void SimWorld::schedule_estop(std::uint64_t press_us, std::uint64_t duration_us) {
  estop_scripted_ = true;
  estop_press_us_ = press_us;
  estop_release_us_ = press_us + std::max<std::uint64_t>(duration_us, 1);
}

void SimWorld::set_led(bool on) {
  if (on != led_) ++led_changes_;
  led_ = on;
}

void SimWorld::watchdog_start(std::uint32_t timeout_ms) {
  watchdog_armed_ = true;
  watchdog_timeout_us_ = static_cast<std::uint64_t>(timeout_ms) * 1000U;
  last_kick_us_ = now_us_;
}

}  // namespace boticelli::hal::sim
