// Feature guard: which unexplained features are corroborated by their neighbours.
#include "algo/mapping/feature_guard.h"

#include <algorithm>

#include <cmath>

namespace boticelli::mapping {

bool are_neighbours(const GuardPoint& a, const GuardPoint& b, const FeatureGuardParams& g) {
  // δr_a + δr_b (§3.7.3): see FeatureGuardParams for why the sum.
  const float delta_r = g.delta_r_fraction * (std::fabs(a.r_m) + std::fabs(b.r_m));
  const float radius = std::fmax(g.neighbour_radius_m, g.neighbour_delta_r_factor * delta_r);
  const float dx = a.x_m - b.x_m;
  const float dy = a.y_m - b.y_m;
  const float dh = a.h_m - b.h_m;
  return dx * dx + dy * dy + dh * dh <= radius * radius;
}

bool corroborated_points(std::span<const GuardPoint> candidates, const FeatureGuardParams& g,
                         GuardPoints& out) {
  return corroborated_points(candidates, 0, candidates.size(), g, out);
}

bool corroborated_points(std::span<const GuardPoint> candidates, std::size_t first,
                         std::size_t last, const FeatureGuardParams& g, GuardPoints& out) {
  bool ok = true;
  for (std::size_t i = first; i < std::min(last, candidates.size()); ++i) {
    const GuardPoint& a = candidates[i];
    const std::size_t required = a.m < g.min_evidence ? g.min_weak_neighbours : g.min_neighbours;
    std::size_t neighbours = 0;
    for (std::size_t j = 0; j < candidates.size() && neighbours < required; ++j) {
      if (j != i && are_neighbours(a, candidates[j], g)) {
        ++neighbours;
      }
    }
    if (neighbours >= required && !out.push_back({a.x_m, a.y_m})) {
      ok = false;
    }
  }
  return ok;
}

}  // namespace boticelli::mapping
