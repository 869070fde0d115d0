// Obstacle points inside the bounding circle and exploration points on it (§5.4.4) or where the
// belief and plausibility polygons disagree (§7.2.3), and their global lists.
#pragma once

#include <cstddef>

#include "algo/core/fixed_vector.h"
#include "algo/core/geometry.h"
#include "algo/mapping/star_polygon.h"

namespace boticelli::mapping {

using PointList = core::FixedVectorBase<core::Point2>;

struct MapPointParams {
  float obstacle_spacing_m = 0.15F;     // along the boundary inside the bounding circle
  float exploration_spacing_m = 0.5F;   // along the bounding circle: finds ~0.5 m channels
  float on_circle_tolerance_m = 0.02F;  // ρ within this of the bounding radius is "on it"
  // An incoming obstacle point this close to a known one is the same point [m].
  float obstacle_merge_radius_m = 0.1F;
  // A known obstacle point this far inside a later free polygon, and this far inside its
  // bounding circle, is contradicted by the newer view and retired [m]. It came from an
  // earlier, coarser model or from a pose that odometry has since corrected. Larger than
  // obstacle_spacing_m's half and than the polygon's per-ray error (about ρ·Δθ, 5 cm at
  // 3 m with 360 rays), so a point on or near the newer boundary, where the wall still is,
  // is kept.
  float obstacle_retire_margin_m = 0.15F;
  float exploration_merge_radius_m = 0.35F;  // likewise for exploration points [m]
  // An exploration point this far inside a later free polygon has been explored [m].
  float explored_margin_m = 0.1F;
  // A known exploration point this close to a later look's position has been explored too:
  // the robot came there and looked all around (a point by a wall, which no polygon reaches
  // because the fit's boundary stands off walls, would otherwise draw the robot back) [m].
  float explored_look_radius_m = 1.0F;
  // §7.2.3 belief–plausibility exploration: a ray whose belief free distance exceeds its
  // plausibility free distance (both cut to the bounding circle) by at least this much
  // crosses an unknown band, the polygon form of a high uncertainty interval Pl − Bel [m].
  float exploration_gap_m = 0.5F;
  // Such a point sits this far inside the plausibility boundary [m]; less than
  // explored_margin_m, so the polygon the point came from does not count it as explored.
  float gap_point_inset_m = 0.05F;
  // LocalModelBuilder::map_points: an unknown stretch of the boundary (end to end) narrower
  // than this gives no exploration points; the mission sets the robot's width plus margins.
  float min_frontier_width_m = 0.6F;
  // GlobalMap::clear_exploration: how far an exploration point may move to clear obstacles.
  float exploration_max_pull_m = 0.6F;
  float exploration_pull_step_m = 0.05F;
};

// §5.4.4: splits the free polygon's boundary (robot frame) into sectors on the bounding
// circle and sectors inside it, and places points at evenly spaced vertex angles in each
// sector: obstacle points on the boundary inside the circle (about one per
// obstacle_spacing_m of boundary), exploration points on the circle (one per
// exploration_spacing_m of arc). Appends to the lists; returns false if one was full.
bool extract_map_points(const StarPolygon& free, float bounding_radius_m,
                        const MapPointParams& params, PointList& obstacles_robot,
                        PointList& exploration_robot);

// §7.2.3: exploration points where the belief model (lower bound of occupancy, so the larger
// free polygon) and the plausibility model (upper bound, the navigation polygon) disagree.
// A vertex ray is a gap ray if min(ρ_bel, R) − min(ρ_pl, R) ≥ exploration_gap_m (R the
// bounding radius); consecutive gap rays (across the seam at angle 0 too) form a sector, and
// each sector gets one point per exploration_spacing_m of the arc the points lie on (at least
// one), at evenly spaced vertex angles, gap_point_inset_m inside the plausibility boundary:
// the nearest place the robot can surely reach from which it looks into the unknown band.
// Appends to exploration_robot (robot frame); returns false if the list was full. Returns
// false and appends nothing if the two polygons' vertex counts differ.
bool extract_gap_exploration_points(const StarPolygon& belief_free,
                                    const StarPolygon& plausibility_free, float bounding_radius_m,
                                    const MapPointParams& params, PointList& exploration_robot);

inline constexpr std::size_t kMaxObstaclePoints = 4096;
inline constexpr std::size_t kMaxExplorationPoints = 512;

// The global obstacle and exploration lists in the world frame, merged across cycles.
class GlobalMap {
 public:
  // Merges one cycle's points (robot frame, taken at `pose` from odometry). First, known
  // obstacle points that this free polygon contradicts (obstacle_retire_margin_m inside it
  // and inside the bounding circle: the polygon speaks only about what it saw) are retired;
  // then incoming obstacle points closer than obstacle_merge_radius_m to a known one are
  // dropped (deduplicated). Known exploration points that this free polygon covers
  // (explored_margin_m inside it) or that lie within explored_look_radius_m of the look's
  // position are removed as explored, then incoming ones are added
  // unless one is already that close. Removal keeps the order of the points that stay.
  // `free` should be the polygon after the feature guard's exclusions (extract_local_map's
  // LocalMap::free), so an obstacle the model smooths away is not retired by it. Returns
  // false if a list overflowed (the points that did not fit are counted and dropped).
  bool merge(const core::Pose2& pose, const StarPolygon& free, float bounding_radius_m,
             const PointList& obstacles_robot, const PointList& exploration_robot,
             const MapPointParams& params);

  // Removes the known exploration points a look saw: at least explored_margin_m inside
  // `seen` (robot frame at `pose`: how far the floor, or an obstacle's base, was seen along
  // each ray) and its bounding circle. Call it before merge() with the same look, so the
  // look's own fresh points (on or near the seen boundary) stay. Returns how many went.
  std::size_t mark_explored(const core::Pose2& pose, const StarPolygon& seen,
                            float bounding_radius_m, const MapPointParams& params);

  // Keeps exploration points reachable by the robot's disc: a point closer than clearance_m
  // to an obstacle point is moved toward `origin` (the look's position, world frame) in
  // steps of exploration_pull_step_m, at most exploration_max_pull_m, until it is clear;
  // points that cannot be cleared, or lie farther than pull_reach_m from `origin` (not
  // this look's), are dropped. A doorway's points thus stay, in the doorway's middle, instead
  // of vanishing with the door frame's obstacle points. Returns the number dropped.
  std::size_t clear_exploration(core::Point2 origin, float clearance_m, float pull_reach_m,
                                const MapPointParams& params);

  void clear();
  [[nodiscard]] const PointList& obstacles() const { return obstacles_; }
  [[nodiscard]] const PointList& exploration() const { return exploration_; }
  // For persistence: restores saved lists (world frame) with push_back after clear().
  PointList& obstacles() { return obstacles_; }
  PointList& exploration() { return exploration_; }
  [[nodiscard]] std::size_t dropped_points() const { return dropped_; }
  // Obstacle points retired as contradicted by a newer polygon, since clear().
  [[nodiscard]] std::size_t retired_points() const { return retired_; }

 private:
  core::FixedVector<core::Point2, kMaxObstaclePoints> obstacles_;
  core::FixedVector<core::Point2, kMaxExplorationPoints> exploration_;
  std::size_t dropped_ = 0;
  std::size_t retired_ = 0;
};

}  // namespace boticelli::mapping
