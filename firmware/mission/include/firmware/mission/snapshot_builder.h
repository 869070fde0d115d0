// SnapshotBuilder: one cycle's picture (--snapshots) put together from the mission's parts —
// the look's readings, its occupancy model and polygons, the global map, the value function,
// the path and the true walls — in the mission frame, for the SnapshotWriter to draw.
#pragma once

#include <cstdint>
#include <span>

#include "algo/core/geometry.h"
#include "algo/worldmap/grid_map.h"
#include "algo/mapping/local_model_builder.h"
#include "algo/mapping/map_points.h"
#include "algo/planning/planner.h"
#include "algo/planning/value_iteration.h"
#include "firmware/mission/look/look_processor.h"
#include "firmware/telemetry/snapshot.h"
#include "firmware/telemetry/truth_source.h"

namespace boticelli::firmware::mission {

struct SnapshotInputs {
  std::uint32_t cycle = 0;
  const char* state = "";
  core::Pose2 robot{};  // where the cycle ended (mission frame)
  float robot_radius_m = 0.25F;
  core::Pose2 look_pose{};  // where the cycle's look was taken
  const LookReadings* readings = nullptr;
  const mapping::LocalModelBuilder* builder = nullptr;
  const mapping::GlobalMap* map = nullptr;
  const core::Point2* goal = nullptr;       // confirmed target, or nullptr
  const worldmap::GridMap* grid = nullptr;  // the world memory, or nullptr
  const core::Point2* grid_goal = nullptr;  // the last plan's goal on it, or nullptr
  std::span<const core::Point2> path;
  const planning::ValueIteration* value = nullptr;
  const planning::StepDecision* decision = nullptr;
  const TruthSource* truth = nullptr;   // the true walls, or nullptr (hardware)
  core::Pose2 frame_origin_in_world{};  // where the mission frame lies in the truth's world
};

// Sets up the picture and hands it to the writer, which draws it a unit at a time; what the
// inputs point at must stay unchanged until the writer is done.
void begin_snapshot(const SnapshotInputs& in, SnapshotWriter& writer);

}  // namespace boticelli::firmware::mission
