// Mission parameters: every stage's settings derived once from the board config, so the stages
// and their capacities agree.
#pragma once

#include <cstddef>
#include <cstdint>

#include "algo/evidence/reading_limits.h"
#include "algo/mapping/local_model_builder.h"
#include "algo/mapping/map_points.h"
#include "algo/planning/planner.h"
#include "algo/planning/rewards.h"
#include "algo/planning/value_iteration.h"
#include "algo/stereo/rig.h"
#include "algo/stereo/stereo_processor.h"
#include "algo/worldmap/grid_map.h"
#include "algo/worldmap/look_fusion.h"
#include "algo/worldmap/nav_planner.h"
#include "algo/worldmap/scan_matcher.h"
#include "firmware/common/board_config.h"
#include "firmware/mission/drive/drive_controller.h"
#include "firmware/mission/target/target_tracker.h"
#include "hal/pan_tilt.h"

namespace boticelli::firmware::mission {

struct LookRow {
  float tilt_rad = 0.0F;
  bool pair = true;  // a stereo pair (tilt, tilt − Φ); else one frame for the floor cue
};

struct MissionParams {
  stereo::RigParams rig;
  stereo::StereoParams stereo;
  evidence::ReadingLimits limits;
  mapping::LocalModelParams model;
  mapping::MapPointParams points;
  planning::ValueIterationParams value;
  planning::RewardParams rewards;
  planning::StepParams step;
  DriveParams drive;
  TargetTrackerParams target;
  // A pair aimed at the confirmed target misses it only when the grid leaves its line of
  // sight clear up to this short of the target (the surface it hangs on is in the map) [m].
  float target_surface_margin_m = 0.3F;
  std::uint32_t pan_positions = 15;
  LookRow rows[BoardConfig::kMaxTiltRows]{};
  std::size_t row_count = 0;
  std::uint32_t settle_us = 60000;           // PTU at rest → frames count after this [µs]
  float ptu_approach_rad = 0.01F;            // BoardConfig::ptu_approach_rad [rad]
  std::uint32_t frame_timeout_us = 3000000;  // no usable frame this long: camera fault [µs]
  std::uint32_t ptu_timeout_us = 8000000;    // a PTU move taking longer: PTU fault [µs]
  // A device fault is held and retried every device_retry_interval_us; with no frame grabbed
  // for device_retry_us since it began the mission gives up (BoardConfig::device_retry_s).
  std::uint64_t device_retry_us = 30000000;
  std::uint32_t device_retry_interval_us = 1000000;
  // While driving the pose goes to the state writer at least this often, and at the end of
  // every step, so a firmware killed mid-step resumes near where the robot stands [µs].
  std::uint32_t pose_save_period_us = 1000000;
  // A resumed mission waits this long after the base is ready for its wheel counters [µs],
  // and believes them up to this much travel of either wheel since the save [m] (beyond: the
  // motor controllers restarted, or the robot was carried).
  std::uint32_t resume_wheels_wait_us = 1000000;
  float resume_max_roll_m = 1.0F;
  std::uint32_t trace_period_us = 100000;  // one trace row per this much time [µs]
  std::uint32_t vi_work_per_unit = 256;    // value-iteration work per background unit
  std::size_t max_failed_cycles = 4;       // cycles in a row with no safe step → not_found
  // From this many such cycles in a row the robot backs off along its last step before the
  // next look (a fresh look on the spot first: the fit of one look can leave no room).
  std::size_t back_off_after_failed_cycles = 2;
  std::uint32_t steps_per_look = 3;  // steps on one look's navigable polygon
  // Where to go (BoardConfig::thesis_planner): frontier goals on the world memory, or the
  // thesis's reward cones.
  bool thesis_planner = true;
  // With the thesis's planner: a confirmed target whose stand-off the grid shows a path to is
  // approached along that path (else by the cones).
  bool target_by_path = true;
  // A candidate two views of one look agree on (TargetTracker::provisional) is a goal as a
  // confirmed target is: the robot goes to its stand-off, where a glance confirms it (the
  // second place) or dismisses it. false: it is only looked at again from wherever the
  // exploration leads (an exploration point at its stand-off for the thesis's planner).
  bool candidate_as_goal = true;
  worldmap::GridMapParams grid;
  worldmap::LookFusionParams fusion;
  // Every look registered against the grid before it is fused, its pose the mission's
  // (BoardConfig::register_looks).
  bool register_looks = false;
  worldmap::ScanMatcherParams registration;
  worldmap::NavParams nav;
  float nav_step_m = 1.0F;  // longest step along the path to a frontier or target goal [m]
  // The target's stand-off lies near the wall it hangs on, where a look's navigable polygon
  // (its fit, shrunk by the robot's radius) seldom reaches: a stand-off goal this near is
  // stepped to when the straight way there is passable on the grid (known free, the robot's
  // radius and margin from every occupied cell), whatever the polygon says (0: never) [m].
  float final_approach_m = 1.0F;
};

// The camera rig the stereo and the sim renderer both use, from the board's declaration.
stereo::RigParams make_rig_params(const BoardConfig& config);

// Every stage's settings from the board (robot size, PTU height, camera, look, limits). The
// look's rows come lowest tilt first: the lowest teaches the floor cue what the floor looks
// like before the higher rows, which see less floor.
MissionParams make_mission_params(const BoardConfig& config);

// One view of the look's scan: `view` counts pans within a row (spread over the PTU's pan
// limits, every other row swept back), then rows; a pair's tilt leaves room for its second
// frame, tilt − Φ, above the tilt limit.
struct LookView {
  float pan_rad = 0.0F;
  float tilt_rad = 0.0F;
  bool pair = true;
};
LookView scan_view(const MissionParams& params, const hal::PanTiltLimits& limits, std::size_t view);

}  // namespace boticelli::firmware::mission
