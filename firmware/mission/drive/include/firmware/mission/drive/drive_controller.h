// DriveController: one step of the mission's Drive stage — turn in place, then drive straight,
// closed loop on odometry.
#pragma once

#include <cstdint>

#include "algo/core/geometry.h"

namespace boticelli::firmware::mission {

struct DriveParams {
  float max_speed_m_s = 0.3F;           // forward speed limit (board) [m/s]
  float max_turn_rate_rad_s = 0.8F;     // yaw rate limit (board) [rad/s]
  float accel_m_s2 = 0.4F;              // planned deceleration before the end [m/s²]
  float turn_gain_per_s = 2.5F;         // yaw rate per rad of heading error [1/s]
  float min_turn_rate_rad_s = 0.08F;    // below this the base barely turns (static friction)
  float heading_tolerance_rad = 0.03F;  // turn done within this
  float position_tolerance_m = 0.015F;  // straight leg done within this of the end
  // The straight leg is abandoned (stop, report) when the robot is this far off the line
  // from the start to the end of the step: the step was checked against the navigation
  // polygon along that line only.
  float max_cross_track_m = 0.06F;
  float settle_speed_m_s = 0.01F;   // stopped: |v| below this ...
  float settle_rate_rad_s = 0.02F;  // ... and |ω| below this
  float timeout_factor = 3.0F;      // a step taking this many times its nominal time fails
};

enum class DriveStatus : std::uint8_t { kIdle, kTurning, kDriving, kStopping, kDone, kFailed };

struct DriveCommand {
  float v_m_s = 0.0F;
  float omega_rad_s = 0.0F;
};

// Drives from the pose at start() to `end` (odometry frame): first turns in place to face it,
// then goes straight while correcting its heading towards it, then stops and waits until the
// base has come to rest. Pure logic: update() takes the odometry and returns the setpoint.
class DriveController {
 public:
  void configure(const DriveParams& params) { params_ = params; }
  [[nodiscard]] const DriveParams& params() const { return params_; }

  void start(const core::Pose2& from, core::Point2 end, std::uint64_t now_us);
  // Turns in place to `heading_rad` (odometry frame) and stops there: no straight leg.
  void start_turn(const core::Pose2& from, float heading_rad, std::uint64_t now_us);
  // One control period; the base must get the returned setpoint.
  DriveCommand update(const core::Pose2& odometry, float v_m_s, float omega_rad_s,
                      std::uint64_t now_us);
  // Stops where it is (the setpoint becomes 0 and the status kFailed with `why`).
  void abort(const char* why);
  void reset() { status_ = DriveStatus::kIdle; }

  [[nodiscard]] DriveStatus status() const { return status_; }
  [[nodiscard]] bool busy() const {
    return status_ == DriveStatus::kTurning || status_ == DriveStatus::kDriving ||
           status_ == DriveStatus::kStopping;
  }
  [[nodiscard]] const char* failure() const { return failure_; }

 private:
  DriveParams params_{};
  DriveStatus status_ = DriveStatus::kIdle;
  DriveStatus after_stop_ = DriveStatus::kDone;
  core::Point2 start_{};
  core::Point2 end_{};
  float heading_rad_ = 0.0F;
  std::uint64_t deadline_us_ = 0;
  const char* failure_ = "";
};

}  // namespace boticelli::firmware::mission
