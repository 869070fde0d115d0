// Feature guard: features the fitted occupancy model calls free, kept as hard obstacles of the
// navigation polygon when other such features corroborate them.
#pragma once

#include <cmath>
#include <cstddef>
#include <cstdint>
#include <span>

#include "algo/core/fixed_vector.h"
#include "algo/core/geometry.h"
#include "algo/evidence/ray_samples.h"
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
//
// Corroboration follows the stereo's range error. A reading lies about δr = delta_r_fraction · r
// from its surface along its ray (the sensor model's δr, §3.7.3, Eq 3.7); real readings of a
// plain table at 2–3 m scatter by a median 0.26 m, so a fixed 0.1 m radius finds no cluster
// there. Two candidates are neighbours when their 3-D distance is at most
//   max(neighbour_radius_m, neighbour_delta_r_factor · (δr_a + δr_b)).
// The sum, not the larger δr: if each reading is within its δr of a surface point, two
// readings of surface points d apart are at most d + δr_a + δr_b apart (triangle inequality),
// so the sum is the smallest radius that still lets every pair of readings of a small patch
// (d → 0) find each other; the larger δr alone misses the pairs whose errors are both near
// their bound in opposite directions (up to 2δr apart). Near the camera δr is small and the
// fixed radius rules.
struct FeatureGuardParams {
  float min_evidence = 0.6F;        // features this occupied are surfaces (m_safe, §5.4)
  float neighbour_radius_m = 0.1F;  // corroboration: unexplained features this close (3-D)
  std::size_t min_neighbours = 4;   // at least this many others within the radius
  // δr / r of the readings, the sensor model's (evidence::RaySampleParams, §3.7.3).
  float delta_r_fraction = evidence::RaySampleParams{}.delta_r_fraction;
  // Neighbour radius in units of the pair's summed range error δr_a + δr_b (0: fixed radius).
  float neighbour_delta_r_factor = 1.0F;
  // If > 0, that radius holds only along the pair's mean line of sight (where the range error
  // lies) and across it they must be within lateral_radius_m [m]. With a ball of the range
  // error's radius (0.6 m at 3 m), thousands of unexplained readings of a coarse fit find
  // four stray mismatches anywhere in free space to corroborate them.
  float lateral_radius_m = 0.25F;
  // Weak features, min_weak_evidence ≤ m < min_evidence: their ray samples (§4.5) plateau at
  // m, so the fit cannot raise F to m_safe (0.6) on them however many there are, and only
  // the guard can keep such a surface. Being more likely mismatches (Eq 3.8: m = 0.4 is a
  // match error of 0.77 E_max), they need min_weak_neighbours others within the radius.
  // min_weak_evidence ≥ min_evidence turns this off.
  float min_weak_evidence = 0.4F;
  std::size_t min_weak_neighbours = 8;
  // A stereo feature whose line of sight meets the floor within floor_delta_r_factor · δr
  // beyond it is not a candidate: a floor texture mismatch puts readings there, along the
  // ray (Eq 3.7), and near the robot, where the rays are steep, a few percent of the floor's
  // readings end up above the lowest slice; corroborating each other, they ring the robot
  // with obstacles that are not there. With δr = 0.1 r and 2 δr this is the lowest
  // 0.35 · (1 − 1/1.2) = 0.06 m above the floor at any range (PTU 0.35 m up). Obstacles
  // there are the floor cue's to report (its bases are exempt), and the fit keeps every
  // reading. 0 turns this off.
  float floor_delta_r_factor = 2.0F;
  // Seen through (not in the thesis): a candidate is dropped when at least
  // see_through_readings readings lie beyond it on their lines of sight (from the camera's
  // optical centre, Reading::view_*), within see_through_angle_rad of the direction to it
  // and beyond by more than both range errors (d_b (1 − δr/r) > d_a (1 + δr/r)): the camera
  // saw past it there, so nothing stands at it. Stereo mismatches that land in front of a
  // surface (§4.8.2's outliers) then do not corroborate each other into a phantom wall.
  // 0 turns this off.
  std::size_t see_through_readings = 0;
  float see_through_angle_rad = 0.02F;
};

// A feature in the robot frame: x, y [m] on the floor plane, h [m] relative to the PTU centre,
// its range r [m] from the PTU centre (gives its range error δr; 0: unknown, then only the
// fixed radius applies) and its evidence m (below min_evidence: a weak feature).
struct GuardPoint {
  float x_m = 0.0F;
  float y_m = 0.0F;
  float h_m = 0.0F;
  float r_m = 0.0F;
  float m = 1.0F;
};

// A look's stereo features and floor-cue bases in the robot's height band: thousands of them
// are unexplained when the fit is coarse (1,000–6,700 a look on rendered frames), and every
// one dropped is a surface left unguarded.
inline constexpr std::size_t kMaxGuardCandidates = 16384;
inline constexpr std::size_t kMaxGuardPoints = 16384;

using GuardCandidates = core::FixedVectorBase<GuardPoint>;
using GuardPoints = core::FixedVectorBase<core::Point2>;

// Appends to `candidates` every reading with m ≥ min(min_evidence, min_weak_evidence) whose
// height lies in the robot's band (slice_height_m(p, 0) .. slice_height_m(p, n − 1)) and where
// the model says free: occupancy(α, h, r) < p.safe_occupancy. `occupancy` is any callable
// (α [rad], h [m], r [m]) → m, e.g. the fitted ALN. Returns the number of readings that did
// not fit (the list was full). Stereo features on the floor's line of sight within
// floor_delta_r_factor · δr are left out (FeatureGuardParams); `floor_cue_bases` says the
// readings are the floor cue's obstacle bases, which never are. Those not fitting are
// dropped, not kept: the list holds the first ones in
// reading order, so with a full list a surface seen late in the readings may go unguarded.
// kMaxGuardCandidates is sized so that this does not happen in a room the model explains
// (only unexplained features get here); a caller that gets a non-zero count should report it
// (the guard is then incomplete, not wrong).
template <typename Occupancy>
std::size_t collect_unexplained_features(std::span<const evidence::Reading> readings,
                                         const Occupancy& occupancy, const ExtractionParams& p,
                                         const FeatureGuardParams& g, GuardCandidates& candidates,
                                         bool floor_cue_bases = false) {
  const float h_lo = slice_height_m(p, 0);
  const float h_floor = -p.ptu_height_m;
  const float floor_reach = g.floor_delta_r_factor * g.delta_r_fraction;
  const float h_hi = slice_height_m(p, p.height_count == 0 ? 0 : p.height_count - 1);
  std::size_t lost = 0;
  for (const evidence::Reading& rd : readings) {
    if (!(rd.m >= std::fmin(g.min_evidence, g.min_weak_evidence)) ||
        !(rd.h_m >= h_lo && rd.h_m <= h_hi) || !(rd.r_m > std::fabs(rd.h_m))) {
      continue;
    }
    // The ray meets the floor at r · h_floor / h (h < 0): within floor_reach · r beyond r?
    if (!floor_cue_bases && floor_reach > 0.0F && rd.h_m < 0.0F &&
        rd.r_m * h_floor / rd.h_m - rd.r_m <= floor_reach * rd.r_m) {
      continue;  // indistinguishable from a mismatched floor texture
    }
    if (!(occupancy(rd.alpha_rad, rd.h_m, rd.r_m) < p.safe_occupancy)) {
      continue;  // the model already holds this surface
    }
    const float rho = std::sqrt(rd.r_m * rd.r_m - rd.h_m * rd.h_m);
    if (!candidates.push_back(
            {rho * std::cos(rd.alpha_rad), rho * std::sin(rd.alpha_rad), rd.h_m, rd.r_m, rd.m})) {
      ++lost;
    }
  }
  return lost;
}

// Removes the candidates the readings saw through (FeatureGuardParams::see_through_readings;
// nothing if 0), keeping the others' order; returns how many went. O(candidates × readings),
// most pairs rejected on their ranges and pan angles alone. A candidate nearer the PTU centre
// than the farthest view stays.
std::size_t drop_seen_through(std::span<const evidence::Reading> readings,
                              const FeatureGuardParams& g, GuardCandidates& candidates);
// The same candidates dropped, with the readings ordered by pan in `scratch` (one index per
// reading; a counting sort into 1024 pan buckets) so that each candidate looks only at those
// in the buckets within its pan reach: O(readings + candidates × readings in reach), about
// 8 KB of stack. With scratch smaller than the readings, more than 2^32 readings or a pan
// outside [0, 2π), the plain scan above.
std::size_t drop_seen_through(std::span<const evidence::Reading> readings,
                              const FeatureGuardParams& g, GuardCandidates& candidates,
                              std::span<std::uint32_t> scratch);

// Orders candidates by x, so corroborated_points looks only at those within reach along x.
void sort_guard_candidates(std::span<GuardPoint> candidates);

// Appends the candidates (robot frame, as x, y) with at least min_neighbours other
// candidates (min_weak_neighbours for a weak one, m < min_evidence) within the pair's
// neighbour radius (FeatureGuardParams). Neighbours of either kind count. Sorted by x
// (sort_guard_candidates), each candidate is compared only with those whose x is within the
// largest radius it can have with any of them; unsorted, with all (O(n²)); the points are the
// same either way. Returns false if `out` was full.
bool corroborated_points(std::span<const GuardPoint> candidates, const FeatureGuardParams& g,
                         GuardPoints& out);
// The same for candidates [first, last) only (each still against all of them), so the
// O(n²) work can be cut into bounded units; consecutive ranges give the same points.
bool corroborated_points(std::span<const GuardPoint> candidates, std::size_t first,
                         std::size_t last, const FeatureGuardParams& g, GuardPoints& out);

// Whether candidates a and b corroborate each other (the rule above).
bool are_neighbours(const GuardPoint& a, const GuardPoint& b, const FeatureGuardParams& g);

}  // namespace boticelli::mapping
