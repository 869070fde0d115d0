// GridMap: the mission's world memory, a 2-D occupancy grid of log-odds in square cells (5 cm by
// default), stored in fixed tiles taken from a pool only where a look saw something.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>

#include "algo/core/geometry.h"

namespace boticelli::worldmap {

inline constexpr int kTileCells = 16;       // a tile is kTileCells × kTileCells cells
inline constexpr int kDirectoryTiles = 64;  // the directory spans this many tiles a side
// Cells a side of the whole grid, centred on the mission frame's origin (±25.6 m at 5 cm).
inline constexpr int kGridCells = kTileCells * kDirectoryTiles;
inline constexpr std::size_t kMaxTiles = 1024;  // the pool's capacity (BoardConfig may use less)
inline constexpr int kMaxLogOdds = 60;          // |log-odds| is clamped here (hits dominate)

struct Cell {
  int ix = 0;
  int iy = 0;
};
inline bool operator==(Cell a, Cell b) {
  return a.ix == b.ix && a.iy == b.iy;
}

// One tile in use as a saved state holds it: its place in the directory (tiles from the grid's
// south-west corner) and its cells' log-odds, rows south to north.
struct SavedTile {
  std::int16_t tx = 0;
  std::int16_t ty = 0;
  std::array<std::int8_t, kTileCells * kTileCells> cells{};
};

// What a cell is, from its log-odds (GridMapParams' thresholds).
enum class CellState : std::uint8_t { kUnknown, kFree, kOccupied };

struct GridMapParams {
  float cell_m = 0.05F;               // cell side [m]
  std::size_t max_tiles = kMaxTiles;  // tiles the pool may hand out (≤ kMaxTiles)
  int free_at_most = -2;              // log-odds ≤ this: free
  int occupied_at_least = 4;          // log-odds ≥ this: occupied
};

class GridMap {
 public:
  GridMap() { clear(); }
  GridMap(const GridMap&) = delete;
  GridMap& operator=(const GridMap&) = delete;

  // Sets the parameters (max_tiles clamped to kMaxTiles) and forgets everything.
  void configure(const GridMapParams& params);
  void clear();
  [[nodiscard]] const GridMapParams& params() const { return params_; }
  [[nodiscard]] float cell_m() const { return params_.cell_m; }

  // The cell that holds p (mission frame); its centre.
  [[nodiscard]] Cell cell_of(core::Point2 p) const;
  [[nodiscard]] core::Point2 centre_of(Cell c) const;
  [[nodiscard]] static bool in_bounds(Cell c) {
    return c.ix >= -kGridCells / 2 && c.ix < kGridCells / 2 && c.iy >= -kGridCells / 2 &&
           c.iy < kGridCells / 2;
  }

  // The cell's log-odds: 0 (unknown) where no tile is, or out of bounds.
  [[nodiscard]] int log_odds(Cell c) const;
  [[nodiscard]] CellState state(Cell c) const { return state_of(log_odds(c)); }
  [[nodiscard]] CellState state_of(int log_odds) const {
    if (log_odds <= params_.free_at_most) return CellState::kFree;
    if (log_odds >= params_.occupied_at_least) return CellState::kOccupied;
    return CellState::kUnknown;
  }
  // Adds `delta` to the cell's log-odds, clamped to ±kMaxLogOdds. False when the cell is out
  // of bounds or its tile is missing and the pool is exhausted (dropped() counts those).
  bool add(Cell c, int delta);
  // Whether an occupied cell lies on the segment a→b (sampled every half cell, both ends
  // included): a line of sight the map says is blocked.
  [[nodiscard]] bool segment_blocked(core::Point2 a, core::Point2 b) const;
  // Whether a line of sight from a towards b is clear of occupied cells up to stop_short_m
  // before b (the cells just before a target may be the surface it hangs on); a sight no
  // longer than stop_short_m is clear.
  [[nodiscard]] bool sight_clear(core::Point2 a, core::Point2 b, float stop_short_m) const;

  [[nodiscard]] std::size_t tiles_used() const { return tiles_used_; }
  [[nodiscard]] std::size_t dropped() const { return dropped_; }
  // Cells now free / occupied (kept as cells change: no scan).
  [[nodiscard]] std::size_t free_cells() const { return free_cells_; }
  [[nodiscard]] std::size_t occupied_cells() const { return occupied_cells_; }
  // The smallest cell box holding every tile in use (false when no tile is): what a picture
  // or an export of the map needs to cover. `lo` inclusive, `hi` exclusive.
  bool tile_bounds(Cell& lo, Cell& hi) const;
  // Every tile in use, in directory order (south-west first), into `out` while it has room;
  // returns how many there are (more than were written when `out` is too small).
  std::size_t save_tiles(SavedTile* out, std::size_t capacity) const;
  // Puts a saved tile back (a resumed mission's grid): false, nothing changed, when its place
  // is outside the directory, already has a tile, or the pool is full; a log-odds beyond
  // ±kMaxLogOdds is clamped.
  bool restore_tile(const SavedTile& tile);
  // The map's memory: the tiles in use and the directory [bytes].
  [[nodiscard]] std::size_t bytes() const {
    return tiles_used_ * sizeof(Tile) + sizeof(directory_);
  }

 private:
  using Tile = std::array<std::int8_t, kTileCells * kTileCells>;
  static constexpr std::int16_t kNoTile = -1;
  [[nodiscard]] static std::size_t directory_index(Cell c) {
    const int tx = (c.ix + kGridCells / 2) / kTileCells;
    const int ty = (c.iy + kGridCells / 2) / kTileCells;
    return static_cast<std::size_t>(ty * kDirectoryTiles + tx);
  }
  [[nodiscard]] static std::size_t cell_index(Cell c) {
    const int cx = (c.ix + kGridCells / 2) % kTileCells;
    const int cy = (c.iy + kGridCells / 2) % kTileCells;
    return static_cast<std::size_t>(cy * kTileCells + cx);
  }

  GridMapParams params_{};
  std::array<std::int16_t, kDirectoryTiles * kDirectoryTiles> directory_{};
  std::array<Tile, kMaxTiles> tiles_{};
  std::size_t tiles_used_ = 0;
  std::size_t dropped_ = 0;
  std::size_t free_cells_ = 0;
  std::size_t occupied_cells_ = 0;
};

}  // namespace boticelli::worldmap
