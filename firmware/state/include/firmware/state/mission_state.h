// MissionState: everything a mission must keep across a restart, in fixed capacities (saved by
// StateStore).
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <string_view>

#include "algo/core/fixed_vector.h"
#include "algo/core/geometry.h"
#include "algo/mapping/map_points.h"
#include "algo/worldmap/grid_map.h"

namespace boticelli::firmware {

// One line of the mission log: which cycle, what happened (printable ASCII).
struct MissionLogEntry {
  static constexpr std::size_t kMaxTextBytes = 95;
  std::uint64_t cycle = 0;
  std::array<char, kMaxTextBytes + 1> text{};  // NUL-terminated
  std::string_view view() const { return {text.data()}; }
};

// How a mission ended, as the state keeps it. A mission stopped from outside (a signal, the
// console's `shutdown`, --max-cycles) or by a fault a restart may cure is still kRunning: the
// next start with --resume carries it on. The other three are final: a resumed run says so and
// keeps the robot stopped.
enum class MissionEnd : std::uint8_t { kRunning, kFound, kNotFound, kAborted };
const char* mission_end_name(MissionEnd end);  // "running", "found", "not_found", "aborted"

struct MissionState {
  // The global map's capacities (mapping::GlobalMap), so a saved state holds what the map
  // holds and a restored one fits back into it.
  static constexpr std::size_t kMaxObstaclePoints = mapping::kMaxObstaclePoints;
  static constexpr std::size_t kMaxExplorationPoints = mapping::kMaxExplorationPoints;
  static constexpr std::size_t kMaxModelBytes = std::size_t{64} * 1024;
  static constexpr std::size_t kMaxLogEntries = 128;

  std::uint64_t cycle = 0;  // completed cycles
  std::uint64_t seed = 1;   // --seed of the run that started the mission
  MissionEnd end = MissionEnd::kRunning;
  std::array<char, MissionLogEntry::kMaxTextBytes + 1> end_reason{};  // printable, NUL-terminated
  // Robot pose [m, rad] in the mission's frame: the odometry frame of the run that started the
  // mission (a resumed run carries it on from here).
  core::Pose2 pose;
  // When `pose` was taken, by the board's wall clock [ms since the Unix epoch]; 0: unknown
  // (a board without one, or a state from before version 4). A resumed run says how old it is.
  std::int64_t pose_time_ms = 0;
  // The motor controllers' wheel counters when `pose` was taken (hal::Odometry, [m]): a
  // resumed run dead-reckons from them what the robot did while no firmware ran. Unknown in
  // a state from before version 5, or from a base that does not report them.
  bool wheels_known = false;
  double wheel_left_m = 0.0;
  double wheel_right_m = 0.0;
  // The stereo's learnt inverse-range bias [1/m] (StereoProcessor::inverse_range_bias, the
  // self-calibration from the floor): a resumed run reads its first look corrected. 0 in a
  // state from before version 6.
  float stereo_bias_per_m = 0.0F;
  bool has_goal = false;
  core::Point2 goal;           // target position once confirmed, mission frame [m]
  float goal_height_m = 0.0F;  // the target's height above the floor [m]
  core::FixedVector<core::Point2, kMaxObstaclePoints> obstacles;  // global obstacle list [m]
  core::FixedVector<core::Point2, kMaxExplorationPoints>
      exploration;  // global exploration list [m]
  // The world memory (worldmap::GridMap): its cell side [m] and every tile in use, so a
  // resumed mission knows what it has seen (a grid of another cell side is not restored).
  float grid_cell_m = 0.0F;
  core::FixedVector<worldmap::SavedTile, worldmap::kMaxTiles> grid;
  std::array<char, kMaxModelBytes> model{};  // the last occupancy ALN, text format (opaque here)
  std::size_t model_bytes = 0;
  core::FixedVector<MissionLogEntry, kMaxLogEntries> log;  // oldest first
  // Lines dropped from the front of `log` since clear() (not saved): log[i] is line number
  // log_dropped + i of this run, so a reader can follow the log while it moves on.
  std::uint64_t log_dropped = 0;

  std::string_view model_text() const { return {model.data(), model_bytes}; }
  std::string_view end_reason_text() const { return {end_reason.data()}; }
  bool finished() const { return end != MissionEnd::kRunning; }
  // Records a final end and its reason (cut and made printable as a log line is).
  void set_end(MissionEnd how, std::string_view why);
  // False (model unchanged) when the text is longer than kMaxModelBytes or contains NUL.
  bool set_model(std::string_view text);
  // Appends a log line; the oldest line goes when the log is full. Bytes outside printable
  // ASCII become '?', and text longer than kMaxTextBytes is cut.
  void add_log(std::uint64_t at_cycle, std::string_view text);
  // Back to the state of a fresh mission.
  void clear();
};

// Compares what the state file holds (log_dropped is not part of it).
bool operator==(const MissionState& a, const MissionState& b);

}  // namespace boticelli::firmware
