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
  free_cells_ = 0;
  occupied_cells_ = 0;
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
  const CellState before = state_of(v);
  v = static_cast<std::int8_t>(std::clamp(v + delta, -kMaxLogOdds, kMaxLogOdds));
  const CellState after = state_of(v);
  if (after != before) {
    free_cells_ -= before == CellState::kFree ? 1U : 0U;
    occupied_cells_ -= before == CellState::kOccupied ? 1U : 0U;
    free_cells_ += after == CellState::kFree ? 1U : 0U;
    occupied_cells_ += after == CellState::kOccupied ? 1U : 0U;
  }
  return true;
}

std::size_t GridMap::save_tiles(SavedTile* out, std::size_t capacity) const {
  std::size_t n = 0;
  for (std::size_t i = 0; i < directory_.size(); ++i) {
    const std::int16_t t = directory_[i];
    if (t == kNoTile) continue;
    if (n < capacity) {
      SavedTile& s = out[n];
      s.tx = static_cast<std::int16_t>(i % kDirectoryTiles);
      s.ty = static_cast<std::int16_t>(i / kDirectoryTiles);
      s.cells = tiles_[static_cast<std::size_t>(t)];
    }
    ++n;
  }
  return n;
}

bool GridMap::restore_tile(const SavedTile& tile) {
  if (tile.tx < 0 || tile.tx >= kDirectoryTiles || tile.ty < 0 || tile.ty >= kDirectoryTiles) {
    return false;
  }
  std::int16_t& t = directory_[static_cast<std::size_t>(tile.ty) * kDirectoryTiles +
                               static_cast<std::size_t>(tile.tx)];
  if (t != kNoTile || tiles_used_ >= params_.max_tiles) return false;
  t = static_cast<std::int16_t>(tiles_used_++);
  Tile& cells = tiles_[static_cast<std::size_t>(t)];
  for (std::size_t i = 0; i < cells.size(); ++i) {
    cells[i] = static_cast<std::int8_t>(std::clamp<int>(tile.cells[i], -kMaxLogOdds, kMaxLogOdds));
    const CellState state = state_of(cells[i]);
    free_cells_ += state == CellState::kFree ? 1U : 0U;
    occupied_cells_ += state == CellState::kOccupied ? 1U : 0U;
  }
  return true;
}

bool GridMap::segment_blocked(core::Point2 a, core::Point2 b) const {
  const float length = core::distance_m(a, b);
  const int samples = static_cast<int>(std::ceil(length / (0.5F * params_.cell_m)));
  for (int i = 0; i <= samples; ++i) {
    const float t = samples > 0 ? static_cast<float>(i) / static_cast<float>(samples) : 0.0F;
    const core::Point2 p{a.x_m + t * (b.x_m - a.x_m), a.y_m + t * (b.y_m - a.y_m)};
    if (state(cell_of(p)) == CellState::kOccupied) return true;
  }
  return false;
}

bool GridMap::sight_clear(core::Point2 a, core::Point2 b, float stop_short_m) const {
  const float d = core::distance_m(a, b);
  const float keep = d - stop_short_m;
  if (keep <= 0.0F) return true;
  const core::Point2 end{a.x_m + (b.x_m - a.x_m) * keep / d, a.y_m + (b.y_m - a.y_m) * keep / d};
  return !segment_blocked(a, end);
}

bool GridMap::tile_bounds(Cell& lo, Cell& hi) const {
  int tx0 = kDirectoryTiles, ty0 = kDirectoryTiles, tx1 = -1, ty1 = -1;
  for (int ty = 0; ty < kDirectoryTiles; ++ty) {
    for (int tx = 0; tx < kDirectoryTiles; ++tx) {
      if (directory_[static_cast<std::size_t>(ty * kDirectoryTiles + tx)] == kNoTile) continue;
      tx0 = std::min(tx0, tx);
      ty0 = std::min(ty0, ty);
      tx1 = std::max(tx1, tx);
      ty1 = std::max(ty1, ty);
    }
  }
  if (tx1 < 0) return false;
  lo = {tx0 * kTileCells - kGridCells / 2, ty0 * kTileCells - kGridCells / 2};
  hi = {(tx1 + 1) * kTileCells - kGridCells / 2, (ty1 + 1) * kTileCells - kGridCells / 2};
  return true;
}

}  // namespace boticelli::worldmap
