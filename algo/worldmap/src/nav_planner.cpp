// NavPlanner: clearance, wavefront, frontiers and goal (see nav_planner.h).
#include "algo/worldmap/nav_planner.h"

#include <algorithm>
#include <cmath>
#include <functional>
#include <limits>

namespace boticelli::worldmap {
namespace {

// The eight moves: dx, dy and cost (10 a cell straight, 14 diagonal).
constexpr std::array<int, 8> kDx{1, -1, 0, 0, 1, 1, -1, -1};
constexpr std::array<int, 8> kDy{0, 0, 1, -1, 1, -1, 1, -1};
constexpr std::array<std::uint32_t, 8> kStepCost{10, 10, 10, 10, 14, 14, 14, 14};
constexpr std::uint16_t kAxial = 5;  // chamfer 5-7 distance: 5 a cell straight, 7 diagonal
constexpr std::uint16_t kDiagonal = 7;
constexpr std::uint16_t kFar = 0xFFFF;

std::size_t idx(int x, int y) {
  return static_cast<std::size_t>(y * kPlanSide + x);
}

std::uint16_t chamfer_units(float metres, float cell_m) {
  return static_cast<std::uint16_t>(
      std::min(std::ceil(metres / cell_m * static_cast<float>(kAxial)), 60000.0F));
}

}  // namespace

void NavPlanner::reset() {
  has_goal_ = false;
  goal_stalled_plans_ = 0;
  blacklist_.clear();
  path_.clear();
  frontiers_.clear();
  phase_ = Phase::kIdle;
}

void NavPlanner::start(const GridMap& map, core::Point2 robot, const NavParams& params) {
  map_ = &map;
  params_ = params;
  const Cell r = map.cell_of(robot);
  origin_ = {r.ix - kPlanSide / 2, r.iy - kPlanSide / 2};
  source_ = static_cast<std::size_t>(kPlanSide / 2) * kPlanSide + kPlanSide / 2;
  const float cell = map.cell_m();
  robot_clear_ = chamfer_units(params.robot_radius_m, cell);
  margin_clear_ = chamfer_units(params.robot_radius_m + params.clearance_m, cell);
  fringe_clear_ = chamfer_units(params.wall_fringe_m, cell);
  reach_clear_ = chamfer_units(params.wall_reach_m, cell);
  escape_cost_ = static_cast<std::uint32_t>(std::ceil(params.robot_radius_m / cell * 10.0F));
  frontiers_.clear();
  path_.clear();
  heap_.clear();
  heap_overflows_ = 0;
  row_ = 0;
  phase_ = Phase::kCopy;
}

bool NavPlanner::run_unit() {
  switch (phase_) {
    case Phase::kCopy:
      copy_rows();
      break;
    case Phase::kClearForward:
      clear_forward_rows();
      break;
    case Phase::kClearBackward:
      clear_backward_rows();
      break;
    case Phase::kWave:
      wave_unit();
      break;
    case Phase::kFrontiers:
      frontier_rows();
      break;
    case Phase::kIdle:
    case Phase::kDone:
      break;
  }
  return phase_ == Phase::kDone;
}

void NavPlanner::copy_rows() {
  const int end = std::min(kPlanSide, row_ + static_cast<int>(params_.rows_per_unit));
  for (; row_ < end; ++row_) {
    for (int x = 0; x < kPlanSide; ++x) {
      const std::size_t i = idx(x, row_);
      const CellState s = map_->state({origin_.ix + x, origin_.iy + row_});
      cell_[i] = s == CellState::kFree       ? kFreeCell
                 : s == CellState::kOccupied ? kOccupiedCell
                                             : kUnknownCell;
      clear_[i] = s == CellState::kOccupied ? 0 : kFar;
      cost_[i] = kUnreached;
      parent_[i] = kNoParent;
      mark_[i] = 0;
    }
  }
  if (row_ == kPlanSide) {
    row_ = 0;
    phase_ = Phase::kClearForward;
  }
}

// Chamfer distance transform (Borgefors 1986), forward pass: from the row above and the left.
void NavPlanner::clear_forward_rows() {
  const int end = std::min(kPlanSide, row_ + static_cast<int>(params_.rows_per_unit));
  auto relax = [&](std::size_t i, int x, int y, std::uint16_t w) {
    if (x < 0 || x >= kPlanSide || y < 0) return;
    const std::uint16_t d = clear_[idx(x, y)];
    if (d != kFar) clear_[i] = std::min<std::uint16_t>(clear_[i], d + w);
  };
  for (; row_ < end; ++row_) {
    for (int x = 0; x < kPlanSide; ++x) {
      const std::size_t i = idx(x, row_);
      relax(i, x - 1, row_, kAxial);
      relax(i, x - 1, row_ - 1, kDiagonal);
      relax(i, x, row_ - 1, kAxial);
      relax(i, x + 1, row_ - 1, kDiagonal);
    }
  }
  if (row_ == kPlanSide) {
    row_ = kPlanSide - 1;
    phase_ = Phase::kClearBackward;
  }
}

// ... backward pass: from the row below and the right.
void NavPlanner::clear_backward_rows() {
  const int end = std::max(-1, row_ - static_cast<int>(params_.rows_per_unit));
  auto relax = [&](std::size_t i, int x, int y, std::uint16_t w) {
    if (x < 0 || x >= kPlanSide || y >= kPlanSide) return;
    const std::uint16_t d = clear_[idx(x, y)];
    if (d != kFar) clear_[i] = std::min<std::uint16_t>(clear_[i], d + w);
  };
  for (; row_ > end; --row_) {
    for (int x = kPlanSide - 1; x >= 0; --x) {
      const std::size_t i = idx(x, row_);
      relax(i, x + 1, row_, kAxial);
      relax(i, x + 1, row_ + 1, kDiagonal);
      relax(i, x, row_ + 1, kAxial);
      relax(i, x - 1, row_ + 1, kDiagonal);
    }
  }
  if (row_ < 0) {
    cost_[source_] = 0;
    (void)push(0, static_cast<std::uint32_t>(source_));
    phase_ = Phase::kWave;
  }
}

bool NavPlanner::passable_cell(std::size_t i) const {
  return cell_[i] == kFreeCell && clear_[i] >= robot_clear_;
}

bool NavPlanner::push(std::uint32_t cost, std::uint32_t index) {
  if (!heap_.push_back((static_cast<std::uint64_t>(cost) << 32U) | index)) {
    ++heap_overflows_;
    return false;
  }
  std::push_heap(heap_.begin(), heap_.end(), std::greater<>());
  return true;
}

// Dijkstra from the robot's cell. The robot may stand where its disc already touches an
// occupied cell's clearance (or on a cell no look showed free): from a cell that is not
// passable, within the robot's own disc, the wave goes only to cells no nearer any obstacle,
// so it leads out, never in.
void NavPlanner::wave_unit() {
  for (std::size_t n = 0; n < params_.pops_per_unit; ++n) {
    if (heap_.empty()) {
      row_ = 0;
      phase_ = Phase::kFrontiers;
      return;
    }
    std::pop_heap(heap_.begin(), heap_.end(), std::greater<>());
    const std::uint64_t top = heap_[heap_.size() - 1];
    heap_.pop_back();
    const auto cost = static_cast<std::uint32_t>(top >> 32U);
    const auto i = static_cast<std::uint32_t>(top & 0xFFFFFFFFU);
    if (cost != cost_[i]) continue;  // a stale entry
    const int x = static_cast<int>(i % kPlanSide);
    const int y = static_cast<int>(i / kPlanSide);
    // Leaving a cell that is not passable is allowed only within the robot's own disc.
    const bool from_passable = passable_cell(i) || cost > escape_cost_;
    for (std::size_t d = 0; d < 8; ++d) {
      const int nx = x + kDx[d];
      const int ny = y + kDy[d];
      if (nx < 0 || nx >= kPlanSide || ny < 0 || ny >= kPlanSide) continue;
      const std::size_t j = idx(nx, ny);
      const bool ok = passable_cell(j) ||
                      (!from_passable && cell_[j] != kOccupiedCell && clear_[j] >= clear_[i]);
      if (!ok) continue;
      std::uint32_t step = kStepCost[d];
      if (clear_[j] < margin_clear_) step *= 2;  // near a wall: keep to the middle
      const std::uint32_t c = cost + step;
      if (c < cost_[j]) {
        cost_[j] = c;
        parent_[j] = static_cast<std::uint8_t>(d);
        (void)push(c, static_cast<std::uint32_t>(j));
      }
    }
  }
}

bool NavPlanner::is_frontier(std::size_t i) const {
  if (cell_[i] != kFreeCell || clear_[i] < fringe_clear_) return false;
  const int x = static_cast<int>(i % kPlanSide);
  const int y = static_cast<int>(i / kPlanSide);
  if (x == 0 || y == 0 || x == kPlanSide - 1 || y == kPlanSide - 1) return false;
  return cell_[i - 1] == kUnknownCell || cell_[i + 1] == kUnknownCell ||
         cell_[i - kPlanSide] == kUnknownCell || cell_[i + kPlanSide] == kUnknownCell;
}

void NavPlanner::frontier_rows() {
  const int end = std::min(kPlanSide, row_ + static_cast<int>(params_.rows_per_unit));
  for (; row_ < end; ++row_) {
    for (int x = 0; x < kPlanSide; ++x) {
      const std::size_t i = idx(x, row_);
      if (mark_[i] == 0 && is_frontier(i)) grow_cluster(i);
    }
  }
  if (row_ == kPlanSide) phase_ = Phase::kDone;
}

// The 8-connected cluster of frontier cells around `seed`: its length, centroid and goal.
void NavPlanner::grow_cluster(std::size_t seed) {
  queue_.clear();
  (void)queue_.push_back(static_cast<std::uint32_t>(seed));
  mark_[seed] = 1;
  double sx = 0.0;
  double sy = 0.0;
  float weight = 0.0F;
  for (std::size_t q = 0; q < queue_.size(); ++q) {
    const std::uint32_t i = queue_[q];
    const int x = static_cast<int>(i % kPlanSide);
    const int y = static_cast<int>(i / kPlanSide);
    sx += x;
    sy += y;
    weight += clear_[i] <= reach_clear_ ? 1.0F : params_.open_floor_weight;
    for (std::size_t d = 0; d < 8; ++d) {
      const int nx = x + kDx[d];
      const int ny = y + kDy[d];
      if (nx < 0 || nx >= kPlanSide || ny < 0 || ny >= kPlanSide) continue;
      const std::size_t j = idx(nx, ny);
      if (mark_[j] != 0 || !is_frontier(j)) continue;
      mark_[j] = 1;
      if (!queue_.push_back(static_cast<std::uint32_t>(j))) break;
    }
  }
  const float cell = map_->cell_m();
  Frontier f;
  if (static_cast<float>(queue_.size()) * cell < params_.min_frontier_m) return;
  f.length_m = weight * cell;
  const auto n = static_cast<double>(queue_.size());
  const float cx = static_cast<float>(sx / n);
  const float cy = static_cast<float>(sy / n);
  // The goal: the cluster's reachable cell the robot's centre may stand on nearest its centroid
  // (a doorway's frontier spans the jambs' clearance too; the robot goes through its middle).
  std::uint32_t best = queue_[0];
  float best_d2 = std::numeric_limits<float>::infinity();
  for (const std::uint32_t i : queue_) {
    if (cost_[i] == kUnreached || !passable_cell(i)) continue;
    const float dx = static_cast<float>(i % kPlanSide) - cx;
    const float dy = static_cast<float>(i / kPlanSide) - cy;
    const float d2 = dx * dx + dy * dy;
    if (d2 < best_d2) {
      best_d2 = d2;
      best = i;
    }
  }
  if (!std::isfinite(best_d2)) return;  // no cell of it is reachable
  f.goal = centre(best);
  f.path_m = static_cast<float>(cost_[best]) * 0.1F * cell;
  f.utility = params_.gain_per_m * f.length_m - f.path_m;
  (void)frontiers_.push_back(f);
}

bool NavPlanner::window_index(core::Point2 p, std::size_t& index) const {
  const Cell c = map_->cell_of(p);
  const int x = c.ix - origin_.ix;
  const int y = c.iy - origin_.iy;
  if (x < 0 || x >= kPlanSide || y < 0 || y >= kPlanSide) return false;
  index = idx(x, y);
  return true;
}

core::Point2 NavPlanner::centre(std::size_t index) const {
  return map_->centre_of({origin_.ix + static_cast<int>(index % kPlanSide),
                          origin_.iy + static_cast<int>(index / kPlanSide)});
}

float NavPlanner::path_m(core::Point2 p) const {
  std::size_t i = 0;
  if (phase_ != Phase::kDone || !window_index(p, i) || cost_[i] == kUnreached) {
    return std::numeric_limits<float>::infinity();
  }
  return static_cast<float>(cost_[i]) * 0.1F * map_->cell_m();
}

bool NavPlanner::passable(core::Point2 p) const {
  std::size_t i = 0;
  return phase_ == Phase::kDone && window_index(p, i) && passable_cell(i);
}

bool NavPlanner::blacklisted(core::Point2 p) const {
  return std::any_of(blacklist_.begin(), blacklist_.end(), [&](const core::Point2& b) {
    return core::distance_m(p, b) < params_.blacklist_radius_m;
  });
}

void NavPlanner::trace_path(std::size_t goal_index) {
  path_.clear();
  std::size_t i = goal_index;
  while (path_.size() < path_.capacity()) {
    (void)path_.push_back(centre(i));
    if (i == source_ || parent_[i] == kNoParent) break;
    const std::size_t d = parent_[i];
    const int x = static_cast<int>(i % kPlanSide) - kDx[d];
    const int y = static_cast<int>(i / kPlanSide) - kDy[d];
    i = idx(x, y);
  }
  std::reverse(path_.begin(), path_.end());
}

NavChoice NavPlanner::choose_target(core::Point2 target, float standoff_m) {
  NavChoice choice;
  path_.clear();
  if (phase_ != Phase::kDone) return choice;
  std::size_t best = 0;
  const std::uint32_t best_cost = standoff_cell(target, standoff_m, best);
  if (best_cost == kUnreached) return choice;
  trace_path(best);
  choice.kind = NavGoalKind::kTarget;
  choice.goal = centre(best);
  choice.path_m = static_cast<float>(best_cost) * 0.1F * map_->cell_m();
  return choice;
}

std::uint32_t NavPlanner::standoff_cell(core::Point2 target, float standoff_m,
                                        std::size_t& best) const {
  const float inner = std::max(0.0F, standoff_m - params_.target_band_m);
  const Cell lo = map_->cell_of({target.x_m - standoff_m, target.y_m - standoff_m});
  const Cell hi = map_->cell_of({target.x_m + standoff_m, target.y_m + standoff_m});
  std::uint32_t best_cost = kUnreached;
  for (int iy = lo.iy; iy <= hi.iy; ++iy) {
    for (int ix = lo.ix; ix <= hi.ix; ++ix) {
      const core::Point2 p = map_->centre_of({ix, iy});
      const float d = core::distance_m(p, target);
      std::size_t i = 0;
      if (d < inner || d > standoff_m || !window_index(p, i)) continue;
      if (!passable_cell(i) || cost_[i] >= best_cost) continue;
      best_cost = cost_[i];
      best = i;
    }
  }
  return best_cost;
}

NavChoice NavPlanner::choose(const core::Point2* target, float standoff_m) {
  NavChoice choice;
  path_.clear();
  if (phase_ != Phase::kDone) return choice;
  const float cell = map_->cell_m();
  if (target != nullptr) {
    // The target's goal: the cheapest reachable cell in the stand-off band round it.
    std::size_t best = 0;
    std::uint32_t best_cost = standoff_cell(*target, standoff_m, best);
    if (best_cost == kUnreached) {
      // No stand-off reachable on what the map knows: as near the target as it allows (the
      // next look shows more), unless that is where the robot already stands.
      float best_d = core::distance_m(centre(source_), *target) - params_.goal_reached_m;
      for (std::size_t i = 0; i < kPlanCells; ++i) {
        if (cost_[i] == kUnreached || !passable_cell(i)) continue;
        const float d = core::distance_m(centre(i), *target);
        if (d < best_d) {
          best_d = d;
          best = i;
          best_cost = cost_[i];
        }
      }
      if (best_cost != kUnreached && !frontiers_.empty()) best_cost = kUnreached;  // explore
    }
    if (best_cost != kUnreached) {
      trace_path(best);
      choice.kind = NavGoalKind::kTarget;
      choice.goal = centre(best);
      choice.path_m = static_cast<float>(best_cost) * 0.1F * cell;
      return choice;
    }
  }
  const core::Point2 robot = centre(source_);
  for (int attempt = 0; attempt < 2; ++attempt) {
    if (has_goal_ && core::distance_m(robot, goal_) <= params_.goal_reached_m) has_goal_ = false;
    // Is the kept goal still at a frontier? Its nearest frontier cell within goal_match_m.
    std::size_t kept = 0;
    bool still = false;
    if (has_goal_) {
      float best_d = params_.goal_match_m;
      const Cell g = map_->cell_of(goal_);
      const int reach = static_cast<int>(std::ceil(params_.goal_match_m / cell));
      for (int dy = -reach; dy <= reach; ++dy) {
        for (int dx = -reach; dx <= reach; ++dx) {
          const core::Point2 p = map_->centre_of({g.ix + dx, g.iy + dy});
          std::size_t i = 0;
          const float d = core::distance_m(p, goal_);
          if (d > best_d || !window_index(p, i) || !is_frontier(i)) continue;
          if (cost_[i] == kUnreached || !passable_cell(i)) continue;
          best_d = d;
          kept = i;
          still = true;
        }
      }
    }
    const Frontier* best = nullptr;
    for (const Frontier& f : frontiers_) {
      if (blacklisted(f.goal)) continue;
      if (best == nullptr || f.utility > best->utility) best = &f;
    }
    float kept_utility = -std::numeric_limits<float>::infinity();
    if (still) {
      const float kept_path = static_cast<float>(cost_[kept]) * 0.1F * cell;
      float length = params_.min_frontier_m;
      for (const Frontier& f : frontiers_) {
        if (core::distance_m(f.goal, goal_) <= 2.0F * params_.goal_match_m) {
          length = std::max(length, f.length_m);
        }
      }
      kept_utility = params_.gain_per_m * length - kept_path;
    }
    if (still && (best == nullptr || best->utility < kept_utility + params_.hysteresis_m)) {
      goal_ = centre(kept);
    } else if (best != nullptr) {
      has_goal_ = true;
      goal_ = best->goal;
      goal_best_path_m_ = std::numeric_limits<float>::infinity();
      goal_stalled_plans_ = 0;
    } else {
      has_goal_ = false;
      return choice;  // no reachable frontier left
    }
    std::size_t gi = 0;
    (void)window_index(goal_, gi);
    const float path = static_cast<float>(cost_[gi]) * 0.1F * cell;
    if (path < goal_best_path_m_ - params_.progress_m) {
      goal_best_path_m_ = path;
      goal_stalled_plans_ = 0;
    } else if (++goal_stalled_plans_ >= params_.progress_plans) {
      // No progress toward it for several plans: something the map does not show stands in
      // the way (explore_lite's progress timeout). Never again; choose another.
      (void)blacklist_.push_back(goal_);
      has_goal_ = false;
      choice.blacklisted = true;
      continue;
    }
    trace_path(gi);
    choice.kind = NavGoalKind::kFrontier;
    choice.goal = goal_;
    choice.path_m = path;
    return choice;
  }
  return choice;
}

}  // namespace boticelli::worldmap
