// 3-D log-odds evidence grid over a bounded box: the baseline the thesis argues against.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>

#include "algo/evidence/reading.h"

namespace boticelli::fusion {

// A point in the grid's frame [m]: x, y on the floor plane, z up.
struct GridPoint {
  float x_m = 0.0F;
  float y_m = 0.0F;
  float z_m = 0.0F;
};

// Where the grid lies: the corner with the smallest coordinates and the cell edge.
struct GridBox {
  GridPoint min_corner{};
  float cell_m = 0.1F;
};

// The grid form of the visual sensor model (Fig 4.2a: one update per cell on the ray).
// A cell whose stretch of the ray ends before r − δr gets free evidence, a cell that the
// ray crosses within [r − δr, r + δr] gets occupied evidence log-odds(m) (Eq 4.15 adds
// them); nothing is said behind r + δr. δr = delta_r_fraction · r as in §3.7.3.
struct GridSensorModel {
  float free_occupancy = 0.3F;    // occupancy a fully trusted ray gives to a cell it passes
  float delta_r_fraction = 0.1F;  // δr / r
  float log_odds_limit = 8.0F;    // clamp so that a cell can still change its mind
};

// The logic of the grid; storage comes from EvidenceGrid<NX, NY, NZ>.
class EvidenceGridBase {
 public:
  EvidenceGridBase(const EvidenceGridBase&) = delete;
  EvidenceGridBase& operator=(const EvidenceGridBase&) = delete;

  void set_box(const GridBox& box) { box_ = box; }
  [[nodiscard]] const GridBox& box() const { return box_; }
  void set_sensor_model(const GridSensorModel& model) { model_ = model; }
  // Every cell back to unknown (log-odds 0, occupancy 0.5).
  void clear();

  // Integrates one reading taken by a sensor at `sensor` (the PTU centre, grid frame);
  // the reading's (α, h, r) are about that centre. Walks the voxels of the ray (Amanatides
  // & Woo, 1987) and returns how many cells it updated.
  std::size_t integrate(const GridPoint& sensor, const evidence::Reading& reading);

  // Log-odds of the cell holding the point; 0 (unknown) outside the box.
  [[nodiscard]] float log_odds_at(const GridPoint& p) const;
  // Occupancy probability of that cell (Eq 4.15 inverted).
  [[nodiscard]] float occupancy_at(const GridPoint& p) const;
  // Free: more free than occupied evidence (log-odds < 0). Unknown cells are not free.
  [[nodiscard]] bool is_free(const GridPoint& p) const { return log_odds_at(p) < 0.0F; }

  [[nodiscard]] std::size_t cells() const { return nx_ * ny_ * nz_; }
  [[nodiscard]] std::size_t nx() const { return nx_; }
  [[nodiscard]] std::size_t ny() const { return ny_; }
  [[nodiscard]] std::size_t nz() const { return nz_; }

 protected:
  EvidenceGridBase(float* cells, std::size_t nx, std::size_t ny, std::size_t nz)
      : cells_(cells), nx_(nx), ny_(ny), nz_(nz) {}
  ~EvidenceGridBase() = default;

 private:
  void add(std::size_t index, float log_odds);
  float* cells_;
  std::size_t nx_;
  std::size_t ny_;
  std::size_t nz_;
  GridBox box_{};
  GridSensorModel model_{};
};

namespace detail {
// Holds the cells; a base listed before EvidenceGridBase so it is built first.
template <std::size_t Cells>
struct GridStorage {
  std::array<float, Cells> cells_storage_{};
};
}  // namespace detail

// Statically sized: EvidenceGrid<50, 50, 20> covers 5 x 5 x 2 m at 0.1 m (50,000 cells).
template <std::size_t NX, std::size_t NY, std::size_t NZ>
class EvidenceGrid final : private detail::GridStorage<NX * NY * NZ>, public EvidenceGridBase {
  static_assert(NX > 0 && NY > 0 && NZ > 0, "a grid needs cells");

 public:
  explicit EvidenceGrid(const GridBox& box = {})
      : EvidenceGridBase(this->cells_storage_.data(), NX, NY, NZ) {
    set_box(box);
    clear();
  }
};

}  // namespace boticelli::fusion
