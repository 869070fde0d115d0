// MissionView: what the console and telemetry may ask the mission (state, pose, model, map).
#pragma once

#include <cstdint>
#include <string_view>

#include "algo/core/geometry.h"
#include "firmware/state/mission_state.h"

namespace boticelli::firmware {

// The navigation goal of the last plan on the grid.
enum class GoalKind : std::uint8_t { kNone, kFrontier, kTarget };
const char* goal_kind_name(GoalKind kind);

struct MapCounts {
  std::uint32_t polygon_vertices = 0;    // vertices of the current navigation polygon
  std::uint32_t obstacle_points = 0;     // global obstacle list
  std::uint32_t exploration_points = 0;  // global exploration list
  // The world memory (the grid of everything seen).
  std::uint32_t grid_tiles = 0;     // tiles in use
  std::uint32_t grid_bytes = 0;     // its memory: tiles in use and the directory
  float free_m2 = 0.0F;             // area of free cells
  float occupied_m2 = 0.0F;         // area of occupied cells
  std::uint32_t grid_dropped = 0;   // updates dropped (pool exhausted or off the grid)
  std::uint32_t frontiers = 0;      // frontier clusters in the last plan on the grid
  std::uint32_t blacklisted = 0;    // frontier goals given up on (no progress)
  GoalKind goal = GoalKind::kNone;  // the last plan's goal on the grid
  float goal_x_m = 0.0F;            // mission frame
  float goal_y_m = 0.0F;
  float goal_path_m = 0.0F;  // path length to it on the grid
};

// The base's odometry calibration as the looks' registrations show it (UMBmark, Borenstein &
// Feng 1996): the values for [base] odometry_track_scale and odometry_diameter_ratio, with
// their standard errors, once there is enough turning and driving to say (`valid`).
struct OdometryCalibration {
  bool valid = false;
  std::uint32_t intervals = 0;  // look-to-look intervals used
  float turned_rad = 0.0F;      // |turning| over them
  float driven_m = 0.0F;        // |driving| over them
  float track_scale = 1.0F;     // effective track / base.track_width_m
  float track_scale_sd = 0.0F;
  float diameter_ratio = 1.0F;  // right wheel's effective diameter / the left's
  float diameter_ratio_sd = 0.0F;
};

// The camera rig's calibration as the floor shows it (stereo::RangeCheck and the stereo's
// self-calibration; docs/configuration.md): the median ratio of stereo to floor distances at
// obstacle bases over the looks that had enough of them, the inverse-range bias the stereo
// removes, and that bias as the one rig error that would cause it alone.
struct CameraCalibration {
  std::uint32_t bases = 0;                // ratios the check is over (0: none yet)
  float stereo_to_floor = 0.0F;           // their median, 1 for a calibrated rig
  bool self_calibrating = false;          // [mission] stereo_self_calibration
  float inverse_range_bias_per_m = 0.0F;  // b in 1/r_read = 1/r + b, removed [1/m]
  float focal_scale = 1.0F;               // b as a true focal length of camera.focal_px times this
  float tilt_step_error_rad = 0.0F;       // or as a true tilt step ptu.tilt_step_rad plus this
};

// The mission's idea of where the target is: none yet, seen once (a candidate not yet
// confirmed by a second view) or confirmed (the goal).
enum class TargetStatus : std::uint8_t { kNone, kSeen, kConfirmed };
struct TargetEstimate {
  TargetStatus status = TargetStatus::kNone;
  std::uint32_t sightings = 0;  // views that saw it
  float x_m = 0.0F;             // mission frame, as pose() [m]
  float y_m = 0.0F;
  float z_m = 0.0F;  // height above the floor [m]
};
const char* target_status_name(TargetStatus status);

// Read-only view the mission implements; the console calls it from its task, so every call
// must be quick and must not allocate.
class MissionView {
 public:
  virtual ~MissionView() = default;
  virtual const char* state_name() const = 0;           // e.g. "look", "think", "drive", "hold"
  virtual core::Pose2 pose() const = 0;                 // mission frame [m, rad]
  virtual float pan_rad() const = 0;                    // current PTU pan [rad]
  virtual std::uint32_t features() const { return 0; }  // features tracked in the last view
  virtual std::uint32_t pieces() const { return 0; }    // linear pieces of the occupancy ALN
  virtual std::uint64_t cycles() const { return 0; }    // completed Look-Think-Drive cycles
  // The current occupancy ALN in the text format; empty when there is none yet. The text
  // stays valid and unchanged until release_model_text() (a model fitted meanwhile is shown
  // after the release), so the console can stream it over many frames.
  virtual std::string_view model_text() { return {}; }
  virtual void release_model_text() {}
  virtual MapCounts map_counts() const { return {}; }
  virtual TargetEstimate target() const { return {}; }
  virtual OdometryCalibration odometry_calibration() const { return {}; }
  virtual CameraCalibration camera_calibration() const { return {}; }
  // The mission log kept in the state file (MissionState::log), by line number: the first
  // line still kept, one past the last, and a line (nullptr when no longer or not yet kept).
  virtual std::uint64_t mission_log_begin() const { return 0; }
  virtual std::uint64_t mission_log_end() const { return 0; }
  virtual const MissionLogEntry* mission_log_line(std::uint64_t number) const {
    (void)number;
    return nullptr;
  }

 protected:
  MissionView() = default;
  MissionView(const MissionView&) = default;
  MissionView& operator=(const MissionView&) = default;
};

}  // namespace boticelli::firmware
