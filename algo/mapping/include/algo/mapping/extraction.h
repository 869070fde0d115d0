// Navigation polygon from the inverted occupancy function: r = F⁻¹(α, h, m_safe), ρ = √(r² − h²)
// (§5.4.1–5.4.2).
#pragma once

#include <algorithm>
#include <array>
#include <cmath>
#include <cstddef>
#include <span>

#include "algo/core/angles.h"
#include "algo/mapping/polygon_ops.h"
#include "algo/mapping/star_polygon.h"

namespace boticelli::mapping {

// Everything the extraction needs to know, in one place. Heights are measured from the
// floor; the occupancy model's h is relative to the PTU centre (thesis §4.5.2).
struct ExtractionParams {
  std::size_t vertex_count = kDefaultPolygonVertices;  // evenly spaced pan angles
  float safe_occupancy = 0.6F;     // m_safe: at most this occupancy is free (§5.4)
  float bounding_radius_m = 3.0F;  // beyond this the model is not trusted (§5.4.4)
  float robot_radius_m = 0.2F;     // the cylindrical robot's radius
  // Added to the robot radius for the shrink: the polygon knows the free range only along
  // its vertex rays, so an obstacle edge (a wall's end) between two rays can reach into a
  // sector by up to about ρ·Δθ (5 cm at 3 m with 360 rays).
  float clearance_margin_m = 0.05F;
  float ptu_height_m = 0.35F;     // PTU centre above the floor
  float lowest_height_m = 0.03F;  // lowest slice above the floor (ground clearance)
  float robot_height_m = 0.45F;   // top of the robot above the floor
  std::size_t height_count = 5;   // slices from lowest_height_m to robot_height_m
  // If > 0, the free polygon is the intersection of this many height bands covering
  // lowest_height_m .. robot_height_m (extract_band: safe by construction between heights)
  // instead of the height_count slices (the thesis's, §5.4.2). At most kMaxHeights.
  std::size_t band_count = 0;
  float seam_margin_rad = 0.2F;  // near α = 0 also read the model at α ± 2π (the α seam)
};

inline constexpr std::size_t kMaxHeights = 16;

// Height [m] of slice i relative to the PTU centre.
inline float slice_height_m(const ExtractionParams& p, std::size_t i) {
  const std::size_t n = std::clamp<std::size_t>(p.height_count, 1, kMaxHeights);
  const float t = n == 1 ? 0.0F : static_cast<float>(i) / static_cast<float>(n - 1);
  return p.lowest_height_m + t * (p.robot_height_m - p.lowest_height_m) - p.ptu_height_m;
}

// §5.4.2: the horizontal free distance ρ = √(r² − h²) for a free range r along the slice
// at height h, clipped to the bounding circle. No solution (r not finite, e.g. the model
// never reaches m_safe) is free up to the bounding circle; r ≤ |h| means the nearest point
// of the slice, straight above or below the PTU, is already occupied: ρ = 0.
inline float horizontal_free_distance_m(float r_m, float h_m, float bounding_radius_m) {
  if (std::isnan(r_m) || (std::isinf(r_m) && r_m > 0.0F)) {
    return bounding_radius_m;
  }
  if (!(r_m > std::fabs(h_m))) {
    return 0.0F;
  }
  return std::min(std::sqrt(r_m * r_m - h_m * h_m), bounding_radius_m);
}

namespace detail {

// The seam's vertex ranges: [0, low) lie within the seam margin above α = 0, [high, n) within
// it below 2π.
inline void seam_ranges(const StarPolygon& out, const ExtractionParams& p, std::size_t& low,
                        std::size_t& high) {
  const std::size_t n = out.vertex_count();
  low = 0;
  while (low < n && out.angle_rad(low) < p.seam_margin_rad) ++low;
  high = n;
  while (high > low && out.angle_rad(high - 1) > core::kTwoPi<float> - p.seam_margin_rad) --high;
}

// The polygon from a block range function ranges(step, first, count, offset, out), with
// horizontal distances for |h| = abs_h_m, the seam read at α ± 2π as extract_slice does.
template <typename Ranges>
void extract_blocks(const Ranges& ranges, float abs_h_m, const ExtractionParams& p,
                    StarPolygon& out) {
  out.set_vertex_count(p.vertex_count);
  const std::size_t n = out.vertex_count();
  const float two_pi = core::kTwoPi<float>;
  const float step = out.angle_step_rad();
  std::size_t low = 0;
  std::size_t high = n;
  seam_ranges(out, p, low, high);
  std::array<float, kMaxPolygonVertices> r;  // the first n filled below
  std::array<float, kMaxPolygonVertices> seam;
  ranges(step, 0, n, 0.0F, r.data());
  for (std::size_t k = 0; k < n; ++k) {
    out.set_rho_m(k, horizontal_free_distance_m(r[k], abs_h_m, p.bounding_radius_m));
  }
  ranges(step, 0, low, two_pi, seam.data());
  for (std::size_t k = 0; k < low; ++k) {
    out.set_rho_m(k, std::min(out.rho_m(k),
                              horizontal_free_distance_m(seam[k], abs_h_m, p.bounding_radius_m)));
  }
  ranges(step, high, n - high, -two_pi, seam.data());
  for (std::size_t k = high; k < n; ++k) {
    out.set_rho_m(k, std::min(out.rho_m(k), horizontal_free_distance_m(seam[k - high], abs_h_m,
                                                                       p.bounding_radius_m)));
  }
}

}  // namespace detail

// The free polygon of one slice: `free_range(α [rad], h [m])` returns r [m] with
// F(α, h, r) = m_safe (the inverted occupancy model, §5.4.1). Near the seam α = 0 the model
// is also read at α + 2π (and just below 2π at α − 2π), where the α-wrapped samples were
// fitted too (§4.9.1), and the smaller distance is kept: both describe the same direction.
// A free-range function that can also fill many angles at once
// (`ranges_at_height(h, step, first, count, offset, out)`, e.g. AlnFreeRange) is asked that
// way, for the whole slice and for the two seam stretches.
template <typename FreeRange>
void extract_slice(const FreeRange& free_range, float h_m, const ExtractionParams& p,
                   StarPolygon& out) {
  constexpr bool kBatch = requires(const FreeRange& f, float* r) {
    f.ranges_at_height(0.0F, 0.0F, std::size_t{0}, std::size_t{0}, 0.0F, r);
  };
  if constexpr (kBatch) {
    detail::extract_blocks(
        [&](float step, std::size_t first, std::size_t count, float offset, float* r) {
          free_range.ranges_at_height(h_m, step, first, count, offset, r);
        },
        h_m, p, out);
  } else {
    out.set_vertex_count(p.vertex_count);
    const std::size_t n = out.vertex_count();
    const float two_pi = core::kTwoPi<float>;
    std::size_t low = 0;
    std::size_t high = n;
    detail::seam_ranges(out, p, low, high);
    for (std::size_t k = 0; k < n; ++k) {
      const float alpha = out.angle_rad(k);
      float rho = horizontal_free_distance_m(free_range(alpha, h_m), h_m, p.bounding_radius_m);
      if (k < low) {
        rho = std::min(rho, horizontal_free_distance_m(free_range(alpha + two_pi, h_m), h_m,
                                                       p.bounding_radius_m));
      } else if (k >= high) {
        rho = std::min(rho, horizontal_free_distance_m(free_range(alpha - two_pi, h_m), h_m,
                                                       p.bounding_radius_m));
      }
      out.set_rho_m(k, rho);
    }
  }
}

// The free polygon of a height band [h_lo_m, h_hi_m] (relative to the PTU centre): along each
// vertex ray, a horizontal distance the occupancy stays below m_safe up to at every height of
// the band, never overestimated. The range is `free_range.ranges_over_band` (a lower bound on
// the band's nearest crossing, AlnFreeRange), and ρ = √(r² − H²) with H the band's largest
// |h|: for every h in the band, √(r(h)² − h²) ≥ √(r_lo² − H²). Unlike slices, nothing between
// two heights can be missed; a band as thin as a slice costs what a slice costs.
template <typename FreeRange>
void extract_band(const FreeRange& free_range, float h_lo_m, float h_hi_m,
                  const ExtractionParams& p, StarPolygon& out) {
  const float abs_h = std::max(std::fabs(h_lo_m), std::fabs(h_hi_m));
  detail::extract_blocks(
      [&](float step, std::size_t first, std::size_t count, float offset, float* r) {
        free_range.ranges_over_band(h_lo_m, h_hi_m, step, first, count, offset, r);
      },
      abs_h, p, out);
}

// Shrinks by the robot radius plus the margin. If the robot already stands closer than that
// to the boundary (a step planned on an earlier, coarser view can end there), by its
// present clearance instead (less 1 mm), so it can still move along or away but never
// closer; false (nowhere to go) once the clearance is below the bare robot radius.
inline bool shrink_for_robot(const StarPolygon& free, float robot_radius_m, float margin_m,
                             StarPolygon& out) {
  if (shrink_by_radius(free, robot_radius_m + margin_m, out)) {
    return true;
  }
  const float clearance = boundary_clearance_m(free) - 0.001F;
  return clearance >= robot_radius_m && shrink_by_radius(free, clearance, out);
}

// The local map of one cycle, in the robot frame.
struct LocalMap {
  StarPolygon free;       // intersection of the slices' polygons, within the bounding circle
  StarPolygon navigable;  // `free` shrunk by the robot radius: where the centre may go
  bool can_move = false;  // false if the robot's disc already touches an obstacle
};

// The free polygon over the robot's height band: the intersection of the height_count slices
// (§5.4.2), or with band_count > 0 of that many bands (extract_band). Bands need a free-range
// function with ranges_over_band (AlnFreeRange).
template <typename FreeRange>
void extract_free_polygon(const FreeRange& free_range, const ExtractionParams& p, StarPolygon& out,
                          StarPolygon& scratch) {
  if (p.band_count > 0) {
    if constexpr (requires(const FreeRange& f, float* r) {
                    f.ranges_over_band(0.0F, 0.0F, 0.0F, std::size_t{0}, std::size_t{0}, 0.0F, r);
                  }) {
      const std::size_t bands = std::min(p.band_count, kMaxHeights);
      const float lo = p.lowest_height_m - p.ptu_height_m;
      const float span = p.robot_height_m - p.lowest_height_m;
      const auto edge = [&](std::size_t i) {
        return lo + span * static_cast<float>(i) / static_cast<float>(bands);
      };
      extract_band(free_range, edge(0), edge(1), p, out);
      for (std::size_t i = 1; i < bands; ++i) {
        extract_band(free_range, edge(i), edge(i + 1), p, scratch);
        (void)intersect_into(out, scratch);
      }
      return;
    }
  }
  const std::size_t n = std::clamp<std::size_t>(p.height_count, 1, kMaxHeights);
  extract_slice(free_range, slice_height_m(p, 0), p, out);
  for (std::size_t i = 1; i < n; ++i) {
    extract_slice(free_range, slice_height_m(p, i), p, scratch);
    (void)intersect_into(out, scratch);
  }
}

// §5.4.2: the free polygon over the robot's height band (extract_free_polygon: slices, whose
// sufficiency rests on the slope bounds on h in the model, Eq 4.25, or bands), then shrunk
// exactly by the robot radius.
// `guard_points` (robot frame, e.g. from the feature guard, feature_guard.h) are obstacles
// the model may not hold: the polygon is pulled in front of them before the shrink.
template <typename FreeRange>
void extract_local_map(const FreeRange& free_range, const ExtractionParams& p, LocalMap& out,
                       StarPolygon& scratch, std::span<const core::Point2> guard_points = {}) {
  extract_free_polygon(free_range, p, out.free, scratch);
  exclude_points(guard_points, out.free);
  out.can_move = shrink_by_radius(out.free, p.robot_radius_m + p.clearance_margin_m, out.navigable);
}

}  // namespace boticelli::mapping
