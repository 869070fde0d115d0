// NavPlanner: where to go in the world memory: a clearance field (chamfer distance to occupied
// cells), a Dijkstra wavefront of path cost from the robot over free cells its disc fits in,
// frontier clusters (free cells next to unknown ones) scored by what they may reveal against
// their path cost, the target's stand-off as a goal, and the path to the chosen goal. Works
// in a window of the map centred on the robot, in bounded units of work, without allocating.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <span>

#include "algo/core/fixed_vector.h"
#include "algo/core/geometry.h"
#include "algo/worldmap/grid_map.h"

namespace boticelli::worldmap {

inline constexpr int kPlanSide = 320;  // window cells a side (16 m at 5 cm), robot at the centre
inline constexpr std::size_t kPlanCells = static_cast<std::size_t>(kPlanSide) * kPlanSide;
inline constexpr std::size_t kMaxFrontiers = 256;
inline constexpr std::size_t kMaxPathPoints = 2048;
inline constexpr std::size_t kMaxBlacklist = 64;

struct NavParams {
  float robot_radius_m = 0.30F;  // no path cell is nearer an occupied cell than this [m]
  float clearance_m = 0.15F;     // path cells within robot_radius_m + this cost double [m]
  // A free cell next to unknown nearer than this to an occupied cell is a wall's own unseen
  // fringe, not a way into unknown space [m].
  float wall_fringe_m = 0.1F;
  // A frontier cluster (free cells next to unknown ones, 8-connected) shorter than this leads
  // nowhere [m]; one with no reachable cell the robot's centre may stand on is left out.
  float min_frontier_m = 0.3F;
  // A frontier's utility: gain_per_m × its length [m] − its path length [m] (explore_lite's
  // gain and potential scales, with the path's cost in place of the straight distance).
  float gain_per_m = 1.0F;
  // The target hangs on a wall: a frontier cell farther than wall_reach_m from every occupied
  // cell (open floor, nothing known to lead on) counts open_floor_weight of its length.
  float wall_reach_m = 1.5F;
  float open_floor_weight = 0.25F;
  float hysteresis_m = 1.0F;        // another frontier must beat the goal's utility by this
  float goal_match_m = 0.5F;        // the goal is kept while a frontier cell lies this near it
  float goal_reached_m = 0.4F;      // a frontier goal this near the robot is reached
  float progress_m = 0.3F;          // the goal's path must shorten by this ...
  std::size_t progress_plans = 5;   // ... within this many plans, or the goal is blacklisted
  float blacklist_radius_m = 0.6F;  // no goal within this of a blacklisted one
  float target_band_m = 0.3F;       // the target's goal: cells from stand-off − this to stand-off
  std::size_t rows_per_unit = 32;   // window rows per unit (copy, clearance, frontiers)
  std::size_t pops_per_unit = 4096;  // wavefront cells settled per unit
};

struct Frontier {
  core::Point2 goal{};    // its reachable cell nearest its centroid (mission frame)
  float length_m = 0.0F;  // cells × cell side, open floor weighted (wall_reach_m)
  float path_m = 0.0F;    // path length to `goal`
  float utility = 0.0F;
};

enum class NavGoalKind : std::uint8_t { kNone, kFrontier, kTarget };

struct NavChoice {
  NavGoalKind kind = NavGoalKind::kNone;
  core::Point2 goal{};
  float path_m = 0.0F;
  bool blacklisted = false;  // this plan blacklisted a goal that made no progress
};

class NavPlanner {
 public:
  NavPlanner() = default;
  NavPlanner(const NavPlanner&) = delete;
  NavPlanner& operator=(const NavPlanner&) = delete;

  // A mission (re)starts: no goal, nothing blacklisted.
  void reset();
  // A plan from `robot` (mission frame) on `map` (which must not change until done()).
  void start(const GridMap& map, core::Point2 robot, const NavParams& params);
  // One unit of work; true when the wavefront and the frontiers are ready.
  bool run_unit();
  void run() {
    while (!run_unit()) {
    }
  }
  [[nodiscard]] bool done() const { return phase_ == Phase::kDone; }

  // After done(): the goal. With `target` (its estimate, or nullptr) the cheapest reachable
  // cell standing off it by standoff_m − target_band_m … standoff_m; else (or if none is
  // reachable) the frontier of best utility, kept while it lasts (hysteresis), blacklisted
  // when its path stops shortening; kNone when no reachable frontier is left. Fills path().
  NavChoice choose(const core::Point2* target, float standoff_m);

  // After done(): only the target's stand-off (choose()'s first rule), kNone when no cell of
  // the stand-off band is reachable; frontiers and the kept goal are left alone. Fills path().
  NavChoice choose_target(core::Point2 target, float standoff_m);

  // The path to the chosen goal, robot first (cell centres, mission frame).
  [[nodiscard]] std::span<const core::Point2> path() const { return path_.span(); }
  [[nodiscard]] std::span<const Frontier> frontiers() const { return frontiers_.span(); }
  [[nodiscard]] std::span<const core::Point2> blacklist() const { return blacklist_.span(); }
  // Path cost [m] from the robot to the cell holding p (∞ if unreachable or outside).
  [[nodiscard]] float path_m(core::Point2 p) const;
  // Whether the cell holding p may hold the robot's centre (free, clear by robot_radius_m).
  [[nodiscard]] bool passable(core::Point2 p) const;
  [[nodiscard]] std::size_t heap_overflows() const { return heap_overflows_; }

 private:
  enum class Phase : std::uint8_t {
    kIdle,
    kCopy,
    kClearForward,
    kClearBackward,
    kWave,
    kFrontiers,
    kDone
  };
  enum : std::uint8_t { kUnknownCell = 0, kFreeCell = 1, kOccupiedCell = 2 };
  static constexpr std::uint32_t kUnreached = 0xFFFFFFFFU;
  static constexpr std::uint8_t kNoParent = 0xFF;

  [[nodiscard]] bool window_index(core::Point2 p, std::size_t& index) const;
  [[nodiscard]] core::Point2 centre(std::size_t index) const;
  [[nodiscard]] bool passable_cell(std::size_t index) const;
  void copy_rows();
  void clear_forward_rows();
  void clear_backward_rows();
  void wave_unit();
  void frontier_rows();
  void grow_cluster(std::size_t seed);
  [[nodiscard]] bool is_frontier(std::size_t index) const;
  [[nodiscard]] bool blacklisted(core::Point2 p) const;
  void trace_path(std::size_t goal_index);
  // The cheapest reachable passable cell standing off `target` by standoff_m − target_band_m
  // … standoff_m (its index in `best`), or kUnreached.
  std::uint32_t standoff_cell(core::Point2 target, float standoff_m, std::size_t& best) const;
  bool push(std::uint32_t cost, std::uint32_t index);

  const GridMap* map_ = nullptr;
  NavParams params_{};
  Phase phase_ = Phase::kIdle;
  Cell origin_{};  // the window's lowest cell
  std::size_t source_ = 0;
  int row_ = 0;
  std::uint16_t robot_clear_ = 0;   // robot_radius_m in chamfer units (5 a cell)
  std::uint16_t margin_clear_ = 0;  // robot_radius_m + clearance_m
  std::uint16_t fringe_clear_ = 0;  // wall_fringe_m
  std::uint16_t reach_clear_ = 0;   // wall_reach_m
  std::uint32_t escape_cost_ = 0;   // robot_radius_m in path cost (10 a cell)
  std::array<std::uint8_t, kPlanCells> cell_{};
  std::array<std::uint16_t, kPlanCells> clear_{};       // chamfer distance to occupied (5 a cell)
  std::array<std::uint32_t, kPlanCells> cost_{};        // path cost (10 a cell straight)
  std::array<std::uint8_t, kPlanCells> parent_{};       // direction to the previous cell
  std::array<std::uint8_t, kPlanCells> mark_{};         // frontier cells already clustered
  core::FixedVector<std::uint64_t, kPlanCells> heap_;   // (cost << 32 | index), lazy deletion
  core::FixedVector<std::uint32_t, kPlanCells> queue_;  // a cluster's cells
  core::FixedVector<Frontier, kMaxFrontiers> frontiers_;
  core::FixedVector<core::Point2, kMaxPathPoints> path_;
  core::FixedVector<core::Point2, kMaxBlacklist> blacklist_;
  std::size_t heap_overflows_ = 0;
  // The goal kept across plans (hysteresis, progress).
  bool has_goal_ = false;
  core::Point2 goal_{};
  float goal_best_path_m_ = 0.0F;
  std::size_t goal_stalled_plans_ = 0;
};

}  // namespace boticelli::worldmap
