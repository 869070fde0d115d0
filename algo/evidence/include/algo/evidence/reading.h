// Reading: one evidence point from stereo, in quasi-cylindrical coordinates about the PTU centre.
#pragma once

#include <cmath>

#include "algo/core/angles.h"
#include "algo/core/geometry.h"

namespace boticelli::evidence {

// Thesis §4.5.2 (quasi-cylindrical coordinates; the thesis uses dm, we use SI).
struct Reading {
  float alpha_rad = 0.0F;  // pan angle of the point about the PTU centre, in [0, 2π)
  float h_m = 0.0F;        // height of the point relative to the PTU centre [m]
  float r_m = 0.0F;        // distance from the PTU centre to the point [m]
  float m = 0.0F;          // evidence in [0, 1] (Eq 3.8)
  // Where its line of sight starts: the camera's optical centre when it was seen, PTU frame
  // [m] (x along pan 0, z up). All 0: the PTU centre, the thesis's origin of every ray.
  float view_x_m = 0.0F;
  float view_y_m = 0.0F;
  float view_z_m = 0.0F;
};

// The reading of the point (x, y, z) [m] in the PTU frame (§4.5.2): α = atan2(y, x) in
// [0, 2π), h = z, r = |(x, y, z)|; evidence m, seen from the PTU centre.
inline Reading reading_at(float x_m, float y_m, float z_m, float m) {
  Reading r;
  r.alpha_rad = core::wrap_two_pi(std::atan2(y_m, x_m));
  r.h_m = z_m;
  r.r_m = std::sqrt(x_m * x_m + (y_m * y_m + z_m * z_m));  // summed as Eigen sums a norm
  r.m = m;
  return r;
}

// ρ = √(r² − h²): the point's distance from the PTU's vertical axis [m] (0 when |h| ≥ r).
inline float horizontal_m(const Reading& r) {
  const float d = r.r_m * r.r_m - r.h_m * r.h_m;
  return d > 0.0F ? std::sqrt(d) : 0.0F;
}

// The point's foot on the floor plane in the robot frame [m] (the PTU axis is the robot's).
inline core::Point2 floor_point_m(const Reading& r) {
  const float rho = horizontal_m(r);
  return {rho * std::cos(r.alpha_rad), rho * std::sin(r.alpha_rad)};
}

}  // namespace boticelli::evidence
