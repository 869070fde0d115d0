// MapStage: local model and global map points of each look (see map_stage.h).
#include "firmware/mission/map/map_stage.h"

#include <cmath>

namespace boticelli::firmware::mission {

void MapStage::start(const MissionState& state, const worldmap::GridMapParams& grid) {
  map_.clear();
  grid_.configure(grid);
  swept_.clear();
  has_prior_look_ = false;  // a resumed mission's first look has none
  for (const core::Point2& p : state.obstacles) (void)map_.obstacles().push_back(p);
  for (const core::Point2& p : state.exploration) (void)map_.exploration().push_back(p);
  // A resumed mission's world memory, when it was kept at this cell side.
  if (state.grid_cell_m == grid.cell_m) {
    for (const worldmap::SavedTile& t : state.grid) (void)grid_.restore_tile(t);
  }
}

void MapStage::begin(const mapping::LocalModelParams& params, const LookReadings& readings,
                     const core::Pose2& look_pose) {
  // The last look's free polygon, from where it stood as seen from here: what it saw free
  // keeps rays whose walks this look finds blocked open that far.
  mapping::PriorLook prior;
  if (has_prior_look_) {
    prior.free = &prior_look_free_;
    prior.pose = prior_look_pose_;
    prior.here = look_pose;
  }
  builder_.start(params, readings.features.span(), readings.floor_obstacles.span(),
                 readings.floor_free.span(), readings.floor_free_near.span(),
                 readings.floor_blocked.span(), prior);
}

void MapStage::fuse(const core::Pose2& look_pose, const FuseParams& params,
                    const Eigen::Vector3f* candidate) {
  const mapping::LocalMap& local = builder_.map();
  // Map points (§5.4.4): obstacles where evidence backs the polygon's boundary; exploration
  // points on the bounding circle and where only the lack of seen floor cuts it.
  cycle_obstacles_.clear();
  cycle_exploration_.clear();
  const float radius = builder_.params().extraction.bounding_radius_m;
  (void)builder_.map_points(params.points, cycle_obstacles_, cycle_exploration_);
  // Known exploration points this look saw are explored; then this look's points go in.
  (void)map_.mark_explored(look_pose, builder_.seen_free(), radius, params.points);
  (void)map_.merge(look_pose, local.free, radius, cycle_obstacles_, cycle_exploration_,
                   params.points);
  prior_look_free_ = local.free;
  prior_look_pose_ = look_pose;
  has_prior_look_ = true;
  // A sighting no second view has confirmed yet: look at it again from the stand-off (the
  // detector may miss it near the image's edge), unless the robot already looked from there.
  if (candidate != nullptr) {
    const Eigen::Vector3f& c = *candidate;
    const float dx = look_pose.x_m - c.x();
    const float dy = look_pose.y_m - c.y();
    const float d = std::hypot(dx, dy);
    if (d > params.points.explored_look_radius_m + params.goal_standoff_m) {
      const float s = params.goal_standoff_m / d;
      const core::Point2 p{c.x() + s * dx, c.y() + s * dy};
      bool known = false;
      for (const core::Point2& q : map_.exploration()) {
        known = known || core::distance_m(p, q) < params.points.exploration_merge_radius_m;
      }
      if (!known) (void)map_.exploration().push_back(p);
    }
  }
  // An exploration point the robot's disc cannot reach (it touches a known obstacle) would
  // only draw the robot into a corner: move it clear, toward where the robot looked from.
  (void)map_.clear_exploration({look_pose.x_m, look_pose.y_m}, params.robot_radius_m, radius,
                               params.points);
}

void MapStage::begin_grid(const core::Pose2& look_pose, const worldmap::LookFusionParams& params) {
  for (const Swept& s : swept_) {
    worldmap::sweep_disc(grid_, s.from, s.to, s.radius_m, params.free_delta);
  }
  swept_.clear();
  fusion_.start(grid_, look_pose, builder_.map().free, builder_.evidence(), params);
}

void MapStage::save(MissionState& state) const {
  state.obstacles.clear();
  for (const core::Point2& p : map_.obstacles()) {
    if (!state.obstacles.push_back(p)) break;
  }
  state.exploration.clear();
  for (const core::Point2& p : map_.exploration()) {
    if (!state.exploration.push_back(p)) break;
  }
  // The grid's tiles in use, into the state's fixed storage.
  state.grid_cell_m = grid_.cell_m();
  const std::size_t n = state.grid.resize(grid_.tiles_used());
  (void)grid_.save_tiles(state.grid.data(), n);
}

}  // namespace boticelli::firmware::mission
