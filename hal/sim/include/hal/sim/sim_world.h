// SimWorld: simulated time and physics (robot base, PTU, contacts, e-stop) and the ground truth.
#pragma once

#include <Eigen/Core>
#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>

#include "algo/core/geometry.h"
#include "algo/stereo/rig.h"
#include "hal/base.h"
#include "hal/pan_tilt.h"
#include "hal/sim/fault_injector.h"
#include "hal/sim/world.h"

namespace boticelli::hal::sim {

// PTU-D46-like axis behaviour (defaults: the D46's limits and its 185.1428" resolution).
struct PtuParams {
  PanTiltLimits limits{-2.7751F, 2.7751F, -0.8203F, 0.5411F, 8.9759e-4F, 8.9759e-4F};
  float speed_rad_s = 1.0F;      // default speed of both axes
  float max_speed_rad_s = 2.6F;  // fastest set_speed() accepted
  float accel_rad_s2 = 4.0F;     // acceleration and deceleration of both axes
  // Gear play of both axes: the camera trails the axis's position by half of it, on the side
  // the axis last moved from (nothing before the first move) [rad].
  float backlash_rad = 0.0F;
};

struct BaseParams {
  float robot_radius_m = 0.25F;
  float robot_height_m = 0.8F;
  float track_width_m = 0.40F;
  float max_speed_m_s = 0.3F;
  float max_turn_rate_rad_s = 0.8F;
  float wheel_accel_m_s2 = 1.0F;  // velocity ramp at the wheel rim (ODrive vel_ramp)
  // Stopping, as the ODrives do it. In closed loop a wheel slows at brake_decel_m_s2 (the
  // velocity controller braking at its current limit); with the axes idle (Estop, an axis
  // error, a lost heartbeat, the ODrives' watchdog) the motors coast and only rolling
  // friction slows the wheels, at coast_decel_m_s2. A controlled stop (stop()) idles the axes
  // once the wheels are at rest or after brake_timeout_us (the driver's brake_timeout_ms).
  float brake_decel_m_s2 = 1.0F;
  float coast_decel_m_s2 = 0.2F;
  std::uint32_t brake_timeout_us = 500000;
  // The driver's check of a wheel against its setpoint (BaseOdriveCanConfig follow_*): a
  // measured speed below follow_ratio of a setpoint of at least follow_min_m_s for
  // follow_timeout_us stops the base, the axes idled.
  std::uint32_t follow_timeout_us = 1000000;
  float follow_min_m_s = 0.05F;
  float follow_ratio = 0.25F;
  // `can delayed`: every setpoint reaches the axes, and every encoder estimate the firmware,
  // this late [µs].
  std::uint32_t can_delay_us = 50000;
  // Odometry errors of a real base (Borenstein & Feng 1996, UMBmark): what the wheels do
  // against what the odometry assumes. The encoders count the commanded wheel turns; the
  // ground moves by the true diameters and track. 1, 1, 1, 0, 0 is perfect odometry.
  float wheel_scale_left = 1.0F;   // true left wheel diameter / the odometry's
  float wheel_scale_right = 1.0F;  // true right wheel diameter / the odometry's
  float track_scale = 1.0F;        // true effective track width / the odometry's
  float turn_scrub = 0.0F;         // sd of the share of each in-place turn lost or gained [1]
  float odometry_noise = 0.0F;     // relative sd of each wheel's step distance (0 = off)
  // The odometry's calibration, as the firmware configures its HAL (BoardConfig
  // odometry_*): wheel setpoints and odometry use each wheel's effective radius over the
  // nominal one and this share of the track. 1, 1, 1 is the nominal base.
  float odometry_left_scale = 1.0F;
  float odometry_right_scale = 1.0F;
  float odometry_track_scale = 1.0F;
  std::uint32_t startup_us = 50000;  // start-up until closed-loop control [µs]
  float contact_margin_m = 0.01F;    // the bumper closes within this gap [m]
  float floor_clearance_m = 0.01F;   // obstacles lower than this are driven over [m]
  // The ODrives' own watchdog: without a setpoint (BaseSim::update) for this long the axes
  // stop with an error, as on the robot [µs]; 0 = off (device tests that never update()).
  std::uint32_t command_timeout_us = 0;
};

struct SimParams {
  PtuParams ptu{};
  BaseParams base{};
  std::uint32_t physics_step_us = 1000;  // integration step [µs]
  std::uint64_t seed = 1;                // odometry noise (the camera has its own seed)
};

// One PTU axis: trapezoidal motion to a quantised target.
struct PtuAxis {
  float position_rad = 0.0F;
  float velocity_rad_s = 0.0F;
  float target_rad = 0.0F;
  float speed_rad_s = 1.0F;
  float last_direction = 0.0F;  // sign of the last motion: +1, −1, 0 before any
  bool moving() const { return position_rad != target_rad || velocity_rad_s != 0.0F; }
};

class SimWorld {
 public:
  // Places the robot at the world's start pose; false (with the reason) when the start pose
  // collides. `world` and `rig` must outlive this object. Does not allocate.
  bool init(const World& world, const stereo::RigModel& rig, const SimParams& params, char* error,
            std::size_t error_size);

  // ---- time ----
  std::uint64_t now_us() const { return now_us_; }
  // Steps the physics (PTU, base, contacts, scripted e-stop, watchdog) up to `deadline_us`.
  void advance_to(std::uint64_t deadline_us);

  // ---- ground truth (sim-only; the firmware sees none of this) ----
  const World& world() const { return *world_; }
  const SimParams& params() const { return params_; }
  const stereo::RigModel& rig() const { return *rig_; }
  core::Pose2 true_pose() const {
    return {static_cast<float>(x_m_), static_cast<float>(y_m_), static_cast<float>(yaw_rad_)};
  }
  std::uint32_t collisions() const { return collisions_; }
  const char* last_collision_model() const { return last_collision_model_; }
  bool in_contact() const { return contact_; }
  Eigen::Vector3f target_point_m() const { return world_->target_point_m; }
  // Camera pose in the world for the PTU's current (true) pan and tilt: its axes' positions
  // less half the backlash on the side each last moved from.
  RigidTransform camera_pose() const;
  // Camera pose for a robot pose and PTU angles (the same kinematics, for tests).
  RigidTransform camera_pose(const core::Pose2& robot, float pan_rad, float tilt_rad) const;
  // Moves the robot (tests only); false and unchanged when it would collide.
  bool teleport(const core::Pose2& pose);
  // Distance from the robot's cylinder to the nearest obstacle it can hit [m] (< 0: overlap).
  float clearance_m(double x_m, double y_m, const char** model = nullptr) const;

  // ---- injected faults (FaultInjector; the devices consult it) ----
  FaultInjector& faults() { return faults_; }
  const FaultInjector& faults() const { return faults_; }

  // ---- base (driven through BaseSim) ----
  void base_start();
  // The base's service call each frame: a setpoint for the ODrives' watchdog, and the
  // injected axis and CAN faults, which stop the base as the ODrive driver does.
  void base_update();
  void base_set_velocity(float v_m_s, float omega_rad_s);
  // How a stop acts on the wheels: braked in closed loop (a requested stop), the axes idled
  // so that the wheels coast (faults that leave no closed loop), or at once (a collision).
  enum class StopKind : std::uint8_t { kBrake, kCoast, kImmediate };
  void base_stop(const char* reason, StopKind kind);
  bool base_resume();
  BaseHealth base_health() const { return base_health_; }
  // When the base last went from moving or ready to stopped (any cause) [µs]; 0 never.
  std::uint64_t last_base_stop_us() const { return last_base_stop_us_; }
  // The wheels: a controlled stop braking them, the axes idle (coasting), the faster wheel's
  // speed [m/s], when they last came to rest [µs] and the ground the faster wheel has covered
  // in all (true, not the odometry's) [m], also at that rest.
  bool base_braking() const { return braking_; }
  bool base_axes_idle() const { return axes_idle_; }
  float wheel_speed_m_s() const {
    return std::max(std::fabs(wheel_left_m_s_), std::fabs(wheel_right_m_s_));
  }
  std::uint64_t last_base_rest_us() const { return last_rest_us_; }
  double rim_travel_m() const { return rim_travel_m_; }
  double rim_travel_at_rest_m() const { return rim_travel_at_rest_m_; }
  const char* base_error() const { return base_error_; }
  // The odometry as the firmware has it (with `can delayed`, can_delay_us old).
  Odometry odometry() const;
  // The true pose at which the odometry frame was fixed (the last base start).
  core::Pose2 odometry_origin() const { return odometry_origin_; }

  // ---- the world outliving the firmware (the sim board keeps it in a file of its own) ----
  // What of the simulated robot a dead firmware leaves behind: where it stands, how fast its
  // wheels turn, and what the motor controllers' wheel counters read.
  struct PhysicalState {
    double x_m = 0.0, y_m = 0.0, yaw_rad = 0.0;      // true pose in the world
    double wheel_left_m = 0.0, wheel_right_m = 0.0;  // the controllers' wheel counters
    float wheel_left_m_s = 0.0F, wheel_right_m_s = 0.0F;
  };
  PhysicalState physical_state() const;
  // Puts the robot back as a dead firmware left it (before the next one starts its base):
  // wheels still turning roll on with nobody commanding them, until the ODrives' watchdog
  // (BaseParams::command_timeout_us) stops them. False, unchanged, when the pose collides.
  bool restore_physical_state(const PhysicalState& state);

  // ---- PTU (driven through PanTiltSim) ----
  PtuAxis& pan() { return pan_; }
  PtuAxis& tilt() { return tilt_; }
  const PtuAxis& pan() const { return pan_; }
  const PtuAxis& tilt() const { return tilt_; }

  // ---- GPIO ----
  void set_estop_pressed(bool pressed);
  // Presses the e-stop at `press_us` for `duration_us` of simulated time (one pending script).
  void schedule_estop(std::uint64_t press_us, std::uint64_t duration_us);
  bool estop_pressed() const { return estop_; }
  std::uint32_t estop_presses() const { return estop_presses_; }
  std::uint32_t contacts() const { return contacts_; }  // bumper closures so far
  void set_led(bool on);
  bool led() const { return led_; }
  std::uint32_t led_changes() const { return led_changes_; }

  // ---- watchdog stand-in ----
  void watchdog_start(std::uint32_t timeout_ms);
  void watchdog_kick() { last_kick_us_ = now_us_; }
  void watchdog_stop() { watchdog_armed_ = false; }
  std::uint32_t watchdog_expirations() const { return watchdog_expirations_; }

  // ---- the simulator's own work ----
  // Host CPU time [ns] the simulator spent on the board's behalf inside device calls the
  // firmware times (the camera's ray-casting): the board's host clock leaves it out, so the
  // firmware's CPU figures are its own work.
  void add_simulator_cpu_ns(std::uint64_t ns) { simulator_cpu_ns_ += ns; }
  std::uint64_t simulator_cpu_ns() const { return simulator_cpu_ns_; }
  // The same work's host wall time [ns] (CLOCK_MONOTONIC): on a robot the camera exposes and
  // hands over its frames beside the firmware, so the board's host clock leaves this out of
  // the firmware's wall time too (its deadlines and wall figures). Never decreases.
  void add_simulator_wall_ns(std::uint64_t ns) { simulator_wall_ns_ += ns; }
  std::uint64_t simulator_wall_ns() const { return simulator_wall_ns_; }

 private:
  void step(std::uint32_t dt_us);
  void step_axis(PtuAxis& axis, float dt_s) const;
  void step_base(float dt_s);
  float gaussian();

  const World* world_ = nullptr;
  const stereo::RigModel* rig_ = nullptr;
  SimParams params_{};
  std::uint64_t now_us_ = 0;
  std::uint64_t rng_state_ = 0;
  // Robot (true pose, double so long runs do not drift by rounding).
  double x_m_ = 0.0, y_m_ = 0.0, yaw_rad_ = 0.0;
  float wheel_left_m_s_ = 0.0F, wheel_right_m_s_ = 0.0F;
  // The in-place turn under way (wheels in opposite directions) and its scrub factor.
  // The motor controllers' wheel counters (the encoders at the odometry's diameters) [m].
  double wheel_count_left_m_ = 0.0, wheel_count_right_m_ = 0.0;
  bool in_place_turn_ = false;
  double turn_scrub_factor_ = 1.0;
  float target_left_m_s_ = 0.0F, target_right_m_s_ = 0.0F;
  BaseHealth base_health_ = BaseHealth::kStopped;
  const char* base_error_ = "not started";
  std::uint64_t base_ready_at_us_ = 0;
  bool base_started_ = false;
  std::uint64_t base_last_update_us_ = 0;
  std::uint64_t last_base_stop_us_ = 0;
  bool braking_ = false;
  bool axes_idle_ = false;
  std::uint64_t brake_deadline_us_ = 0;
  std::uint64_t last_rest_us_ = 0;
  std::uint64_t behind_since_us_[2] = {0, 0};  // a wheel behind its setpoint since (0: not)
  // Setpoints on their way over a delayed bus, and the odometry's recent past (one sample
  // per physics step) for estimates that arrive late.
  struct PendingSetpoint {
    std::uint64_t due_us = 0;
    float left_m_s = 0.0F, right_m_s = 0.0F;
  };
  static constexpr std::size_t kPendingSetpoints = 32;
  PendingSetpoint pending_[kPendingSetpoints] = {};
  std::size_t pending_head_ = 0, pending_count_ = 0;
  static constexpr std::size_t kOdometryHistory = 128;
  Odometry odometry_history_[kOdometryHistory] = {};
  std::size_t odometry_history_head_ = 0;
  mutable std::uint64_t odometry_given_us_ = 0;  // the newest sample handed out
  bool axis_failing(FaultDevice device, FaultType type) const;
  void apply_due_setpoints();
  void check_wheels_follow();
  double rim_travel_m_ = 0.0;
  double rim_travel_at_rest_m_ = 0.0;
  char base_fault_error_[96] = {};
  Odometry odometry_{};
  core::Pose2 odometry_origin_{};
  std::uint32_t collisions_ = 0;
  const char* last_collision_model_ = "";
  char collision_error_[96] = {};
  bool contact_ = false;
  std::uint32_t contacts_ = 0;
  // PTU.
  PtuAxis pan_{};
  PtuAxis tilt_{};
  // GPIO.
  bool estop_ = false;
  std::uint32_t estop_presses_ = 0;
  bool estop_scripted_ = false;
  std::uint64_t estop_press_us_ = 0, estop_release_us_ = 0;
  bool led_ = false;
  std::uint32_t led_changes_ = 0;
  // Watchdog.
  bool watchdog_armed_ = false;
  std::uint64_t watchdog_timeout_us_ = 0, last_kick_us_ = 0;
  std::uint32_t watchdog_expirations_ = 0;
  // Faults.
  FaultInjector faults_;
  // Why the base cannot leave kStopped now (an axis or CAN fault is active), or nullptr.
  const char* base_fault() const;
  std::uint64_t simulator_cpu_ns_ = 0;
  std::uint64_t simulator_wall_ns_ = 0;
};

}  // namespace boticelli::hal::sim
