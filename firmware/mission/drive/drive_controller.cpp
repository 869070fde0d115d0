// DriveController: turn in place, then straight with heading correction (see drive_controller.h).
#include "firmware/mission/drive/drive_controller.h"

#include <algorithm>
#include <cmath>

#include "algo/core/angles.h"

namespace boticelli::firmware::mission {

void DriveController::start(const core::Pose2& from, core::Point2 end, std::uint64_t now_us) {
  start_ = {from.x_m, from.y_m};
  end_ = end;
  heading_rad_ = std::atan2(end.y_m - from.y_m, end.x_m - from.x_m);
  const float distance = core::distance_m(start_, end_);
  const float turn = std::fabs(core::wrap_pi(heading_rad_ - from.yaw_rad));
  // Nominal time: the turn and the leg at their limits, plus ramps; then the margin.
  const float nominal_s = turn / params_.max_turn_rate_rad_s + distance / params_.max_speed_m_s +
                          2.0F * params_.max_speed_m_s / params_.accel_m_s2 + 1.0F;
  deadline_us_ = now_us + static_cast<std::uint64_t>(nominal_s * params_.timeout_factor * 1e6F);
  failure_ = "";
  after_stop_ = DriveStatus::kDone;
  // Within the tolerance it is done, as the leg is (`update`): at exactly the tolerance too.
  status_ = distance <= params_.position_tolerance_m ? DriveStatus::kDone : DriveStatus::kTurning;
}

void DriveController::start_turn(const core::Pose2& from, float heading_rad, std::uint64_t now_us) {
  start_ = {from.x_m, from.y_m};
  end_ = start_;  // the leg after the turn is already at its end: it stops at once
  heading_rad_ = heading_rad;
  const float turn = std::fabs(core::wrap_pi(heading_rad_ - from.yaw_rad));
  const float nominal_s = turn / params_.max_turn_rate_rad_s + 1.0F;
  deadline_us_ = now_us + static_cast<std::uint64_t>(nominal_s * params_.timeout_factor * 1e6F);
  failure_ = "";
  after_stop_ = DriveStatus::kDone;
  status_ = DriveStatus::kTurning;
}

void DriveController::abort(const char* why) {
  if (busy()) {
    failure_ = why;
    after_stop_ = DriveStatus::kFailed;
    status_ = DriveStatus::kStopping;
  }
}

DriveCommand DriveController::update(const core::Pose2& odometry, float v_m_s, float omega_rad_s,
                                     std::uint64_t now_us) {
  DriveCommand cmd;
  if (busy() && status_ != DriveStatus::kStopping && now_us > deadline_us_) {
    abort("step timed out");
  }
  const core::Point2 here{odometry.x_m, odometry.y_m};
  switch (status_) {
    case DriveStatus::kTurning: {
      const float error = core::wrap_pi(heading_rad_ - odometry.yaw_rad);
      if (std::fabs(error) <= params_.heading_tolerance_rad &&
          std::fabs(omega_rad_s) <= params_.settle_rate_rad_s * 10.0F) {
        status_ = DriveStatus::kDriving;
        break;  // the leg starts next period from rest
      }
      float rate = params_.turn_gain_per_s * error;
      if (std::fabs(rate) < params_.min_turn_rate_rad_s) {
        rate = std::copysign(params_.min_turn_rate_rad_s, error);
      }
      cmd.omega_rad_s = std::clamp(rate, -params_.max_turn_rate_rad_s, params_.max_turn_rate_rad_s);
      break;
    }
    case DriveStatus::kDriving: {
      const float ux = std::cos(heading_rad_);
      const float uy = std::sin(heading_rad_);
      const float dx = end_.x_m - here.x_m;
      const float dy = end_.y_m - here.y_m;
      const float along = ux * dx + uy * dy;  // still to go along the line
      // Off the checked line: from the start, the signed distance to the line.
      const float cross = -uy * (here.x_m - start_.x_m) + ux * (here.y_m - start_.y_m);
      if (std::fabs(cross) > params_.max_cross_track_m) {
        abort("left the step's line");
        break;
      }
      if (along <= params_.position_tolerance_m) {
        after_stop_ = DriveStatus::kDone;
        status_ = DriveStatus::kStopping;
        break;
      }
      cmd.v_m_s = std::min(params_.max_speed_m_s, std::sqrt(2.0F * params_.accel_m_s2 * along));
      // Steer back onto the line (and towards the end) while driving.
      const float bearing = std::atan2(dy, dx);
      const float error = along > 0.05F ? core::wrap_pi(bearing - odometry.yaw_rad)
                                        : core::wrap_pi(heading_rad_ - odometry.yaw_rad);
      cmd.omega_rad_s = std::clamp(params_.turn_gain_per_s * error, -params_.max_turn_rate_rad_s,
                                   params_.max_turn_rate_rad_s);
      break;
    }
    case DriveStatus::kStopping:
      if (std::fabs(v_m_s) <= params_.settle_speed_m_s &&
          std::fabs(omega_rad_s) <= params_.settle_rate_rad_s) {
        status_ = after_stop_;
      }
      break;
    case DriveStatus::kIdle:
    case DriveStatus::kDone:
    case DriveStatus::kFailed:
      break;
  }
  return cmd;
}

}  // namespace boticelli::firmware::mission
