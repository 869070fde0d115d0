// LookFusion: one look's local map fused into the world memory (GridMap): the free polygon as
// seen free, the evidence that backs its boundary as occupied, in bounded units of work.
#pragma once

#include <cstddef>

#include "algo/core/geometry.h"
#include "algo/mapping/star_polygon.h"
#include "algo/worldmap/grid_map.h"

namespace boticelli::worldmap {

struct LookFusionParams {
  int free_delta = -3;     // log-odds a look adds to each cell its free polygon covers
  int occupied_delta = 5;  // ... and to each cell that holds evidence backing the boundary
  // Evidence of an obstacle (LocalModelBuilder::evidence()) marks its cell occupied when it
  // lies at most this far beyond the free polygon's boundary on its vertex ray [m]: what
  // backs the boundary. Evidence far beyond it (a look whose fit collapsed to a disc round
  // the robot) adds no obstacle there.
  float backing_m = 0.6F;
  float max_range_m = 5.0F;        // nothing farther than this from the look is fused [m]
  std::size_t rows_per_unit = 24;  // grid rows of the free polygon's box per unit of work
};

class LookFusion {
 public:
  // A look at `look_pose` (mission frame) with its free polygon and nearest evidence per
  // vertex ray (both robot frame; evidence ρ = ∞ where none, same vertex count). The
  // polygons must stay valid until done().
  void start(GridMap& map, const core::Pose2& look_pose, const mapping::StarPolygon& free,
             const mapping::StarPolygon& evidence, const LookFusionParams& params);
  // One unit: some rows of free cells, or (the last unit) the evidence. True when done.
  bool run_unit();
  void run() {
    while (!run_unit()) {
    }
  }
  [[nodiscard]] bool done() const { return phase_ == Phase::kDone; }
  [[nodiscard]] std::size_t free_cells() const { return free_cells_; }
  [[nodiscard]] std::size_t occupied_cells() const { return occupied_cells_; }

 private:
  enum class Phase : std::uint8_t { kIdle, kFree, kEvidence, kDone };
  void evidence_cells();

  GridMap* map_ = nullptr;
  core::Pose2 pose_{};
  const mapping::StarPolygon* free_ = nullptr;
  const mapping::StarPolygon* evidence_ = nullptr;
  LookFusionParams params_{};
  Phase phase_ = Phase::kIdle;
  Cell lo_{};
  Cell hi_{};
  int row_ = 0;
  std::size_t free_cells_ = 0;
  std::size_t occupied_cells_ = 0;
};

// The cells the robot's disc (`radius_m`) swept driving straight from `from` to `to` get
// `delta` (negative: free): the robot stood there, so nothing does.
void sweep_disc(GridMap& map, core::Point2 from, core::Point2 to, float radius_m, int delta);

}  // namespace boticelli::worldmap
