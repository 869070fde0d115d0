// Plane segment geometry in double precision for the exact shrink (distances, ray casts).
#pragma once

#include <algorithm>
#include <cmath>
#include <limits>

namespace boticelli::mapping::detail {

struct Vec2d {
  double x = 0.0;
  double y = 0.0;
};

inline Vec2d operator+(Vec2d a, Vec2d b) {
  return {a.x + b.x, a.y + b.y};
}
inline Vec2d operator-(Vec2d a, Vec2d b) {
  return {a.x - b.x, a.y - b.y};
}
inline Vec2d operator*(double s, Vec2d a) {
  return {s * a.x, s * a.y};
}
inline double dot(Vec2d a, Vec2d b) {
  return a.x * b.x + a.y * b.y;
}
inline double cross(Vec2d a, Vec2d b) {
  return a.x * b.y - a.y * b.x;
}
inline double norm(Vec2d a) {
  return std::sqrt(dot(a, a));
}

inline constexpr double kNoHit = std::numeric_limits<double>::infinity();

// Distance from point p to segment [a, b].
inline double point_segment_distance(Vec2d p, Vec2d a, Vec2d b) {
  const Vec2d e = b - a;
  const double len2 = dot(e, e);
  double t = len2 > 0.0 ? dot(p - a, e) / len2 : 0.0;
  t = std::clamp(t, 0.0, 1.0);
  return norm(p - (a + t * e));
}

// True if the closed segments [a, b] and [c, d] share a point.
inline bool segments_intersect(Vec2d a, Vec2d b, Vec2d c, Vec2d d) {
  const double d1 = cross(b - a, c - a);
  const double d2 = cross(b - a, d - a);
  const double d3 = cross(d - c, a - c);
  const double d4 = cross(d - c, b - c);
  if (((d1 > 0.0 && d2 < 0.0) || (d1 < 0.0 && d2 > 0.0)) &&
      ((d3 > 0.0 && d4 < 0.0) || (d3 < 0.0 && d4 > 0.0))) {
    return true;
  }
  // Touching and collinear cases are covered by the zero distance of the endpoint tests.
  return false;
}

inline double segment_segment_distance(Vec2d a, Vec2d b, Vec2d c, Vec2d d) {
  if (segments_intersect(a, b, c, d)) {
    return 0.0;
  }
  return std::min({point_segment_distance(a, c, d), point_segment_distance(b, c, d),
                   point_segment_distance(c, a, b), point_segment_distance(d, a, b)});
}

// Squared distance from point p to segment [a, b].
inline double point_segment_distance2(Vec2d p, Vec2d a, Vec2d b) {
  const Vec2d e = b - a;
  const double len2 = dot(e, e);
  double t = len2 > 0.0 ? dot(p - a, e) / len2 : 0.0;
  t = std::clamp(t, 0.0, 1.0);
  const Vec2d d = p - (a + t * e);
  return dot(d, d);
}

// segment_segment_distance(a, b, c, d) < radius, without square roots and stopping at the
// first endpoint that is close enough.
inline bool segments_closer_than(Vec2d a, Vec2d b, Vec2d c, Vec2d d, double radius) {
  const double r2 = radius * radius;
  return segments_intersect(a, b, c, d) || point_segment_distance2(a, c, d) < r2 ||
         point_segment_distance2(b, c, d) < r2 || point_segment_distance2(c, a, b) < r2 ||
         point_segment_distance2(d, a, b) < r2;
}

inline bool point_in_triangle(Vec2d p, Vec2d a, Vec2d b, Vec2d c) {
  const double d1 = cross(b - a, p - a);
  const double d2 = cross(c - b, p - b);
  const double d3 = cross(a - c, p - c);
  const bool has_neg = d1 < 0.0 || d2 < 0.0 || d3 < 0.0;
  const bool has_pos = d1 > 0.0 || d2 > 0.0 || d3 > 0.0;
  return !(has_neg && has_pos);
}

// Distance between the triangle (a, b, c) (filled) and the segment [p, q].
inline double triangle_segment_distance(Vec2d a, Vec2d b, Vec2d c, Vec2d p, Vec2d q) {
  if (point_in_triangle(p, a, b, c) || point_in_triangle(q, a, b, c)) {
    return 0.0;
  }
  return std::min({segment_segment_distance(a, b, p, q), segment_segment_distance(b, c, p, q),
                   segment_segment_distance(c, a, p, q)});
}

// First t ≥ 0 where the ray t·u (|u| = 1) enters the disc of radius R around c.
inline double ray_circle_hit(Vec2d u, Vec2d c, double radius) {
  const double uc = dot(u, c);
  const double disc = uc * uc - (dot(c, c) - radius * radius);
  if (disc < 0.0) {
    return kNoHit;
  }
  const double t = uc - std::sqrt(disc);
  return t >= 0.0 ? t : kNoHit;
}

// First t ≥ 0 where the ray t·u crosses the segment [a, b].
inline double ray_segment_hit(Vec2d u, Vec2d a, Vec2d b) {
  const Vec2d e = b - a;
  const double den = cross(u, e);
  if (den == 0.0) {
    return kNoHit;
  }
  const double t = cross(a, e) / den;
  const double s = cross(a, u) / den;
  if (t < 0.0 || s < 0.0 || s > 1.0) {
    return kNoHit;
  }
  return t;
}

// First t ≥ 0 where the ray t·u (from outside) enters the stadium {x : dist(x, [a, b]) ≤ R}:
// the first contact with one of its two end circles or its two straight sides.
inline double ray_stadium_hit(Vec2d u, Vec2d a, Vec2d b, double radius) {
  double t = std::min(ray_circle_hit(u, a, radius), ray_circle_hit(u, b, radius));
  const Vec2d e = b - a;
  const double len = norm(e);
  if (len > 0.0) {
    const Vec2d n{-e.y / len * radius, e.x / len * radius};
    t = std::min(t, ray_segment_hit(u, a + n, b + n));
    t = std::min(t, ray_segment_hit(u, a - n, b - n));
  }
  return t;
}

}  // namespace boticelli::mapping::detail
