// Feature guard: which unexplained features are corroborated by their neighbours.
#include "algo/mapping/feature_guard.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <limits>

#include "algo/core/angles.h"

namespace boticelli::mapping {

bool are_neighbours(const GuardPoint& a, const GuardPoint& b, const FeatureGuardParams& g) {
  // δr_a + δr_b (§3.7.3): see FeatureGuardParams for why the sum.
  const float delta_r = g.delta_r_fraction * (std::fabs(a.r_m) + std::fabs(b.r_m));
  const float radius = std::fmax(g.neighbour_radius_m, g.neighbour_delta_r_factor * delta_r);
  const float dx = b.x_m - a.x_m;
  const float dy = b.y_m - a.y_m;
  const float dh = b.h_m - a.h_m;
  const float d2 = dx * dx + dy * dy + dh * dh;
  if (!(g.lateral_radius_m > 0.0F)) {
    return d2 <= radius * radius;
  }
  // Along and across the mean line of sight from the PTU centre: the range error lies along
  // it; across it a reading is off by a pixel or two.
  const float sx = a.x_m + b.x_m;
  const float sy = a.y_m + b.y_m;
  const float sh = a.h_m + b.h_m;
  const float s2 = sx * sx + sy * sy + sh * sh;
  const float along = s2 > 1e-12F ? (dx * sx + dy * sy + dh * sh) / std::sqrt(s2) : 0.0F;
  const float across2 = std::fmax(d2 - along * along, 0.0F);
  // Never wider across than the ball the range error alone would allow.
  const float lateral = std::fmin(g.lateral_radius_m, radius);
  return std::fabs(along) <= radius && across2 <= lateral * lateral;
}

bool corroborated_points(std::span<const GuardPoint> candidates, const FeatureGuardParams& g,
                         GuardPoints& out) {
  return corroborated_points(candidates, 0, candidates.size(), g, out);
}

namespace {

// What every candidate's see-through test shares: the cone's cosine, how much farther a
// reading must be (both range errors) and the farthest a line of sight starts from the PTU
// centre (the camera's lever).
struct SeeThrough {
  float cos_max = 1.0F;
  float far_factor = 1.0F;
  float lever = 0.0F;
};

SeeThrough see_through_of(std::span<const evidence::Reading> readings,
                          const FeatureGuardParams& g) {
  SeeThrough st;
  st.cos_max = std::cos(g.see_through_angle_rad);
  st.far_factor = (1.0F + g.delta_r_fraction) / (1.0F - g.delta_r_fraction);
  for (const evidence::Reading& q : readings) {
    st.lever = std::fmax(st.lever, std::sqrt(q.view_x_m * q.view_x_m + q.view_y_m * q.view_y_m +
                                             q.view_z_m * q.view_z_m));
  }
  return st;
}

// One candidate's test. A reading seen past the candidate lies on a line of sight within the
// angle of it, from a view at most `lever` away: seen from the PTU centre its direction is
// within spread = angle + asin(lever / r) of the candidate's. So pans farther apart than
// pan_reach (1.05 spread / (cos(elevation) − spread), 5% for the small-angle approximation;
// every pan once the cone may hold the vertical) or ranges short of near_limit are skipped.
struct CandidateCone {
  bool testable = false;  // farther than the lever
  float alpha = 0.0F;     // pan of the candidate, (−π, π]
  float pan_reach = 0.0F;
  float near_limit = 0.0F;
};

CandidateCone cone_of(const GuardPoint& c, const SeeThrough& st, const FeatureGuardParams& g) {
  CandidateCone cone;
  const float r = std::sqrt(c.x_m * c.x_m + c.y_m * c.y_m + c.h_m * c.h_m);
  if (!(r > st.lever)) return cone;
  cone.testable = true;
  cone.alpha = std::atan2(c.y_m, c.x_m);
  const float cos_el = std::sqrt(c.x_m * c.x_m + c.y_m * c.y_m) / r;
  const float spread = g.see_through_angle_rad + std::asin(std::fmin(st.lever / r, 1.0F));
  cone.pan_reach = cos_el > spread ? 1.05F * spread / (cos_el - spread) : HUGE_VALF;
  cone.near_limit = (r - st.lever) * st.far_factor - st.lever;
  return cone;
}

// Whether reading q lies beyond candidate c (both range errors) within the angle of its line
// of sight from q's view.
bool sees_past(const evidence::Reading& q, const GuardPoint& c, const CandidateCone& cone,
               const SeeThrough& st) {
  // The pan difference's size folded into [0, π] without a library call or a branch: pans in
  // [0, 2π) and (−π, π] differ by less than 3π, where it is min(|d|, |2π − |d||); others
  // take std::remainder. One branch for both tests, which almost every reading fails.
  const float d = std::fabs(q.alpha_rad - cone.alpha);
  const float pan = d <= 3.0F * core::kPi<float>
                        ? std::min(d, std::fabs(core::kTwoPi<float> - d))
                        : std::fabs(std::remainder(d, core::kTwoPi<float>));
  if (!(q.r_m > cone.near_limit) | (pan > cone.pan_reach)) return false;
  // From q's view: u to q, w to the candidate; q beyond both range errors, within the angle.
  const core::Point2 qp = evidence::floor_point_m(q);
  const float ux = qp.x_m - q.view_x_m;
  const float uy = qp.y_m - q.view_y_m;
  const float uz = q.h_m - q.view_z_m;
  const float wx = c.x_m - q.view_x_m;
  const float wy = c.y_m - q.view_y_m;
  const float wz = c.h_m - q.view_z_m;
  const float u = std::sqrt(ux * ux + uy * uy + uz * uz);
  const float w = std::sqrt(wx * wx + wy * wy + wz * wz);
  if (!(u > w * st.far_factor)) return false;
  return ux * wx + uy * wy + uz * wz >= st.cos_max * u * w;
}

// Drops the candidates for which seen(c, cone) counts g.see_through_readings readings (it may
// stop counting there), keeping the others' order; returns how many went.
template <typename Seen>
std::size_t drop_where(GuardCandidates& candidates, const SeeThrough& st,
                       const FeatureGuardParams& g, const Seen& seen) {
  std::size_t kept = 0;
  for (std::size_t i = 0; i < candidates.size(); ++i) {
    const GuardPoint c = candidates[i];
    const CandidateCone cone = cone_of(c, st, g);
    if (!cone.testable || seen(c, cone) < g.see_through_readings) candidates[kept++] = c;
  }
  const std::size_t dropped = candidates.size() - kept;
  while (candidates.size() > kept) candidates.pop_back();
  return dropped;
}

}  // namespace

std::size_t drop_seen_through(std::span<const evidence::Reading> readings,
                              const FeatureGuardParams& g, GuardCandidates& candidates) {
  if (g.see_through_readings == 0 || !(g.delta_r_fraction < 1.0F)) return 0;
  const SeeThrough st = see_through_of(readings, g);
  return drop_where(candidates, st, g, [&](const GuardPoint& c, const CandidateCone& cone) {
    std::size_t through = 0;
    for (const evidence::Reading& q : readings) {
      if (sees_past(q, c, cone, st) && ++through >= g.see_through_readings) break;
    }
    return through;
  });
}

std::size_t drop_seen_through(std::span<const evidence::Reading> readings,
                              const FeatureGuardParams& g, GuardCandidates& candidates,
                              std::span<std::uint32_t> scratch) {
  if (g.see_through_readings == 0 || !(g.delta_r_fraction < 1.0F)) return 0;
  const std::size_t n = readings.size();
  bool ordered = scratch.size() >= n && n <= std::numeric_limits<std::uint32_t>::max();
  for (std::size_t k = 0; k < n && ordered; ++k) {
    const float a = readings[k].alpha_rad;
    ordered = a >= 0.0F && a < core::kTwoPi<float>;  // a Reading's pan, [0, 2π); not NaN
  }
  if (!ordered) return drop_seen_through(readings, g, candidates);
  const SeeThrough st = see_through_of(readings, g);
  // The readings by pan bucket (a counting sort, in reading order within a bucket).
  constexpr std::size_t kBuckets = 1024;  // 6 mrad each
  constexpr float kPerRad = static_cast<float>(kBuckets) / core::kTwoPi<float>;
  const auto bucket_of = [&](float a) {
    return std::min(static_cast<std::size_t>(a * kPerRad), kBuckets - 1);
  };
  std::array<std::uint32_t, kBuckets + 1> start{};
  for (const evidence::Reading& q : readings) ++start[bucket_of(q.alpha_rad) + 1];
  for (std::size_t b = 0; b < kBuckets; ++b) start[b + 1] += start[b];
  std::array<std::uint32_t, kBuckets> next{};
  std::copy_n(start.begin(), kBuckets, next.begin());
  const std::span<std::uint32_t> order = scratch.first(n);
  for (std::size_t k = 0; k < n; ++k) {
    order[next[bucket_of(readings[k].alpha_rad)]++] = static_cast<std::uint32_t>(k);
  }
  return drop_where(candidates, st, g, [&](const GuardPoint& c, const CandidateCone& cone) {
    std::size_t through = 0;
    const auto scan = [&](std::size_t from, std::size_t to) {
      for (std::size_t k = from; k < to && through < g.see_through_readings; ++k) {
        if (sees_past(readings[order[k]], c, cone, st)) ++through;
      }
    };
    // The buckets holding the pans within reach, widened by a milliradian (sees_past still
    // applies the reach itself, so the wider window only costs the readings at its edges).
    const float reach = cone.pan_reach + 1e-3F;
    if (!(reach < core::kPi<float>)) {  // also NaN
      scan(0, n);
      return through;
    }
    const float a = cone.alpha < 0.0F ? cone.alpha + core::kTwoPi<float> : cone.alpha;
    const auto first = static_cast<std::ptrdiff_t>(std::floor((a - reach) * kPerRad));
    const auto last = static_cast<std::ptrdiff_t>(std::floor((a + reach) * kPerRad));
    constexpr auto kCount = static_cast<std::ptrdiff_t>(kBuckets);
    if (last - first + 1 >= kCount) {  // every bucket: all readings, each once
      scan(0, n);
      return through;
    }
    for (std::ptrdiff_t b = first; b <= last && through < g.see_through_readings; ++b) {
      const auto wrapped = static_cast<std::size_t>((b % kCount + kCount) % kCount);
      scan(start[wrapped], start[wrapped + 1]);
    }
    return through;
  });
}

void sort_guard_candidates(std::span<GuardPoint> candidates) {
  std::sort(candidates.begin(), candidates.end(),
            [](const GuardPoint& a, const GuardPoint& b) { return a.x_m < b.x_m; });
}

bool corroborated_points(std::span<const GuardPoint> candidates, std::size_t first,
                         std::size_t last, const FeatureGuardParams& g, GuardPoints& out) {
  // Sorted by x (sort_guard_candidates): only candidates within the largest radius a pair
  // with this one can have, along x, can be neighbours; else every pair is tried.
  const bool sorted =
      std::is_sorted(candidates.begin(), candidates.end(),
                     [](const GuardPoint& a, const GuardPoint& b) { return a.x_m < b.x_m; });
  float r_max = 0.0F;
  for (const GuardPoint& c : candidates) {
    r_max = std::fmax(r_max, std::fabs(c.r_m));
  }
  bool ok = true;
  const std::size_t n = candidates.size();
  for (std::size_t i = first; i < std::min(last, n); ++i) {
    const GuardPoint& a = candidates[i];
    const std::size_t required = a.m < g.min_evidence ? g.min_weak_neighbours : g.min_neighbours;
    std::size_t neighbours = 0;
    if (sorted) {
      // |Δx| ≤ |b − a| ≤ along + across bound.
      const float reach =
          std::fmax(g.neighbour_radius_m,
                    g.neighbour_delta_r_factor * g.delta_r_fraction * (std::fabs(a.r_m) + r_max)) +
          std::fmax(g.lateral_radius_m, 0.0F);
      for (std::size_t j = i + 1; j < n && neighbours < required; ++j) {
        if (candidates[j].x_m - a.x_m > reach) break;
        neighbours += are_neighbours(a, candidates[j], g) ? 1U : 0U;
      }
      for (std::size_t j = i; j-- > 0 && neighbours < required;) {
        if (a.x_m - candidates[j].x_m > reach) break;
        neighbours += are_neighbours(a, candidates[j], g) ? 1U : 0U;
      }
    } else {
      for (std::size_t j = 0; j < n && neighbours < required; ++j) {
        if (j != i && are_neighbours(a, candidates[j], g)) {
          ++neighbours;
        }
      }
    }
    if (neighbours >= required && !out.push_back({a.x_m, a.y_m})) {
      ok = false;
    }
  }
  return ok;
}

}  // namespace boticelli::mapping
