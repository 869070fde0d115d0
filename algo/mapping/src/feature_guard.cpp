// Feature guard: which unexplained features are corroborated by their neighbours.
#include "algo/mapping/feature_guard.h"

namespace boticelli::mapping {

bool corroborated_points(std::span<const GuardPoint> candidates, const FeatureGuardParams& g,
                         GuardPoints& out) {
  const float r2 = g.neighbour_radius_m * g.neighbour_radius_m;
  bool ok = true;
  for (std::size_t i = 0; i < candidates.size(); ++i) {
    const GuardPoint& a = candidates[i];
    std::size_t neighbours = 0;
    for (std::size_t j = 0; j < candidates.size() && neighbours < g.min_neighbours; ++j) {
      const GuardPoint& b = candidates[j];
      const float dx = a.x_m - b.x_m;
      const float dy = a.y_m - b.y_m;
      const float dh = a.h_m - b.h_m;
      neighbours += (j != i && dx * dx + dy * dy + dh * dh <= r2) ? 1 : 0;
    }
    if (neighbours >= g.min_neighbours && !out.push_back({a.x_m, a.y_m})) {
      ok = false;
    }
  }
  return ok;
}

}  // namespace boticelli::mapping
