// SnapshotBuilder: one cycle's picture from the mission's parts (see snapshot_builder.h).
#include "firmware/mission/snapshot_builder.h"

#include <algorithm>
#include <array>
#include <cmath>

#include "algo/core/angles.h"
#include "algo/core/fixed_vector.h"

namespace boticelli::firmware::mission {
namespace {

// Working storage of the pictures (static: they are large).
core::FixedVector<SnapshotReading, kMaxLookFeatures + kMaxLookFloorObstacles> g_snap_readings;
std::array<core::Point2, mapping::kMaxPolygonVertices> g_snap_free;
std::array<core::Point2, mapping::kMaxPolygonVertices> g_snap_navigable;
std::array<core::Point2, 2048> g_snap_outline_points;
std::array<std::span<const core::Point2>, 256> g_snap_outlines;
std::array<SnapshotCircle, 256> g_snap_circles;

struct OccupancyView {
  const mapping::LocalModelBuilder* builder;
  core::Pose2 pose;
};
OccupancyView g_snap_occupancy{};  // the picture's occupancy field, read until it is done

// The occupancy model sliced at the robot's heights: the highest occupancy over the slices.
float occupancy_at(const void* context, float x_m, float y_m) {
  const auto& v = *static_cast<const OccupancyView*>(context);
  const core::Point2 q = core::to_robot(v.pose, {x_m, y_m});
  const float rho = std::hypot(q.x_m, q.y_m);
  const float alpha = core::wrap_two_pi(std::atan2(q.y_m, q.x_m));
  const mapping::ExtractionParams& p = v.builder->params().extraction;
  float m = 0.0F;
  for (std::size_t i = 0; i < p.height_count; ++i) {
    const float h = mapping::slice_height_m(p, i);
    m = std::max(m, v.builder->occupancy(alpha, h, std::sqrt(rho * rho + h * h)));
  }
  return std::clamp(m, 0.0F, 1.0F);
}

float grid_at(const void* context, float x_m, float y_m) {
  const auto& grid = *static_cast<const worldmap::GridMap*>(context);
  switch (grid.state(grid.cell_of({x_m, y_m}))) {
    case worldmap::CellState::kFree:
      return kGridFree;
    case worldmap::CellState::kOccupied:
      return kGridOccupied;
    default:
      return kGridUnknown;
  }
}

float value_at(const void* context, float x_m, float y_m) {
  return static_cast<const planning::ValueIteration*>(context)->value({x_m, y_m});
}

void to_world(const mapping::StarPolygon& poly, const core::Pose2& pose,
              std::array<core::Point2, mapping::kMaxPolygonVertices>& out) {
  for (std::size_t k = 0; k < poly.vertex_count(); ++k)
    out[k] = core::to_world(pose, poly.vertex(k));
}

}  // namespace

void begin_snapshot(const SnapshotInputs& in, SnapshotWriter& writer) {
  g_snap_readings.clear();
  auto add = [&](const evidence::Reading& r) {
    const core::Point2 w = core::to_world(in.look_pose, evidence::floor_point_m(r));
    (void)g_snap_readings.push_back({w.x_m, w.y_m, r.m});
  };
  for (const evidence::Reading& r : in.readings->features) add(r);
  for (const evidence::Reading& r : in.readings->floor_obstacles) add(r);
  const mapping::LocalMap& local = in.builder->map();
  to_world(local.free, in.look_pose, g_snap_free);
  to_world(local.navigable, in.look_pose, g_snap_navigable);
  SnapshotFrame f;
  // The cycle's count and pose stand until the next cycle ends, after this picture.
  f.cycle = in.cycle;
  f.state = in.state;
  f.robot = in.robot;
  f.robot_radius_m = in.robot_radius_m;
  // The view: the room so far (path, points) and 3.5 m around the robot.
  float x0 = f.robot.x_m - 3.5F, x1 = f.robot.x_m + 3.5F;
  float y0 = f.robot.y_m - 3.5F, y1 = f.robot.y_m + 3.5F;
  for (const core::Point2& p : in.path) {
    x0 = std::min(x0, p.x_m - 1.0F);
    x1 = std::max(x1, p.x_m + 1.0F);
    y0 = std::min(y0, p.y_m - 1.0F);
    y1 = std::max(y1, p.y_m + 1.0F);
  }
  f.view = {x0, y0, x1, y1};
  f.readings = g_snap_readings.span();
  g_snap_occupancy = {in.builder, in.look_pose};
  f.occupancy = &occupancy_at;
  f.occupancy_context = &g_snap_occupancy;
  f.occupancy_threshold = in.builder->params().extraction.safe_occupancy;
  f.free_polygon = {g_snap_free.data(), local.free.vertex_count()};
  f.navigable_polygon = {g_snap_navigable.data(), local.navigable.vertex_count()};
  f.obstacle_points = in.map->obstacles().span();
  f.exploration_points = in.map->exploration().span();
  if (in.goal != nullptr) f.goal = *in.goal;
  f.path = in.path;
  if (in.grid != nullptr) {
    f.grid = &grid_at;
    f.grid_context = in.grid;
  }
  if (in.grid_goal != nullptr) f.grid_goal = *in.grid_goal;
  f.value = &value_at;
  f.value_context = in.value;
  if (in.decision->kind == planning::StepKind::kMove) f.step_end = in.decision->target;
  if (in.truth != nullptr) {
    // The truth is in the world frame; the pictures are in the mission frame.
    const core::Pose2 origin = in.frame_origin_in_world;
    std::size_t used = 0;
    std::size_t count = 0;
    for (const std::span<const core::Point2> outline : in.truth->outlines()) {
      if (count == g_snap_outlines.size() || used + outline.size() > g_snap_outline_points.size()) {
        break;
      }
      for (std::size_t i = 0; i < outline.size(); ++i) {
        g_snap_outline_points[used + i] = core::to_robot(origin, outline[i]);
      }
      g_snap_outlines[count++] = {g_snap_outline_points.data() + used, outline.size()};
      used += outline.size();
    }
    std::size_t circles = 0;
    for (const SnapshotCircle& c : in.truth->circles()) {
      if (circles == g_snap_circles.size()) break;
      g_snap_circles[circles++] = {core::to_robot(origin, c.centre), c.radius_m};
    }
    f.truth_polygons = {g_snap_outlines.data(), count};
    f.truth_circles = {g_snap_circles.data(), circles};
  }
  writer.begin(f);
}

}  // namespace boticelli::firmware::mission
