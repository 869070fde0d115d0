// Intersection and exact robot-radius shrink of star-shaped navigation polygons (§5.4.2).
#pragma once

#include <span>

#include "algo/core/geometry.h"
#include "algo/mapping/star_polygon.h"

namespace boticelli::mapping {

// into ← into ∩ other, vertex by vertex: ρ_k = min(ρ_k, ρ'_k). Both polygons must have the
// same vertex count (returns false otherwise and leaves `into` unchanged). The result lies
// inside both polygons (each sector's triangle is inside both sectors' triangles) and equals
// the true intersection along every vertex ray; it is the largest polygon of this form that
// lies in the intersection.
bool intersect_into(StarPolygon& into, const StarPolygon& other);

// Shrinks `free_region` by the robot radius [m] into `out` (same vertex count) such that
// for every point p of `out` the robot's disc, moved in a straight line from the centre to
// p, never leaves `free_region` (dist(segment [0, p], boundary) ≥ radius). Exact, not an
// offset approximation: each ρ is the first contact of the ray with the radius-neighbourhood
// of the boundary (stadiums around the edges), then each sector's triangle is checked
// against the boundary and pulled in if the straight edge between two exact vertices would
// cut a corner (docs/mapping.md, step 5). Exact to 1 µm (chords may touch the
// neighbourhood that deep). Returns false (and all ρ = 0) if the disc at the centre already
// touches the boundary: the robot cannot move safely at all. Uses about 80 KB of stack.
bool shrink_by_radius(const StarPolygon& free_region, float radius_m, StarPolygon& out);

// Distance [m] from the centre to the polygon's boundary (the robot's present clearance).
[[nodiscard]] float boundary_clearance_m(const StarPolygon& region);

// Smallest distance [m] from the segment [0, p] (robot frame) to the polygon's boundary;
// the brute-force reference the tests and the planner's checks use (O(n)).
[[nodiscard]] float sweep_clearance_m(const StarPolygon& region, core::Point2 p);

// Pulls the polygon in front of each point (robot frame): both vertices of the sector
// holding it are cut to just below the point's distance (by 1 ppm), so the sector's triangle
// (inside the disc of the larger of the two) no longer contains it; a point within rounding of a
// vertex ray cuts both sectors beside that ray. Points at the centre close the polygon.
void exclude_points(std::span<const core::Point2> points, StarPolygon& free);

// The vertex whose ray is nearest the pan angle alpha_rad (any value): round(α / step) mod n,
// for a polygon of p's vertex count or of vertex_count (clamped as StarPolygon clamps it).
[[nodiscard]] std::size_t nearest_vertex(const StarPolygon& p, float alpha_rad);
[[nodiscard]] std::size_t nearest_vertex(std::size_t vertex_count, float alpha_rad);

// Moves to the front of `points` (robot frame), in their order, the ones a polygon of
// vertex_count vertices (clamped as StarPolygon clamps it) needs: per vertex, the first point that
// exclude_points cuts it nearest for, and per vertex ray the first point nearest the centre of
// those whose nearest vertex (nearest_vertex) it is; and the first point at the centre, if any.
// Returns how many. So exclude_points over the kept points cuts any polygon of that vertex count
// exactly as over all of them, and every vertex ray keeps its nearest point: a guard list keeps at
// most 2n + 1 points however many features corroborate a surface. Allocation-free (about 17 KB of
// stack).
std::size_t keep_points_that_cut(std::span<core::Point2> points, std::size_t vertex_count);

// Pulls the polygon in front of a disc of radius_m around each point (robot frame): both
// vertices of every sector the disc reaches into are cut to the disc's nearest distance
// within that sector, so no sector's triangle holds a point of the disc. A point nearer the centre
// than radius_m cuts only itself (a disc around the robot would close the polygon on a single stray
// reading).
void exclude_discs(std::span<const core::Point2> points, float radius_m, StarPolygon& free);

// Morphological opening of the radial function over a circular window of 2·half_width + 1
// vertices: every vertex takes the largest, over the windows holding it, of the window's
// smallest ρ. A wedge narrower than the window (a ray or two the fit left open through a
// wall, or that a stray far reading kept seen) is cut to its neighbours; anything wider stays
// as it was. Never grows the polygon. half_width 0 leaves it unchanged.
void open_spikes(StarPolygon& free, std::size_t half_width);

}  // namespace boticelli::mapping
