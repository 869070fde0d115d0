// BoardConfig: the declarative description of the robot a board drives (dimensions, camera,
// look, timing); the board's values override these defaults, a configuration file overrides both.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>

namespace boticelli::firmware {

// Declarative description of the robot a board drives. Values are the board's own (see
// boards/<board>/board_config.cpp); units are in the names. The thesis's reference robot
// (§3.4, App. A): 640x480 camera averaged to 160x120 with F = 150 px there, L = 21 cm,
// tilt step Φ = 7.7°.
struct BoardConfig {
  // Camera at full resolution (what the driver delivers).
  std::uint32_t camera_width_px = 640;
  std::uint32_t camera_height_px = 480;
  float focal_px = 600.0F;        // focal length at full resolution [px]
  float principal_x_px = 320.0F;  // principal point [px]
  float principal_y_px = 240.0F;
  // Lens distortion, OpenCV's radial-tangential model in normalised coordinates (rig.h;
  // docs/configuration.md "Calibrating the camera"): calibrateCamera's k1, k2, p1, p2, k3.
  float k1 = 0.0F;
  float k2 = 0.0F;
  float p1 = 0.0F;
  float p2 = 0.0F;
  float k3 = 0.0F;
  // Pan-tilt unit and the L-shaped camera support (App. A).
  float ptu_height_m = 0.6F;       // PTU centre (pan and tilt axes) above the floor [m]
  float lever_m = 0.21F;           // tilt axis to camera optical centre, L [m]
  float support_angle_rad = 0.0F;  // angle Ω of the L-support between lever and optical axis [rad]
  float tilt_step_rad = 0.134390352F;  // tilt between the two stereo frames, Φ = 7.7° [rad]
  // Base.
  float robot_radius_m = 0.25F;  // radius of the cylinder that contains the robot [m]
  float robot_height_m = 0.8F;   // height of that cylinder [m]
  float wheel_radius_m = 0.08F;  // [m]
  float track_width_m = 0.40F;   // distance between the wheels [m]
  // The odometry's calibration (UMBmark, Borenstein & Feng 1996): the effective track is
  // track_width_m times this, and the right wheel's effective diameter is this ratio times
  // the left's (their mean stays 2 × wheel_radius_m). `base-calibration` on the console
  // estimates both from a mission's registrations.
  float odometry_track_scale = 1.0F;     // [1]
  float odometry_diameter_ratio = 1.0F;  // right / left [1]
  // The calibrated odometry: the effective track [m] and each wheel's effective radius over
  // wheel_radius_m (2/(1 + E_d) and 2·E_d/(1 + E_d)).
  [[nodiscard]] float odometry_track_m() const { return track_width_m * odometry_track_scale; }
  [[nodiscard]] float odometry_left_scale() const {
    return 2.0F / (1.0F + odometry_diameter_ratio);
  }
  [[nodiscard]] float odometry_right_scale() const {
    return 2.0F * odometry_diameter_ratio / (1.0F + odometry_diameter_ratio);
  }
  float max_speed_m_s = 0.3F;        // forward speed limit [m/s]
  float max_turn_rate_rad_s = 0.8F;  // yaw rate limit [rad/s]
  // Executive and console.
  std::uint32_t minor_frame_us = 10000;  // executive minor frame [µs]
  std::uint32_t console_baud = 115200;
  std::uint32_t telemetry_period_ms = 1000;
  // Linux process set-up for the executive (firmware/realtime.h): mlockall, prefaulted
  // stack, SCHED_FIFO at this priority when permitted. Off on the host simulation.
  bool realtime = false;
  int fifo_priority = 50;
  // Hardware watchdog (/dev/watchdog). Its timeout must lie in the board's range: at least the
  // service's restart chain after a hang plus a margin (shorter, the board would reset before
  // systemd has restarted a hung firmware), at most what the device can count. It is off only
  // by an explicit `[watchdog] enabled = false`, which every start warns about.
  bool watchdog_enabled = true;
  std::uint32_t watchdog_timeout_ms = 2000;      // [ms]
  std::uint32_t watchdog_min_timeout_ms = 1000;  // the board's range [ms] (not a file key)
  std::uint32_t watchdog_max_timeout_ms = 60000;
  // Background units per frame (0 = limited by time only); a simulated board may set it so
  // the work done per frame does not depend on the host's speed.
  std::uint32_t background_units_per_slice = 0;
  std::uint32_t checkpoint_period_ms = 1000;  // state checkpoint period while no cycle ends
  // Fault policy (docs/reliability.md): a device fault holds the robot stopped and the device
  // is retried for this long; then the firmware gives up and exits with kExitFailure, which
  // the service unit restarts with --resume [s].
  float device_retry_s = 30.0F;
  // The mission's look (§6.2.1, §6.3): pan positions spread over the PTU's pan range (the
  // camera's 56° field of view closes the circle beyond it), and tilt rows; each row is a
  // stereo pair (tilt, tilt − Φ) or a single frame for the floor cue only.
  std::uint32_t look_pan_positions = 15;
  static constexpr std::size_t kMaxTiltRows = 4;
  std::array<float, kMaxTiltRows> look_tilt_rad = {0.0F, -0.5F, -0.8F, 0.0F};
  std::array<bool, kMaxTiltRows> look_tilt_is_pair = {true, true, false, false};
  std::uint32_t look_tilt_rows = 2;
  std::uint32_t camera_settle_ms = 60;  // after the PTU stops, before a frame counts [ms]
  // Gear play: a stereo pair's first tilt is approached from at least this far above, so both
  // of its frames take up the PTU's backlash on the same side and the tilt step between them
  // is Φ (0: moves go straight to the view) [rad].
  float ptu_approach_rad = 0.01F;
  // What the camera can be trusted for (thesis §3.4: about 0.1 m to 4.5 m).
  float max_range_m = 4.5F;
  float ceiling_height_m = 2.5F;     // readings above this height are errors [m]
  float clearance_margin_m = 0.05F;  // kept beyond the robot radius from every obstacle [m]
  float ground_clearance_m = 0.03F;  // lowest obstacle height the base cannot drive over [m]
  float goal_standoff_m = 0.75F;     // the mission ends this far from the target [m]
  std::uint32_t steps_per_look = 3;  // steps driven on one look's polygon before the next look
  // Where to go: true (default), the thesis's reward cones and ALN value iteration (ch. 5.5);
  // false, frontier goals by path cost on the world memory's grid (docs/mission.md: on seeds
  // 1-2 of the shipped and test worlds it found 29 of 36 targets, the thesis's planner 30).
  bool thesis_planner = true;
  // Every look registered against the world memory before it is fused, its corrected pose the
  // mission's ([mission] register_looks). Off by default: on a realistic base it holds the pose
  // far better than odometry over long runs, but with perfect odometry its small corrections
  // are pure error (docs/benchmarks.md, localization).
  bool register_looks = false;
  // On a floor the floor cue has learned to be textured, stereo readings of the floor itself
  // (a rug's or wood's texture) are free floor, not occupancy, when their line of sight meets
  // the floor within this range error (a fraction of the range; evidence::floor_readings);
  // deeper ones are refused. 0: off, the thesis's readings ([mission] floor_range_error).
  float floor_range_error = 0.05F;
  // The stereo calibrates itself from the floor: each look's calibration self-check (stereo
  // against floor-cue distances at obstacle bases) gives the inverse-range bias a focal length
  // or tilt step a little off adds, and the next looks' tilt pairs have it removed
  // (StereoParams::self_calibration; [mission] stereo_self_calibration).
  bool stereo_self_calibration = true;
};

}  // namespace boticelli::firmware
