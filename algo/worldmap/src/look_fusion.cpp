// LookFusion: a look's free polygon and backing evidence into the grid (see look_fusion.h).
#include "algo/worldmap/look_fusion.h"

#include <algorithm>
#include <cmath>

namespace boticelli::worldmap {

void LookFusion::start(GridMap& map, const core::Pose2& look_pose, const mapping::StarPolygon& free,
                       const mapping::StarPolygon& evidence, const LookFusionParams& params) {
  map_ = &map;
  pose_ = look_pose;
  free_ = &free;
  evidence_ = &evidence;
  params_ = params;
  free_cells_ = 0;
  occupied_cells_ = 0;
  const float reach = std::min(free.max_rho_m(), params.max_range_m);
  lo_ = map.cell_of({look_pose.x_m - reach, look_pose.y_m - reach});
  hi_ = map.cell_of({look_pose.x_m + reach, look_pose.y_m + reach});
  row_ = lo_.iy;
  phase_ = Phase::kFree;
}

bool LookFusion::run_unit() {
  if (phase_ == Phase::kFree) {
    const int end = std::min(hi_.iy + 1, row_ + static_cast<int>(params_.rows_per_unit));
    const float r2 = params_.max_range_m * params_.max_range_m;
    for (; row_ < end; ++row_) {
      for (int ix = lo_.ix; ix <= hi_.ix; ++ix) {
        const Cell c{ix, row_};
        const core::Point2 q = core::to_robot(pose_, map_->centre_of(c));
        if (q.x_m * q.x_m + q.y_m * q.y_m > r2 || !free_->contains(q)) continue;
        if (map_->add(c, params_.free_delta)) ++free_cells_;
      }
    }
    if (row_ > hi_.iy) phase_ = Phase::kEvidence;
    return false;
  }
  if (phase_ == Phase::kEvidence) {
    evidence_cells();
    phase_ = Phase::kDone;
  }
  return phase_ == Phase::kDone;
}

void LookFusion::evidence_cells() {
  const std::size_t n = std::min(free_->vertex_count(), evidence_->vertex_count());
  Cell last{kGridCells, kGridCells};  // none yet
  for (std::size_t k = 0; k < n; ++k) {
    const float e = evidence_->rho_m(k);
    if (!std::isfinite(e) || e > params_.max_range_m) continue;
    if (e > free_->rho_m(k) + params_.backing_m) continue;
    const float a = evidence_->angle_rad(k);
    const Cell c = map_->cell_of(core::to_world(pose_, {e * std::cos(a), e * std::sin(a)}));
    if (c == last) continue;  // neighbouring rays on one cell: one hit a look
    last = c;
    // The polygon stops short of the surface (the fit's caution, the range error): the floor
    // between its boundary and the evidence was in view, so it is not left unknown (it would
    // line every wall with a frontier).
    const float step = 0.5F * map_->cell_m();
    Cell filled{kGridCells, kGridCells};
    for (float r = free_->rho_m(k) + step; r < e - map_->cell_m(); r += step) {
      const Cell f = map_->cell_of(core::to_world(pose_, {r * std::cos(a), r * std::sin(a)}));
      if (f == filled || f == c) continue;
      filled = f;
      (void)map_->add(f, params_.free_delta);
    }
    if (map_->add(c, params_.occupied_delta)) ++occupied_cells_;
  }
}

void sweep_disc(GridMap& map, core::Point2 from, core::Point2 to, float radius_m, int delta) {
  const float lo_x = std::min(from.x_m, to.x_m) - radius_m;
  const float lo_y = std::min(from.y_m, to.y_m) - radius_m;
  const float hi_x = std::max(from.x_m, to.x_m) + radius_m;
  const float hi_y = std::max(from.y_m, to.y_m) + radius_m;
  const Cell lo = map.cell_of({lo_x, lo_y});
  const Cell hi = map.cell_of({hi_x, hi_y});
  const float dx = to.x_m - from.x_m;
  const float dy = to.y_m - from.y_m;
  const float len2 = dx * dx + dy * dy;
  for (int iy = lo.iy; iy <= hi.iy; ++iy) {
    for (int ix = lo.ix; ix <= hi.ix; ++ix) {
      const core::Point2 p = map.centre_of({ix, iy});
      float t = len2 > 0.0F ? ((p.x_m - from.x_m) * dx + (p.y_m - from.y_m) * dy) / len2 : 0.0F;
      t = std::clamp(t, 0.0F, 1.0F);
      const core::Point2 q{from.x_m + t * dx, from.y_m + t * dy};
      if (core::distance_m(p, q) <= radius_m) (void)map.add({ix, iy}, delta);
    }
  }
}

}  // namespace boticelli::worldmap
