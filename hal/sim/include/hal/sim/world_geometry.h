// World geometry for tests and benchmarks: the robot disc's clearance, run traces checked against
// the walls, shortest paths (SPL). Host-side, allocates; independent of SimWorld's own counter.
#pragma once

#include <cstddef>
#include <string>
#include <vector>

#include "algo/core/geometry.h"
#include "hal/sim/world.h"

namespace boticelli::hal::sim {

// Obstacles no higher than this are driven over (a cable on the floor) [m]; the simulator's
// BaseParams::floor_clearance_m has the same default.
inline constexpr float kFloorClearanceM = 0.01F;

// Distance [m] from the robot's vertical cylinder (radius_m, from the floor to height_m) at
// (x_m, y_m) to the nearest collider whose height range overlaps (kFloorClearanceM, height_m);
// negative when they overlap (minus the penetration depth), +inf when there is none.
// Computed from World::colliders: point-to-convex-polygon and point-to-circle distances.
float disc_clearance_m(const World& world, float x_m, float y_m, float radius_m, float height_m);

// One row of a mission trace (--trace FILE): header t_s,x_m,y_m,yaw_rad,pan_rad,tilt_rad,state
// and possibly more columns; x, y, yaw are the simulator's true pose. When the header has the
// firmware's columns odo_x_m,odo_y_m,odo_yaw_rad and est_x_m,est_y_m,est_yaw_rad (the raw
// odometry and the mission's pose estimate, both in the mission frame), `odo` and `est` hold
// them (x, y, yaw) and `has_pose_columns` is set.
struct TraceRow {
  double t_s;
  double x_m;
  double y_m;
  double yaw_rad;
  double pan_rad;
  double tilt_rad;
  char state[24];
  bool has_pose_columns;
  double odo[3];
  double est[3];
};

// Reads a trace and validates the header and every row (field count as in the header, finite
// numbers, also in the odo_ and est_ columns, a non-empty state of at most 23 characters, time
// never going back, at least one row). On failure returns false with "FILE:LINE: why" in
// `error`.
bool read_trace(const char* path, std::vector<TraceRow>& rows, std::string& error);

// The simulator never lets the disc overlap (it refuses the 1 ms step that would and stops the
// base), so a bump shows in a true-pose trace as a clearance of at most one step (0.3 mm at
// 0.3 m/s) and the trace's 0.1 mm rounding. A contact episode therefore starts when the
// clearance drops below kTraceContactM and ends when it is back above kTraceReleaseM (the
// bumper's 1 cm contact margin), so touching and backing off is one collision, not many.
inline constexpr double kTraceContactM = 0.001;
inline constexpr double kTraceReleaseM = 0.01;

struct TraceCheck {
  std::size_t rows = 0;
  std::size_t collisions = 0;  // contact episodes (see kTraceContactM)
  double min_clearance_m = 0;  // smallest clearance along the whole path, rows and between
  double max_gap_s = 0;        // largest time between two consecutive rows
  double path_length_m = 0;    // sum of the straight segments between rows
};

// Checks a trace against the world: the straight segment between consecutive rows is
// sub-sampled at most 1 cm apart (finer close to obstacles), so a contact between rows counts.
TraceCheck check_trace(const World& world, const std::vector<TraceRow>& rows, float radius_m,
                       float height_m);

// Times a trace drove back the way it came: its true path read in stretches of stride_m of
// travel, a reversal wherever one stretch's direction turns from the one before by more than
// min_turn_rad (a turn in place between two steps counts as its outcome).
std::size_t count_reversals(const std::vector<TraceRow>& rows, double stride_m = 0.25,
                            double min_turn_rad = 2.35619449);

// Length [m] of the shortest collision-free path of the robot's disc from `start` to any point
// within goal_radius_m of `goal`: Dijkstra over a 2.5 cm grid (aligned on the start) with
// 16-neighbour moves whose edges are proven free (the clearance's 1-Lipschitz bound, or a
// walk along the edge next to walls), then
// string-pulled with exact visibility checks and a straight last leg to the goal circle, so it
// is within about 1 % of the Euclidean-optimal length. +inf when the start collides or no such
// path exists; 0 when the start is already within the goal radius.
double shortest_path_m(const World& world, core::Point2 start, core::Point2 goal,
                       float goal_radius_m, float robot_radius_m, float height_m);

}  // namespace boticelli::hal::sim
