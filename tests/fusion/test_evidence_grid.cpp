// Tests of the log-odds evidence grid baseline: voxel walk, free and occupied updates.
#include <cmath>

#include "algo/core/angles.h"
#include "algo/evidence/reading.h"
#include "algo/fusion/evidence_grid.h"
#include "alloc_guard.h"
#include "CppUTest/TestHarness.h"

using namespace boticelli;
using namespace boticelli::fusion;

namespace {
// 4 x 4 x 2 m at 0.1 m, centred on the sensor at the origin.
using Grid = EvidenceGrid<40, 40, 20>;
const GridBox kBox{{-2.0F, -2.0F, -1.0F}, 0.1F};
}  // namespace

TEST_GROUP(EvidenceGrid) {
  Grid grid{kBox};
  const GridPoint sensor{0.05F, 0.05F, 0.05F};
};

TEST(EvidenceGrid, StartsUnknownAndUnknownIsNotFree) {
  DOUBLES_EQUAL(0.5, grid.occupancy_at({1.0F, 1.0F, 0.0F}), 1e-6);
  CHECK_FALSE(grid.is_free({1.0F, 1.0F, 0.0F}));
}

TEST(EvidenceGrid, AHorizontalRayFreesTheCellsBeforeThePointAndMarksThePoint) {
  // α = 0, h = 0, r = 1.5 m: along +x; δr = 0.15 m.
  const std::size_t updated = grid.integrate(sensor, {0.0F, 0.0F, 1.5F, 0.9F});
  // Cells x = 0.0..1.7 are crossed (the walk stops at r + δr = 1.65 m from 0.05).
  LONGS_EQUAL(17, updated);
  CHECK(grid.is_free({0.5F, 0.05F, 0.05F}));
  CHECK(grid.is_free({1.25F, 0.05F, 0.05F}));
  DOUBLES_EQUAL(0.9, grid.occupancy_at({1.55F, 0.05F, 0.05F}), 1e-5);
  DOUBLES_EQUAL(0.9, grid.occupancy_at({1.65F, 0.05F, 0.05F}), 1e-5);
  // Behind r + δr and beside the ray nothing is known.
  DOUBLES_EQUAL(0.5, grid.occupancy_at({1.85F, 0.05F, 0.05F}), 1e-6);
  DOUBLES_EQUAL(0.5, grid.occupancy_at({0.5F, 0.35F, 0.05F}), 1e-6);
}

TEST(EvidenceGrid, TheSameReadingTwiceRaisesConfidenceAsLogOddsAdd) {
  const evidence::Reading reading{0.0F, 0.0F, 1.5F, 0.6F};
  (void)grid.integrate(sensor, reading);
  (void)grid.integrate(sensor, reading);
  // §4.4.2: 0.6 twice becomes 0.69 in the grid, the independence assumption at work.
  DOUBLES_EQUAL(0.36 / 0.52, grid.occupancy_at({1.55F, 0.05F, 0.05F}), 1e-5);
}

TEST(EvidenceGrid, ADiagonalRayVisitsAConnectedChainOfCells) {
  // α = 45°, rising: the walk must step one face at a time, never skipping a cell, so the
  // number of cells is (cells crossed in x) + (in y) + (in z) + 1.
  const float r = 1.5F;
  const float h = 0.5F;
  const float alpha = core::deg_to_rad(45.0F);
  const std::size_t updated = grid.integrate({0.05F, 0.05F, 0.05F}, {alpha, h, r, 0.9F});
  const float t_end = 1.1F * r;
  const float rho = std::sqrt(r * r - h * h) / r * t_end;
  const float x_end = 0.05F + rho * std::cos(alpha);
  const float z_end = 0.05F + h / r * t_end;
  const auto cx = static_cast<std::size_t>(std::floor(x_end / 0.1F));
  const auto cz = static_cast<std::size_t>(std::floor(z_end / 0.1F));
  LONGS_EQUAL(cx + cx + cz + 1, updated);
  CHECK(grid.is_free({0.5F, 0.5F, 0.05F + 0.5F * std::sqrt(2.0F) * h / std::sqrt(r * r - h * h)}));
}

TEST(EvidenceGrid, RaysLeavingTheBoxAreClippedAndRaysOutsideAreIgnored) {
  const std::size_t updated = grid.integrate(sensor, {core::kPi<float>, 0.0F, 4.0F, 0.9F});
  LONGS_EQUAL(21, updated);  // cells x = 0.0 down to −2.0
  LONGS_EQUAL(0, grid.integrate({5.0F, 5.0F, 5.0F}, {0.0F, 0.0F, 1.0F, 0.9F}));
}

TEST(EvidenceGrid, IntegratingDoesNotAllocate) {
  std::size_t updated = 0;
  CHECK_NO_ALLOCATION(for (int i = 0; i < 100; ++i) {
    updated += grid.integrate(sensor, {0.06F * static_cast<float>(i), 0.2F, 1.8F, 0.8F});
  });
  CHECK(updated > 1000);
}
