// Feature guard: features the fitted occupancy model calls free, kept as hard obstacles of the
// navigation polygon when other such features corroborate them.
#pragma once

#include <cmath>
#include <cstddef>
#include <span>

#include "algo/core/fixed_vector.h"
#include "algo/core/geometry.h"
#include "algo/evidence/reading.h"
#include "algo/mapping/extraction.h"
#include "algo/mapping/star_polygon.h"

namespace boticelli::mapping {

// The regression smooths: an obstacle much smaller than the model's pieces (a 0.5 m box in a
// room fitted with a few pieces) can end up below m_safe although dozens of features lie on
// it (thesis §4.8.2, Fig 4.7: the box needs many pieces, and the α slope bound of Eq 4.28
// keeps a piece from rising to m_safe across a narrow object). A cluster of such features is
// evidence the robot must not drive into; a lone one is an outlier of the stereo (§4.8.2)
// that the fit was right to ignore. So the guard keeps the corroborated ones and the
// extraction pulls the polygon in front of them.
struct FeatureGuardParams {
  float min_evidence = 0.6F;        // features this occupied are surfaces (m_safe, §5.4)
  float neighbour_radius_m = 0.1F;  // corroboration: unexplained features this close (3-D)
  std::size_t min_neighbours = 4;   // at least this many others within the radius
};

// A feature in the robot frame: x, y [m] on the floor plane, h [m] relative to the PTU centre.
struct GuardPoint {
  float x_m = 0.0F;
  float y_m = 0.0F;
  float h_m = 0.0F;
};

inline constexpr std::size_t kMaxGuardCandidates = 2048;
inline constexpr std::size_t kMaxGuardPoints = 1024;

using GuardCandidates = core::FixedVectorBase<GuardPoint>;
using GuardPoints = core::FixedVectorBase<core::Point2>;

// Appends to `candidates` every reading with m ≥ min_evidence whose height lies in the
// robot's band (slice_height_m(p, 0) .. slice_height_m(p, n − 1)) and where the model says
// free: occupancy(α, h, r) < p.safe_occupancy. `occupancy` is any callable
// (α [rad], h [m], r [m]) → m, e.g. the fitted ALN. Returns the number of readings that did
// not fit (the list was full); those are not kept.
template <typename Occupancy>
std::size_t collect_unexplained_features(std::span<const evidence::Reading> readings,
                                         const Occupancy& occupancy, const ExtractionParams& p,
                                         const FeatureGuardParams& g, GuardCandidates& candidates) {
  const float h_lo = slice_height_m(p, 0);
  const float h_hi = slice_height_m(p, p.height_count == 0 ? 0 : p.height_count - 1);
  std::size_t lost = 0;
  for (const evidence::Reading& rd : readings) {
    if (!(rd.m >= g.min_evidence) || !(rd.h_m >= h_lo && rd.h_m <= h_hi) ||
        !(rd.r_m > std::fabs(rd.h_m))) {
      continue;
    }
    if (!(occupancy(rd.alpha_rad, rd.h_m, rd.r_m) < p.safe_occupancy)) {
      continue;  // the model already holds this surface
    }
    const float rho = std::sqrt(rd.r_m * rd.r_m - rd.h_m * rd.h_m);
    if (!candidates.push_back(
            {rho * std::cos(rd.alpha_rad), rho * std::sin(rd.alpha_rad), rd.h_m})) {
      ++lost;
    }
  }
  return lost;
}

// Appends the candidates (robot frame, as x, y) with at least min_neighbours other
// candidates within neighbour_radius_m. O(n²) over the candidates, which are few: the
// features the model explains never get here. Returns false if `out` was full.
bool corroborated_points(std::span<const GuardPoint> candidates, const FeatureGuardParams& g,
                         GuardPoints& out);

}  // namespace boticelli::mapping
