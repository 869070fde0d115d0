// Triangulation from two camera poses: exact (Eq 3.2) and the thesis's fast form (Eq 3.4).
#pragma once

#include <Eigen/Core>

#include "algo/evidence/reading.h"
#include "algo/stereo/rig.h"

namespace boticelli::stereo {

// Eq 3.2 (R·m'·r' = m·r − h) solved in the least-squares sense: the point midway between
// the closest points of the two rays c1 + r·d1 and c2 + r'·d2 (unit directions, PTU frame).
// False if the rays are parallel or the point is not in front of both cameras.
bool triangulate_exact(const Eigen::Vector3f& c1_m, const Eigen::Vector3f& d1,
                       const Eigen::Vector3f& c2_m, const Eigen::Vector3f& d2,
                       Eigen::Vector3f& point_m);

// Eq 3.4 generalised to any L, Ω, Φ: the motion of a feature is taken as purely vertical,
// so depth comes from the two vertical angles only. In the first camera's frame, with
// tan θ = y1 (normalised row of the feature), tan θ'' the slope y/z of the second ray
// (θ' turned by the tilt) and (0, b_y, b_z) the second optical centre:
//   Z = (b_y − b_z·tan θ'') / (tan θ − tan θ''),  X = Z·x1,  Y = Z·y1.
// Returns the point in the first camera's frame; false if Z ≤ 0 or the rays are parallel.
bool triangulate_fast(const CameraPose& first, const CameraPose& second,
                      const Eigen::Vector2f& normalized1, const Eigen::Vector2f& normalized2,
                      Eigen::Vector3f& point_camera1_m);

// A tilt pair's range is the parallax left once the tilt step Φ is taken out with the
// configured focal length: a focal length f·s or a step Φ·k a little off leaves a parallax of
// about (s − 1)·f·Φ (or (k − 1)·f·Φ) on every point, which adds the same b to every inverse
// range, 1/r̂ = 1/r + b (b ≈ (s − 1)/L for a lever arm L: 0.048 m⁻¹ for 1 % and L = 0.21 m,
// 3 m read as 2.6 m). This moves point_m along its line of sight from centre_m to the range r
// of 1/r = 1/r̂ − b. False (point_m untouched) when that is beyond max_range_m or behind the
// camera (1/r̂ ≤ b + 1/max_range_m): what the bias says is farther than anything measured.
bool remove_inverse_range_bias(const Eigen::Vector3f& centre_m, float bias_per_m, float max_range_m,
                               Eigen::Vector3f& point_m);

// A PTU-frame point as a Reading about the PTU centre (§4.5.2): α = atan2(y, x) in [0, 2π),
// h = z, r = |p|; m is the evidence (Eq 3.8); seen from view_ptu_m (the camera's optical
// centre, PTU frame; Reading::view_*).
evidence::Reading reading_from_point(const Eigen::Vector3f& point_ptu_m, float evidence_m,
                                     const Eigen::Vector3f& view_ptu_m = Eigen::Vector3f::Zero());

// App. A: the epipolar line i' = K·j' + B in the second frame for the feature at centred
// pixel (i, j) of the first (i = u − c_x, j = v − c_y; pixels of `intrinsics`), from the
// two poses rather than the thesis's closed form (A.4, A.5), which it reduces to for
// Ω = 0 and no offsets. Returns false if the line is horizontal in the image.
bool epipolar_line(const CameraPose& first, const CameraPose& second,
                   const CameraIntrinsics& intrinsics, float i_px, float j_px, float& slope_k,
                   float& offset_b_px);

}  // namespace boticelli::stereo
