// MapStage: the Think stage's local model of a look (thesis ch. 4–5) and the global map the
// mission keeps across looks (§5.4.4 obstacle and exploration points, mission frame).
#pragma once

#include <Eigen/Core>

#include "algo/core/fixed_vector.h"
#include "algo/core/geometry.h"
#include "algo/mapping/local_model_builder.h"
#include "algo/mapping/map_points.h"
#include "algo/worldmap/grid_map.h"
#include "algo/worldmap/look_fusion.h"
#include "algo/worldmap/scan_matcher.h"
#include "firmware/mission/look/look_processor.h"
#include "firmware/state/mission_state.h"

namespace boticelli::firmware::mission {

// What a look's fusion needs besides the look (all from the mission's parameters).
struct FuseParams {
  mapping::MapPointParams points;
  float robot_radius_m = 0.25F;   // exploration points the robot's disc cannot reach move
  float goal_standoff_m = 0.75F;  // a lone target sighting is revisited from this far [m]
};

class MapStage {
 public:
  MapStage() = default;
  MapStage(const MapStage&) = delete;
  MapStage& operator=(const MapStage&) = delete;

  // A mission (re)starts: the global lists as the state holds them, an empty grid (the world
  // memory is rebuilt by the looks after a resume), no earlier look.
  void start(const MissionState& state, const worldmap::GridMapParams& grid);
  // The local model of a look taken at `look_pose` (mission frame) from its readings; the
  // last look's free polygon, seen from here, is its prior.
  void begin(const mapping::LocalModelParams& params, const LookReadings& readings,
             const core::Pose2& look_pose);
  // One unit of the local model; done() when the polygon and the points are ready.
  void run_unit() { (void)builder_.run_unit(); }
  [[nodiscard]] bool done() const { return builder_.done(); }
  // The look's map points merged into the global lists; known exploration points this look
  // saw marked explored; a lone target sighting (`candidate`, or nullptr) given an
  // exploration point at the stand-off; exploration points the robot cannot reach moved clear.
  void fuse(const core::Pose2& look_pose, const FuseParams& params,
            const Eigen::Vector3f* candidate);
  // The look (taken at `look_pose` by odometry) registered against the grid before it is
  // fused, in units: start, then register_unit() until register_done(); registration() says
  // where the look was taken and how well that is known.
  void begin_register(const core::Pose2& look_pose, const worldmap::ScanMatcherParams& params) {
    matcher_.start(grid_, look_pose, builder_.map().free, builder_.evidence(), params);
  }
  void register_unit() { (void)matcher_.run_unit(); }
  [[nodiscard]] bool register_done() const { return matcher_.done(); }
  [[nodiscard]] const worldmap::Registration& registration() const { return matcher_.result(); }
  // The moves swept since the last look, then the look's free polygon and the evidence
  // backing it, into the grid (background), in units: start, then grid_unit() until
  // grid_done().
  void begin_grid(const core::Pose2& look_pose, const worldmap::LookFusionParams& params);
  void grid_unit() { (void)fusion_.run_unit(); }
  [[nodiscard]] bool grid_done() const { return fusion_.done(); }
  // The robot's disc (radius_m) drove from `from` to `to`: those cells are free. Only noted
  // here (the mission task calls it); begin_grid() writes them. False if the note was full.
  bool swept(core::Point2 from, core::Point2 to, float radius_m) {
    return swept_.push_back({from, to, radius_m});
  }
  [[nodiscard]] const worldmap::GridMap& grid() const { return grid_; }
  // Copies the global lists into the state (as many as it holds).
  void save(MissionState& state) const;

  [[nodiscard]] const mapping::LocalModelBuilder& builder() const { return builder_; }
  [[nodiscard]] const mapping::LocalMap& local() const { return builder_.map(); }
  [[nodiscard]] const mapping::GlobalMap& global() const { return map_; }

 private:
  mapping::LocalModelBuilder builder_;
  // The last look's free polygon and pose (mission frame), the next look's prior.
  mapping::StarPolygon prior_look_free_{};
  core::Pose2 prior_look_pose_{};
  bool has_prior_look_ = false;
  mapping::GlobalMap map_;
  worldmap::GridMap grid_;
  worldmap::LookFusion fusion_;
  worldmap::ScanMatcher matcher_;
  struct Swept {
    core::Point2 from;
    core::Point2 to;
    float radius_m;
  };
  core::FixedVector<Swept, 16> swept_;  // moves since the last look (a few steps a look)
  core::FixedVector<core::Point2, mapping::kMaxObstaclePoints> cycle_obstacles_;
  core::FixedVector<core::Point2, mapping::kMaxExplorationPoints> cycle_exploration_;
};

}  // namespace boticelli::firmware::mission
