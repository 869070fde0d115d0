// Board: what a board folder hands the firmware — its description, its config and its HAL bag.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <span>

#include <Eigen/Core>

#include "algo/core/geometry.h"
#include "firmware/config_file.h"
#include "firmware/fault_injection.h"
#include "firmware/options.h"
#include "firmware/snapshot.h"
#include "hal/hal.h"

namespace boticelli::firmware {

struct BoardInfo {
  const char* name;         // folder in boards/, e.g. "sim"
  const char* description;  // one line for --version
  bool simulated;           // true for the sim board (accepts --world)
};

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
  float radial_k1 = 0.0F;  // radial distortion, normalised coordinates
  // Pan-tilt unit and the L-shaped camera support (App. A).
  float ptu_height_m = 0.6F;       // PTU centre (pan and tilt axes) above the floor [m]
  float lever_m = 0.21F;           // tilt axis to camera optical centre, L [m]
  float support_angle_rad = 0.0F;  // angle Ω of the L-support between lever and optical axis [rad]
  float tilt_step_rad = 0.134390352F;  // tilt between the two stereo frames, Φ = 7.7° [rad]
  // Base.
  float robot_radius_m = 0.25F;      // radius of the cylinder that contains the robot [m]
  float robot_height_m = 0.8F;       // height of that cylinder [m]
  float wheel_radius_m = 0.08F;      // [m]
  float track_width_m = 0.40F;       // distance between the wheels [m]
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
  std::uint32_t watchdog_timeout_ms = 2000;  // /dev/watchdog timeout; 0 = do not arm it
  // Background units per frame (0 = limited by time only); a simulated board may set it so
  // the work done per frame does not depend on the host's speed.
  std::uint32_t background_units_per_slice = 0;
  std::uint32_t checkpoint_period_ms = 1000;  // state checkpoint period while no cycle ends
  // The mission's look (§6.2.1, §6.3): pan positions spread over the PTU's pan range (the
  // camera's 56° field of view closes the circle beyond it), and tilt rows; each row is a
  // stereo pair (tilt, tilt − Φ) or a single frame for the floor cue only.
  std::uint32_t look_pan_positions = 15;
  static constexpr std::size_t kMaxTiltRows = 4;
  std::array<float, kMaxTiltRows> look_tilt_rad = {0.0F, -0.5F, -0.8F, 0.0F};
  std::array<bool, kMaxTiltRows> look_tilt_is_pair = {true, true, false, false};
  std::uint32_t look_tilt_rows = 2;
  std::uint32_t camera_settle_ms = 60;  // after the PTU stops, before a frame counts [ms]
  // What the camera can be trusted for (thesis §3.4: about 0.1 m to 4.5 m).
  float max_range_m = 4.5F;
  float ceiling_height_m = 2.5F;     // readings above this height are errors [m]
  float clearance_margin_m = 0.05F;  // kept beyond the robot radius from every obstacle [m]
  float ground_clearance_m = 0.03F;  // lowest obstacle height the base cannot drive over [m]
  float goal_standoff_m = 0.75F;     // the mission ends this far from the target [m]
  std::uint32_t steps_per_look = 3;  // steps driven on one look's polygon before the next look
};

// Ground truth a simulated board can report (never used to decide anything): the trace and
// the MISSION line's target error. Hardware boards have none.
class TruthSource {
 public:
  virtual ~TruthSource() = default;
  virtual core::Pose2 robot_pose() const = 0;       // true pose in the world [m, rad]
  virtual core::Pose2 odometry_origin() const = 0;  // world pose of the odometry frame's origin
  virtual Eigen::Vector3f target_m() const = 0;     // the true target point in the world [m]
  // The obstacles seen from above, for pictures: convex outlines and circles (world frame).
  virtual std::span<const std::span<const core::Point2>> outlines() const { return {}; }
  virtual std::span<const SnapshotCircle> circles() const { return {}; }

 protected:
  TruthSource() = default;
  TruthSource(const TruthSource&) = default;
  TruthSource& operator=(const TruthSource&) = default;
};

class Board {
 public:
  virtual ~Board() = default;
  virtual const BoardInfo& info() const = 0;
  virtual const BoardConfig& config() const = 0;
  // Puts the config (and the board's device settings) back to the compiled-in defaults of
  // boards/<board>/board_config.h and adds the keys a configuration file may set, bound to
  // them (add_board_config_keys() and the board's devices). The firmware then applies the
  // file, before init().
  virtual bool reset_config(ConfigSchema& schema) = 0;
  // The configuration file read when there is no --config FILE (it may be missing), or
  // nullptr: only --config.
  virtual const char* default_config_path() const { return nullptr; }
  // Creates the devices for these options (the sim board loads --world). The firmware then
  // calls each device's init()/open() once. On failure returns false and writes a one-line
  // reason into `error`.
  virtual bool init(const Options& options, char* error, std::size_t error_size) = 0;
  // The devices; valid after a successful init().
  virtual hal::Hal& hal() = 0;
  // Ground truth, or nullptr (hardware).
  virtual const TruthSource* truth() const { return nullptr; }
  // The console's `fault` command, or nullptr (hardware: faults cannot be injected).
  virtual FaultInjection* fault_injection() { return nullptr; }
  // A resumed mission's saved pose, in the mission's frame (the robot's pose when the mission
  // first started), called after init() and before the devices start. The sim board puts the
  // robot there (that frame being the world's start pose) and fails if the pose collides; a
  // hardware board cannot move the robot and trusts it to stand where it stopped.
  virtual bool place_robot(const core::Pose2& mission_pose, char* error, std::size_t error_size) {
    (void)mission_pose;
    (void)error;
    (void)error_size;
    return true;
  }
};

}  // namespace boticelli::firmware
