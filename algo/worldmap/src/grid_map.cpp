// GridMap: tiled log-odds occupancy grid (see grid_map.h).
#include "algo/worldmap/grid_map.h"

#include <algorithm>
#include <cmath>

namespace boticelli::worldmap {

void GridMap::configure(const GridMapParams& params) {
  params_ = params;
  params_.max_tiles = std::min(params_.max_tiles, kMaxTiles);
  clear();
}

void GridMap::clear() {
  directory_.fill(kNoTile);
  tiles_used_ = 0;
  dropped_ = 0;
}

Cell GridMap::cell_of(core::Point2 p) const {
  return {static_cast<int>(std::floor(p.x_m / params_.cell_m)),
          static_cast<int>(std::floor(p.y_m / params_.cell_m))};
}

core::Point2 GridMap::centre_of(Cell c) const {
  return {(static_cast<float>(c.ix) + 0.5F) * params_.cell_m,
          (static_cast<float>(c.iy) + 0.5F) * params_.cell_m};
}

int GridMap::log_odds(Cell c) const {
  if (!in_bounds(c)) return 0;
  const std::int16_t t = directory_[directory_index(c)];
  if (t == kNoTile) return 0;
  return tiles_[static_cast<std::size_t>(t)][cell_index(c)];
}

bool GridMap::add(Cell c, int delta) {
  if (!in_bounds(c)) {
    ++dropped_;
    return false;
  }
  std::int16_t& t = directory_[directory_index(c)];
  if (t == kNoTile) {
    if (tiles_used_ >= params_.max_tiles) {
      ++dropped_;
      return false;
    }
    t = static_cast<std::int16_t>(tiles_used_++);
    tiles_[static_cast<std::size_t>(t)].fill(0);
  }
  std::int8_t& v = tiles_[static_cast<std::size_t>(t)][cell_index(c)];
  v = static_cast<std::int8_t>(std::clamp(v + delta, -kMaxLogOdds, kMaxLogOdds));
  return true;
}

}  // namespace boticelli::worldmap
