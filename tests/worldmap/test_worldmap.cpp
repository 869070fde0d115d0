// Tests of the world memory: grid, look fusion, clearance, wavefront, frontiers and goals.
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <limits>
#include <random>
#include <vector>

#include "algo/mapping/star_polygon.h"
#include "algo/worldmap/grid_map.h"
#include "algo/worldmap/look_fusion.h"
#include "algo/worldmap/nav_planner.h"

#include "CppUTest/TestHarness.h"
#include "alloc_guard.h"

using boticelli::core::Point2;
using boticelli::core::Pose2;
namespace mapping = boticelli::mapping;
namespace wm = boticelli::worldmap;

namespace {

wm::GridMap g_map;
wm::NavPlanner g_nav;
wm::LookFusion g_fusion;

constexpr int kFreeLo = -20;  // log-odds written for free / occupied cells in test maps
constexpr int kOccHi = 20;

void set_cell(int ix, int iy, wm::CellState s) {
  const int now = g_map.log_odds({ix, iy});
  const int want = s == wm::CellState::kFree ? kFreeLo : s == wm::CellState::kOccupied ? kOccHi : 0;
  (void)g_map.add({ix, iy}, want - now);
}

// A random map in the square [−half, half) cells: blobs of free and occupied cells, unknown
// elsewhere; the robot's cell free.
void random_map(std::uint32_t seed, int half) {
  g_map.configure({});
  std::mt19937 rng(seed);
  std::uniform_int_distribution<int> u(-half, half - 1);
  std::uniform_int_distribution<int> pick(0, 9);
  for (int iy = -half; iy < half; ++iy) {
    for (int ix = -half; ix < half; ++ix) {
      const int p = pick(rng);
      set_cell(ix, iy, p < 7 ? wm::CellState::kFree : wm::CellState::kUnknown);
    }
  }
  for (int k = 0; k < half / 2; ++k) set_cell(u(rng), u(rng), wm::CellState::kOccupied);
  for (int k = 0; k < half / 4; ++k) {  // unknown holes
    const int cx = u(rng);
    const int cy = u(rng);
    for (int dy = -2; dy <= 2; ++dy) {
      for (int dx = -2; dx <= 2; ++dx) set_cell(cx + dx, cy + dy, wm::CellState::kUnknown);
    }
  }
  set_cell(0, 0, wm::CellState::kFree);
}

// Chamfer 5-7 distance from (x, y) to the nearest occupied cell, by brute force.
int brute_clearance(int x, int y, int half) {
  int best = 0xFFFF;
  for (int iy = -half - 1; iy <= half; ++iy) {
    for (int ix = -half - 1; ix <= half; ++ix) {
      if (g_map.state({ix, iy}) != wm::CellState::kOccupied) continue;
      const int dx = std::abs(ix - x);
      const int dy = std::abs(iy - y);
      best = std::min(best, 7 * std::min(dx, dy) + 5 * (std::max(dx, dy) - std::min(dx, dy)));
    }
  }
  return best;
}

}  // namespace

TEST_GROUP(GridMap){void setup() override{g_map.configure({});
}
}
;

TEST(GridMap, AnUntouchedCellIsUnknownAndTakesNoMemory) {
  CHECK(g_map.state({3, -7}) == wm::CellState::kUnknown);
  LONGS_EQUAL(0, g_map.tiles_used());
  LONGS_EQUAL(sizeof(std::int16_t) * wm::kDirectoryTiles * wm::kDirectoryTiles, g_map.bytes());
}

TEST(GridMap, LogOddsCrossTheThresholdsAndAreClamped) {
  CHECK(g_map.add({1, 1}, -1));
  CHECK(g_map.state({1, 1}) == wm::CellState::kUnknown);
  CHECK(g_map.add({1, 1}, -1));
  CHECK(g_map.state({1, 1}) == wm::CellState::kFree);
  CHECK(g_map.add({1, 1}, 5));
  CHECK(g_map.state({1, 1}) == wm::CellState::kUnknown);
  CHECK(g_map.add({1, 1}, 1));
  CHECK(g_map.state({1, 1}) == wm::CellState::kOccupied);
  CHECK(g_map.add({1, 1}, 1000));
  LONGS_EQUAL(wm::kMaxLogOdds, g_map.log_odds({1, 1}));
  CHECK(g_map.add({1, 1}, -1000));
  LONGS_EQUAL(-wm::kMaxLogOdds, g_map.log_odds({1, 1}));
}

TEST(GridMap, CellsOfOneTileShareItAndNeighboursDoNotAlias) {
  CHECK(g_map.add({0, 0}, 7));
  CHECK(g_map.add({wm::kTileCells - 1, wm::kTileCells - 1}, -7));
  LONGS_EQUAL(1, g_map.tiles_used());
  CHECK(g_map.add({-1, 0}, 9));
  LONGS_EQUAL(2, g_map.tiles_used());
  LONGS_EQUAL(7, g_map.log_odds({0, 0}));
  LONGS_EQUAL(9, g_map.log_odds({-1, 0}));
  LONGS_EQUAL(-7, g_map.log_odds({wm::kTileCells - 1, wm::kTileCells - 1}));
  LONGS_EQUAL(0, g_map.log_odds({wm::kTileCells, 0}));
}

TEST(GridMap, AnExhaustedPoolOrACellOutsideTheGridIsDroppedAndCounted) {
  wm::GridMapParams p;
  p.max_tiles = 2;
  g_map.configure(p);
  CHECK(g_map.add({0, 0}, 1));
  CHECK(g_map.add({100, 0}, 1));
  CHECK_FALSE(g_map.add({200, 0}, 1));
  CHECK_FALSE(g_map.add({wm::kGridCells, 0}, 1));
  LONGS_EQUAL(2, g_map.dropped());
  LONGS_EQUAL(2, g_map.tiles_used());
}

TEST(GridMap, TheFreeAndOccupiedCountsMatchAScanOfEveryCell) {
  std::uint64_t rng = 7;
  for (int i = 0; i < 4000; ++i) {
    rng = rng * 6364136223846793005ULL + 1442695040888963407ULL;
    const wm::Cell c{static_cast<int>((rng >> 33) % 90) - 45,
                     static_cast<int>((rng >> 45) % 90) - 45};
    (void)g_map.add(c, static_cast<int>((rng >> 20) % 13) - 6);
  }
  std::size_t free = 0, occupied = 0;
  for (int iy = -48; iy < 48; ++iy) {
    for (int ix = -48; ix < 48; ++ix) {
      free += g_map.state({ix, iy}) == wm::CellState::kFree ? 1U : 0U;
      occupied += g_map.state({ix, iy}) == wm::CellState::kOccupied ? 1U : 0U;
    }
  }
  CHECK(free > 100 && occupied > 100);
  LONGS_EQUAL(free, g_map.free_cells());
  LONGS_EQUAL(occupied, g_map.occupied_cells());
  wm::Cell lo, hi;
  CHECK(g_map.tile_bounds(lo, hi));
  LONGS_EQUAL(-48, lo.ix);
  LONGS_EQUAL(-48, lo.iy);
  LONGS_EQUAL(48, hi.ix);
  LONGS_EQUAL(48, hi.iy);
  g_map.clear();
  LONGS_EQUAL(0, g_map.free_cells());
  CHECK_FALSE(g_map.tile_bounds(lo, hi));
}

TEST(GridMap, ASegmentIsBlockedOnlyByAnOccupiedCellOnIt) {
  CHECK(g_map.add(g_map.cell_of({1.0F, 0.02F}), 10));
  CHECK(g_map.add(g_map.cell_of({1.0F, 0.5F}), -10));
  CHECK(g_map.segment_blocked({0.0F, 0.0F}, {2.0F, 0.05F}));
  CHECK_FALSE(g_map.segment_blocked({0.0F, 0.0F}, {0.97F, 0.0F}));
  CHECK_FALSE(g_map.segment_blocked({0.0F, 0.2F}, {2.0F, 0.2F}));
  CHECK(g_map.segment_blocked({1.0F, 0.0F}, {1.0F, 0.0F}));
}

// A line of sight stops short of its end by the margin (the surface a target hangs on), in
// its own direction: an occupied cell off the line, or mirrored across either axis, does not
// block it.
TEST(GridMap, ASightIsClearUnlessAnOccupiedCellLiesOnItBeforeTheMarginAtItsEnd) {
  const Point2 from{0.5F, 0.25F};
  const Point2 to{2.5F, 1.25F};  // 2.24 m away, up and to the right
  CHECK(g_map.sight_clear(from, to, 0.3F));
  CHECK(g_map.add(g_map.cell_of({2.4F, 1.2F}), 10));  // within the margin: the wall itself
  CHECK(g_map.sight_clear(from, to, 0.3F));
  CHECK_FALSE(g_map.sight_clear(from, to, 0.05F));
  // Cells where a mirrored line would run: below the start, left of it.
  CHECK(g_map.add(g_map.cell_of({1.5F, -0.25F}), 10));
  CHECK(g_map.add(g_map.cell_of({-0.5F, 0.75F}), 10));
  CHECK(g_map.sight_clear(from, to, 0.3F));
  CHECK(g_map.add(g_map.cell_of({1.5F, 0.75F}), 10));  // on the line, halfway
  CHECK_FALSE(g_map.sight_clear(from, to, 0.3F));
  CHECK(g_map.sight_clear(from, {1.5F, 0.75F}, 1.2F));  // shorter than the margin: clear
}

TEST(GridMap, PointsMapToTheCellsThatHoldThem) {
  const wm::Cell c = g_map.cell_of({-0.01F, 0.07F});
  LONGS_EQUAL(-1, c.ix);
  LONGS_EQUAL(1, c.iy);
  const Point2 m = g_map.centre_of(c);
  DOUBLES_EQUAL(-0.025, m.x_m, 1e-6);
  DOUBLES_EQUAL(0.075, m.y_m, 1e-6);
}

TEST_GROUP(LookFusion){void setup() override{g_map.configure({});
}
}
;

TEST(LookFusion, TheFreePolygonIsFreeAndTheEvidenceBehindItsBoundaryOccupied) {
  mapping::StarPolygon free(360);
  free.fill(1.0F);
  mapping::StarPolygon evidence(360);
  evidence.fill(std::numeric_limits<float>::infinity());
  for (std::size_t k = 80; k < 100; ++k) evidence.set_rho_m(k, 1.32F);  // a wall to +y
  const Pose2 pose{2.0F, -1.0F, 0.0F};
  g_fusion.start(g_map, pose, free, evidence, {});
  CHECK_NO_ALLOCATION(g_fusion.run());
  CHECK(g_map.state(g_map.cell_of({2.0F, -1.0F})) == wm::CellState::kFree);
  CHECK(g_map.state(g_map.cell_of({2.6F, -0.5F})) == wm::CellState::kFree);
  CHECK(g_map.state(g_map.cell_of({3.2F, -1.0F})) == wm::CellState::kUnknown);
  CHECK(g_map.state(g_map.cell_of({2.0F, 0.32F})) == wm::CellState::kOccupied);
  // The strip between the polygon's boundary (1 m) and the evidence (1.32 m) was in view.
  CHECK(g_map.state(g_map.cell_of({2.0F, 0.17F})) == wm::CellState::kFree);
  CHECK(g_map.state(g_map.cell_of({2.0F, -2.3F})) == wm::CellState::kUnknown);
  CHECK(g_fusion.free_cells() > 1000);
  CHECK(g_fusion.occupied_cells() >= 2);
}

TEST(LookFusion, EvidenceFarBeyondACollapsedPolygonAddsNoObstacle) {
  mapping::StarPolygon free(360);
  free.fill(0.3F);  // the fit left a disc round the robot
  mapping::StarPolygon evidence(360);
  evidence.fill(2.0F);
  g_fusion.start(g_map, {0.0F, 0.0F, 0.5F}, free, evidence, {});
  g_fusion.run();
  LONGS_EQUAL(0, g_fusion.occupied_cells());
  CHECK(g_map.state(g_map.cell_of({2.0F, 0.0F})) == wm::CellState::kUnknown);
}

TEST(LookFusion, TheRobotsSweptDiscIsFree) {
  wm::sweep_disc(g_map, {0.0F, 0.0F}, {1.0F, 0.0F}, 0.2F, -3);
  CHECK(g_map.state(g_map.cell_of({0.5F, 0.15F})) == wm::CellState::kFree);
  CHECK(g_map.state(g_map.cell_of({1.15F, 0.0F})) == wm::CellState::kFree);
  CHECK(g_map.state(g_map.cell_of({0.5F, 0.3F})) == wm::CellState::kUnknown);
}

TEST_GROUP(NavPlanner){void setup() override{g_nav.reset();
}
}
;

TEST(NavPlanner, ClearanceAndPathCostMatchBruteForceOnRandomMaps) {
  constexpr int kHalf = 24;
  for (std::uint32_t seed = 1; seed <= 3; ++seed) {
    random_map(seed, kHalf);
    wm::NavParams p;
    p.robot_radius_m = 0.1F;  // 2 cells
    p.clearance_m = 0.05F;
    g_nav.start(g_map, {0.01F, 0.01F}, p);
    CHECK_NO_ALLOCATION(g_nav.run());
    // The reference: passable cells by brute-force clearance, then Bellman-Ford relaxation
    // with the same moves, costs and rules.
    const int n = 2 * kHalf + 2;
    auto idx = [&](int x, int y) {
      return static_cast<std::size_t>((y + kHalf + 1) * n + (x + kHalf + 1));
    };
    std::vector<int> clear(static_cast<std::size_t>(n * n));
    std::vector<bool> free(static_cast<std::size_t>(n * n));
    for (int y = -kHalf - 1; y <= kHalf; ++y) {
      for (int x = -kHalf - 1; x <= kHalf; ++x) {
        clear[idx(x, y)] = brute_clearance(x, y, kHalf);
        free[idx(x, y)] = g_map.state({x, y}) == wm::CellState::kFree;
        const bool passable = free[idx(x, y)] && clear[idx(x, y)] >= 10;
        CHECK_EQUAL(passable, g_nav.passable(g_map.centre_of({x, y})));
      }
    }
    constexpr std::uint32_t kInf = 0xFFFFFFFFU;
    std::vector<std::uint32_t> cost(static_cast<std::size_t>(n * n), kInf);
    cost[idx(0, 0)] = 0;
    for (bool changed = true; changed;) {
      changed = false;
      for (int y = -kHalf; y < kHalf; ++y) {
        for (int x = -kHalf; x < kHalf; ++x) {
          const std::uint32_t c0 = cost[idx(x, y)];
          if (c0 == kInf) continue;
          const bool from_ok = (free[idx(x, y)] && clear[idx(x, y)] >= 10) || c0 > 20;
          for (int dy = -1; dy <= 1; ++dy) {
            for (int dx = -1; dx <= 1; ++dx) {
              if (dx == 0 && dy == 0) continue;
              const std::size_t j = idx(x + dx, y + dy);
              const bool to_ok = free[j] && clear[j] >= 10;
              const bool occupied = g_map.state({x + dx, y + dy}) == wm::CellState::kOccupied;
              if (!to_ok && (from_ok || occupied || clear[j] < clear[idx(x, y)])) continue;
              std::uint32_t step = dx != 0 && dy != 0 ? 14 : 10;
              if (clear[j] < 15) step *= 2;
              if (c0 + step < cost[j]) {
                cost[j] = c0 + step;
                changed = true;
              }
            }
          }
        }
      }
    }
    for (int y = -kHalf; y < kHalf; ++y) {
      for (int x = -kHalf; x < kHalf; ++x) {
        const float got = g_nav.path_m(g_map.centre_of({x, y}));
        const std::uint32_t want = cost[idx(x, y)];
        if (want == kInf) {
          CHECK(std::isinf(got));
        } else {
          DOUBLES_EQUAL(static_cast<double>(want) * 0.005, got, 1e-4);
        }
      }
    }
  }
}

TEST(NavPlanner, FrontiersAreTheReachableClustersOfFreeCellsBesideUnknownOnes) {
  constexpr int kHalf = 24;
  for (std::uint32_t seed = 4; seed <= 6; ++seed) {
    random_map(seed, kHalf);
    wm::NavParams p;
    p.robot_radius_m = 0.05F;
    p.wall_fringe_m = 0.1F;
    p.min_frontier_m = 0.2F;
    p.wall_reach_m = 100.0F;  // every frontier cell counts whole
    g_nav.start(g_map, {0.01F, 0.01F}, p);
    g_nav.run();
    // Reference: frontier cells by the definition, 8-connected components by union-find.
    const int n = 2 * kHalf;
    auto id = [&](int x, int y) { return static_cast<std::size_t>((y + kHalf) * n + (x + kHalf)); };
    std::vector<std::size_t> parent(static_cast<std::size_t>(n * n));
    std::vector<bool> frontier(static_cast<std::size_t>(n * n), false);
    const auto cells = static_cast<std::size_t>(n * n);
    for (std::size_t i = 0; i < cells; ++i) parent[i] = i;
    auto find = [&](std::size_t a) {
      while (parent[a] != a) a = parent[a] = parent[parent[a]];
      return a;
    };
    auto unknown = [&](int x, int y) { return g_map.state({x, y}) == wm::CellState::kUnknown; };
    for (int y = -kHalf; y < kHalf; ++y) {
      for (int x = -kHalf; x < kHalf; ++x) {
        const Point2 c = g_map.centre_of({x, y});
        (void)c;
        frontier[id(x, y)] =
            g_map.state({x, y}) == wm::CellState::kFree && brute_clearance(x, y, kHalf) >= 10 &&
            (unknown(x - 1, y) || unknown(x + 1, y) || unknown(x, y - 1) || unknown(x, y + 1));
      }
    }
    for (int y = -kHalf; y < kHalf; ++y) {
      for (int x = -kHalf; x < kHalf; ++x) {
        if (!frontier[id(x, y)]) continue;
        for (int dy = -1; dy <= 1; ++dy) {
          for (int dx = -1; dx <= 1; ++dx) {
            const int nx = x + dx;
            const int ny = y + dy;
            if (nx < -kHalf || nx >= kHalf || ny < -kHalf || ny >= kHalf) continue;
            if (frontier[id(nx, ny)]) parent[find(id(x, y))] = find(id(nx, ny));
          }
        }
      }
    }
    std::vector<int> size(static_cast<std::size_t>(n * n), 0);
    std::vector<bool> reachable(static_cast<std::size_t>(n * n), false);
    for (int y = -kHalf; y < kHalf; ++y) {
      for (int x = -kHalf; x < kHalf; ++x) {
        if (!frontier[id(x, y)]) continue;
        const std::size_t root = find(id(x, y));
        ++size[root];
        const Point2 c = g_map.centre_of({x, y});
        if (g_nav.passable(c) && std::isfinite(g_nav.path_m(c))) reachable[root] = true;
      }
    }
    std::vector<int> want;
    for (std::size_t i = 0; i < cells; ++i) {
      if (size[i] >= 4 && reachable[i]) want.push_back(size[i]);  // 0.2 m of 5 cm cells
    }
    std::vector<int> got;
    for (const wm::Frontier& f : g_nav.frontiers()) {
      got.push_back(static_cast<int>(std::lround(f.length_m / 0.05F)));
      CHECK(std::isfinite(f.path_m));
      DOUBLES_EQUAL(f.length_m - f.path_m, f.utility, 1e-4);
      CHECK(f.length_m > 0.0F);
    }
    std::sort(want.begin(), want.end());
    std::sort(got.begin(), got.end());
    CHECK(!want.empty());
    CHECK(want == got);
  }
}

namespace {

// A corridor 1.5 m wide along +x from the robot, free for `free_to_m`, unknown beyond; walls
// (occupied) on both sides.
void corridor(float free_to_m) {
  g_map.configure({});
  const int end = static_cast<int>(free_to_m / 0.05F);
  for (int ix = -10; ix < end; ++ix) {
    for (int iy = -15; iy <= 15; ++iy) set_cell(ix, iy, wm::CellState::kFree);
    set_cell(ix, -16, wm::CellState::kOccupied);
    set_cell(ix, 16, wm::CellState::kOccupied);
  }
  for (int iy = -16; iy <= 16; ++iy) set_cell(-11, iy, wm::CellState::kOccupied);
}

}  // namespace

TEST(NavPlanner, TheGoalIsTheCorridorsOpenEndAndThePathLeadsThere) {
  corridor(3.0F);
  g_nav.start(g_map, {0.0F, 0.0F}, {});
  g_nav.run();
  const wm::NavChoice c = g_nav.choose(nullptr, 0.75F);
  CHECK(c.kind == wm::NavGoalKind::kFrontier);
  DOUBLES_EQUAL(2.97, c.goal.x_m, 0.06);
  DOUBLES_EQUAL(0.0, c.goal.y_m, 0.1);
  CHECK(g_nav.path().size() > 10);
  DOUBLES_EQUAL(0.0, g_nav.path()[0].x_m, 0.05);
  const Point2 last = g_nav.path()[g_nav.path().size() - 1];
  DOUBLES_EQUAL(c.goal.x_m, last.x_m, 1e-6);
  for (const Point2& q : g_nav.path()) CHECK(g_nav.passable(q));
}

TEST(NavPlanner, AClosedRoomLeavesNothingToExplore) {
  corridor(3.0F);
  for (int iy = -16; iy <= 16; ++iy) set_cell(60, iy, wm::CellState::kOccupied);
  g_nav.start(g_map, {0.0F, 0.0F}, {});
  g_nav.run();
  CHECK(g_nav.frontiers().empty());
  CHECK(g_nav.choose(nullptr, 0.75F).kind == wm::NavGoalKind::kNone);
}

TEST(NavPlanner, AGoalThatStopsGettingNearerIsBlacklisted) {
  corridor(3.0F);
  wm::NavParams p;
  p.progress_plans = 3;
  bool blacklisted = false;
  for (int plan = 0; plan <= 3; ++plan) {  // the goal set, then three plans no nearer
    g_nav.start(g_map, {0.0F, 0.0F}, p);
    g_nav.run();
    const wm::NavChoice c = g_nav.choose(nullptr, 0.75F);
    blacklisted = blacklisted || c.blacklisted;
  }
  CHECK(blacklisted);
  LONGS_EQUAL(1, g_nav.blacklist().size());
  // The only frontier is blacklisted: nothing reachable is left to explore.
  g_nav.start(g_map, {0.0F, 0.0F}, p);
  g_nav.run();
  CHECK(g_nav.choose(nullptr, 0.75F).kind == wm::NavGoalKind::kNone);
}

TEST(NavPlanner, AGoalGettingNearerIsKept) {
  corridor(3.0F);
  wm::NavParams p;
  p.progress_plans = 2;
  for (int plan = 0; plan < 5; ++plan) {
    g_nav.start(g_map, {0.4F * static_cast<float>(plan), 0.0F}, p);
    g_nav.run();
    const wm::NavChoice c = g_nav.choose(nullptr, 0.75F);
    CHECK(c.kind == wm::NavGoalKind::kFrontier);
    CHECK_FALSE(c.blacklisted);
  }
  LONGS_EQUAL(0, g_nav.blacklist().size());
}

TEST(NavPlanner, TheTargetsGoalIsTheNearestReachableCellAtTheStandOff) {
  corridor(3.0F);
  const Point2 target{2.5F, 0.8F};  // on the corridor's wall
  g_nav.start(g_map, {0.0F, 0.0F}, {});
  g_nav.run();
  const wm::NavChoice c = g_nav.choose(&target, 0.75F);
  CHECK(c.kind == wm::NavGoalKind::kTarget);
  const float d = boticelli::core::distance_m(c.goal, target);
  CHECK(d <= 0.75F + 1e-4F);
  CHECK(d >= 0.45F - 1e-4F);
  CHECK(c.goal.x_m < 2.5F);  // the near side: the cheapest
  CHECK(g_nav.passable(c.goal));
}

TEST(NavPlanner, AnUnreachableTargetLeavesTheFrontiersAsGoal) {
  corridor(3.0F);
  const Point2 target{2.5F, 3.0F};  // beyond the wall
  g_nav.start(g_map, {0.0F, 0.0F}, {});
  g_nav.run();
  CHECK(g_nav.choose(&target, 0.75F).kind == wm::NavGoalKind::kFrontier);
}

TEST(NavPlanner, ARobotInsideAWallsClearanceFindsItsWayOut) {
  corridor(3.0F);
  g_nav.start(g_map, {1.0F, 0.7F}, {});  // 0.1 m from the wall: its disc touches it
  g_nav.run();
  CHECK_FALSE(g_nav.passable({1.0F, 0.7F}));
  CHECK(std::isfinite(g_nav.path_m({2.0F, 0.0F})));
  CHECK(std::isinf(g_nav.path_m({1.0F, 0.78F})));  // never into the wall
}

TEST(NavPlanner, AFrontierOnOpenFloorFarFromAnyWallCountsLessOfItsLength) {
  g_map.configure({});
  for (int iy = -20; iy <= 20; ++iy) {
    for (int ix = -20; ix <= 20; ++ix) set_cell(ix, iy, wm::CellState::kFree);
  }
  set_cell(-60, 0, wm::CellState::kOccupied);  // 3 m from the nearest frontier cell
  wm::NavParams p;
  p.wall_reach_m = 1.0F;
  p.open_floor_weight = 0.25F;
  g_nav.start(g_map, {0.0F, 0.0F}, p);
  g_nav.run();
  LONGS_EQUAL(1, g_nav.frontiers().size());
  // 160 cells round the 41 × 41 square's edge, all on open floor.
  DOUBLES_EQUAL(160 * 0.05 * 0.25, g_nav.frontiers()[0].length_m, 1e-3);
  p.wall_reach_m = 5.0F;  // the one occupied cell is near enough to all of them
  g_nav.start(g_map, {0.0F, 0.0F}, p);
  g_nav.run();
  DOUBLES_EQUAL(160 * 0.05, g_nav.frontiers()[0].length_m, 1e-3);
}

TEST(NavPlanner, ChoosingOnlyTheTargetLeavesTheFrontierGoalAlone) {
  corridor(3.0F);
  g_nav.start(g_map, {0.0F, 0.0F}, {});
  g_nav.run();
  const Point2 near{2.5F, 0.8F};
  const wm::NavChoice c = g_nav.choose_target(near, 0.75F);
  CHECK(c.kind == wm::NavGoalKind::kTarget);
  CHECK(boticelli::core::distance_m(c.goal, near) <= 0.75F + 1e-4F);
  const Point2 beyond{2.5F, 3.0F};  // behind the wall: no stand-off cell reachable
  CHECK(g_nav.choose_target(beyond, 0.75F).kind == wm::NavGoalKind::kNone);
  CHECK(g_nav.path().empty());
  CHECK(g_nav.choose(nullptr, 0.75F).kind == wm::NavGoalKind::kFrontier);
}
