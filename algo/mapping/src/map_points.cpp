// Obstacle and exploration points from the free polygon (§5.4.4), exploration points from the
// belief–plausibility gap (§7.2.3) and the global lists' merging.
#include "algo/mapping/map_points.h"

#include <algorithm>
#include <cmath>

namespace boticelli::mapping {
namespace {

bool on_circle(const StarPolygon& free, std::size_t k, float bounding_radius_m, float tol_m) {
  return free.rho_m(k) >= bounding_radius_m - tol_m;
}

// True if world point w lies at least margin_m inside both the free polygon (robot frame at
// `pose`) and its bounding circle.
bool well_inside(const core::Pose2& pose, const StarPolygon& free, float bounding_radius_m,
                 core::Point2 w, float margin_m) {
  const core::Point2 q = core::to_robot(pose, w);
  const float d = std::hypot(q.x_m, q.y_m);
  return d + margin_m <= bounding_radius_m &&
         d + margin_m <= free.radius_at_m(std::atan2(q.y_m, q.x_m));
}

// Removes, in place and keeping the order of the rest, the points `pose`'s free polygon
// covers by margin_m; returns how many went.
std::size_t remove_well_inside(PointList& list, const core::Pose2& pose, const StarPolygon& free,
                               float bounding_radius_m, float margin_m) {
  std::size_t kept = 0;
  for (std::size_t i = 0; i < list.size(); ++i) {
    if (!well_inside(pose, free, bounding_radius_m, list[i], margin_m)) {
      list[kept++] = list[i];
    }
  }
  const std::size_t removed = list.size() - kept;
  list.resize(kept);
  return removed;
}

bool near_any(const PointList& list, core::Point2 p, float radius_m) {
  return std::any_of(list.begin(), list.end(),
                     [&](const core::Point2& q) { return core::distance_m(p, q) < radius_m; });
}

// Width of the unknown band along vertex ray k [m]: how much farther the belief model (lower
// bound of occupancy) than the plausibility model (upper bound) calls the floor free, both
// cut to the bounding circle. Bel ≤ Pl (Eq 4.16–4.18) makes it ≥ 0 for exact fits; a negative
// value is a fit that broke the order, not an unknown region. NaN if a ρ is NaN.
float gap_width_m(const StarPolygon& belief_free, const StarPolygon& plausibility_free,
                  std::size_t k, float bounding_radius_m) {
  return std::min(belief_free.rho_m(k), bounding_radius_m) -
         std::min(plausibility_free.rho_m(k), bounding_radius_m);
}

bool is_gap_ray(const StarPolygon& belief_free, const StarPolygon& plausibility_free, std::size_t k,
                float bounding_radius_m, float min_gap_m) {
  const float gap = gap_width_m(belief_free, plausibility_free, k, bounding_radius_m);
  return gap > 0.0F && gap >= min_gap_m;  // false for NaN
}

// The gap point on vertex ray k: §7.2.3 asks for the points of high uncertainty Pl − Bel, the
// band (ρ_pl, ρ_bel]. Only the plausibility polygon is proven free (it is the navigation
// polygon, §5.4), so a point in the band could not be reached or even approached safely; the
// point goes to the near edge of the band, inset_m inside the plausibility boundary (at most
// half way to the robot), where the robot can drive and look into the unknown.
core::Point2 gap_point(const StarPolygon& plausibility_free, std::size_t k, float bounding_radius_m,
                       float inset_m) {
  const float rho = std::max(std::min(plausibility_free.rho_m(k), bounding_radius_m), 0.0F);
  const float d = rho - std::clamp(inset_m, 0.0F, 0.5F * rho);
  const float a = plausibility_free.angle_rad(k);
  return {d * std::cos(a), d * std::sin(a)};
}

}  // namespace

bool extract_gap_exploration_points(const StarPolygon& belief_free,
                                    const StarPolygon& plausibility_free, float bounding_radius_m,
                                    const MapPointParams& params, PointList& exploration_robot) {
  const std::size_t n = plausibility_free.vertex_count();
  if (belief_free.vertex_count() != n) {
    return false;
  }
  const float min_gap = params.exploration_gap_m;
  auto gap = [&](std::size_t k) {
    return is_gap_ray(belief_free, plausibility_free, k % n, bounding_radius_m, min_gap);
  };
  // Start at a class change so no sector wraps round the seam; none: all gap or none.
  std::size_t start = n;
  for (std::size_t k = 0; k < n; ++k) {
    if (gap(k) != gap(k + n - 1)) {
      start = k;
      break;
    }
  }
  if (start == n) {
    if (!gap(0)) {
      return true;
    }
    start = 0;
  }
  bool ok = true;
  std::size_t done = 0;
  while (done < n) {
    const std::size_t first = (start + done) % n;
    const bool in_gap = gap(first);
    std::size_t len = 1;
    while (done + len < n && gap(first + len) == in_gap) {
      ++len;
    }
    done += len;
    if (!in_gap) {
      continue;
    }
    // Length of the arc the sector's points lie on.
    float length_m = 0.0F;
    for (std::size_t i = 0; i + 1 < len; ++i) {
      const std::size_t k = (first + i) % n;
      length_m += core::distance_m(
          gap_point(plausibility_free, k, bounding_radius_m, params.gap_point_inset_m),
          gap_point(plausibility_free, (k + 1) % n, bounding_radius_m, params.gap_point_inset_m));
    }
    auto count = static_cast<std::size_t>(
        std::ceil(length_m / std::max(params.exploration_spacing_m, 1e-3F)));
    count = std::clamp<std::size_t>(count, 1, len);
    for (std::size_t i = 0; i < count; ++i) {
      // Evenly spaced vertex angles in the sector, centred (as on the bounding circle).
      const std::size_t offset = (2 * i + 1) * len / (2 * count);
      ok = exploration_robot.push_back(gap_point(plausibility_free, (first + offset) % n,
                                                 bounding_radius_m, params.gap_point_inset_m)) &&
           ok;
    }
  }
  return ok;
}

bool extract_map_points(const StarPolygon& free, float bounding_radius_m,
                        const MapPointParams& params, PointList& obstacles_robot,
                        PointList& exploration_robot) {
  const std::size_t n = free.vertex_count();
  const float tol = params.on_circle_tolerance_m;
  // Start at a class change so no sector wraps; if there is none, one sector is everything.
  std::size_t start = 0;
  for (std::size_t k = 0; k < n; ++k) {
    if (on_circle(free, k, bounding_radius_m, tol) !=
        on_circle(free, (k + n - 1) % n, bounding_radius_m, tol)) {
      start = k;
      break;
    }
  }
  bool ok = true;
  std::size_t done = 0;
  while (done < n) {
    const std::size_t first = (start + done) % n;
    const bool circle = on_circle(free, first, bounding_radius_m, tol);
    std::size_t len = 1;
    while (done + len < n && on_circle(free, (first + len) % n, bounding_radius_m, tol) == circle) {
      ++len;
    }
    // Boundary length of the sector: the edges between its own vertices.
    float length_m = 0.0F;
    for (std::size_t i = 0; i + 1 < len; ++i) {
      const std::size_t k = (first + i) % n;
      const core::Point2 a = free.vertex(k);
      const core::Point2 b = free.vertex((k + 1) % n);
      length_m += core::distance_m(a, b);
    }
    const float spacing = circle ? params.exploration_spacing_m : params.obstacle_spacing_m;
    auto count = static_cast<std::size_t>(std::ceil(length_m / std::max(spacing, 1e-3F)));
    count = std::clamp<std::size_t>(count, 1, len);
    PointList& list = circle ? exploration_robot : obstacles_robot;
    for (std::size_t i = 0; i < count; ++i) {
      // Evenly spaced vertex angles in the sector, centred.
      const std::size_t offset = (2 * i + 1) * len / (2 * count);
      ok = list.push_back(free.vertex((first + offset) % n)) && ok;
    }
    done += len;
  }
  return ok;
}

std::size_t GlobalMap::mark_explored(const core::Pose2& pose, const StarPolygon& seen,
                                     float bounding_radius_m, const MapPointParams& params) {
  return remove_well_inside(exploration_, pose, seen, bounding_radius_m, params.explored_margin_m);
}

std::size_t GlobalMap::clear_exploration(core::Point2 origin, float clearance_m, float pull_reach_m,
                                         const MapPointParams& params) {
  const auto clear_at = [&](core::Point2 p) {
    for (const core::Point2& o : obstacles_) {
      if (core::distance_m(o, p) < clearance_m) return false;
    }
    return true;
  };
  const float step = std::max(params.exploration_pull_step_m, 1e-3F);
  std::size_t kept = 0;
  const std::size_t n = exploration_.size();
  for (std::size_t i = 0; i < n; ++i) {
    const core::Point2 p = exploration_[i];
    const float d = core::distance_m(p, origin);
    bool found = clear_at(p);
    core::Point2 q = p;
    if (!found && d <= pull_reach_m && d > 0.0F) {
      const float ux = (origin.x_m - p.x_m) / d;
      const float uy = (origin.y_m - p.y_m) / d;
      const float max_pull = std::min(params.exploration_max_pull_m, d);
      for (float t = step; t <= max_pull + 1e-6F && !found; t += step) {
        q = {p.x_m + t * ux, p.y_m + t * uy};
        found = clear_at(q);
      }
    }
    if (found) exploration_[kept++] = q;
  }
  exploration_.resize(kept);
  return n - kept;
}

void GlobalMap::clear() {
  obstacles_.clear();
  exploration_.clear();
  dropped_ = 0;
  retired_ = 0;
}

bool GlobalMap::merge(const core::Pose2& pose, const StarPolygon& free, float bounding_radius_m,
                      const PointList& obstacles_robot, const PointList& exploration_robot,
                      const MapPointParams& params) {
  bool ok = true;
  // Contradicted: the newer view sees free floor well inside where the point was.
  retired_ += remove_well_inside(obstacles_, pose, free, bounding_radius_m,
                                 params.obstacle_retire_margin_m);
  for (const core::Point2& p : obstacles_robot) {
    const core::Point2 w = core::to_world(pose, p);
    if (near_any(obstacles_, w, params.obstacle_merge_radius_m)) {
      continue;
    }
    if (!obstacles_.push_back(w)) {
      ++dropped_;
      ok = false;
    }
  }
  // Explored: well inside this cycle's free polygon (and the bounding circle).
  (void)remove_well_inside(exploration_, pose, free, bounding_radius_m, params.explored_margin_m);
  {
    const core::Point2 here{pose.x_m, pose.y_m};
    std::size_t kept = 0;
    for (std::size_t i = 0; i < exploration_.size(); ++i) {
      if (core::distance_m(exploration_[i], here) >= params.explored_look_radius_m) {
        exploration_[kept++] = exploration_[i];
      }
    }
    exploration_.resize(kept);
  }
  for (const core::Point2& p : exploration_robot) {
    const core::Point2 w = core::to_world(pose, p);
    if (near_any(exploration_, w, params.exploration_merge_radius_m)) {
      continue;
    }
    if (!exploration_.push_back(w)) {
      ++dropped_;
      ok = false;
    }
  }
  return ok;
}

}  // namespace boticelli::mapping
