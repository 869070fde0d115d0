// Obstacle and exploration points from the free polygon (§5.4.4) and the global lists' merging.
#include "algo/mapping/map_points.h"

#include <algorithm>
#include <cmath>

namespace boticelli::mapping {
namespace {

bool on_circle(const StarPolygon& free, std::size_t k, float bounding_radius_m, float tol_m) {
  return free.rho_m(k) >= bounding_radius_m - tol_m;
}

bool near_any(const PointList& list, core::Point2 p, float radius_m) {
  return std::any_of(list.begin(), list.end(),
                     [&](const core::Point2& q) { return core::distance_m(p, q) < radius_m; });
}

}  // namespace

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

void GlobalMap::clear() {
  obstacles_.clear();
  exploration_.clear();
  dropped_ = 0;
}

bool GlobalMap::merge(const core::Pose2& pose, const StarPolygon& free, float bounding_radius_m,
                      const PointList& obstacles_robot, const PointList& exploration_robot,
                      const MapPointParams& params) {
  bool ok = true;
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
  std::size_t kept = 0;
  for (std::size_t i = 0; i < exploration_.size(); ++i) {
    const core::Point2 q = core::to_robot(pose, exploration_[i]);
    const float d = std::hypot(q.x_m, q.y_m);
    const bool explored =
        d + params.explored_margin_m <= bounding_radius_m &&
        d + params.explored_margin_m <= free.radius_at_m(std::atan2(q.y_m, q.x_m));
    if (!explored) {
      exploration_[kept++] = exploration_[i];
    }
  }
  exploration_.resize(kept);
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
