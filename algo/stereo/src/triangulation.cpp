// Triangulation (Eqs 3.2, 3.4), readings about the PTU centre, and the epipolar line (App. A).
#include "algo/stereo/triangulation.h"

#include <cmath>

#include <Eigen/Geometry>

namespace boticelli::stereo {

bool triangulate_exact(const Eigen::Vector3f& c1_m, const Eigen::Vector3f& d1,
                       const Eigen::Vector3f& c2_m, const Eigen::Vector3f& d2,
                       Eigen::Vector3f& point_m) {
  // Minimise |c1 + r·d1 − c2 − r'·d2|²: the normal equations of the 2x2 system.
  const Eigen::Vector3f w = c1_m - c2_m;
  const float b = d1.dot(d2);
  const float d = d1.dot(w);
  const float e = d2.dot(w);
  const float denom = 1.0F - b * b;
  if (!(denom > 1e-12F)) {
    return false;
  }
  const float r1 = (b * e - d) / denom;
  const float r2 = (e - b * d) / denom;
  if (!(r1 > 0.0F) || !(r2 > 0.0F)) {
    return false;
  }
  point_m = 0.5F * ((c1_m + r1 * d1) + (c2_m + r2 * d2));
  return true;
}

bool triangulate_fast(const CameraPose& first, const CameraPose& second,
                      const Eigen::Vector2f& normalized1, const Eigen::Vector2f& normalized2,
                      Eigen::Vector3f& point_camera1_m) {
  // Second centre and second ray in the first camera's frame (the tilt turns about x).
  const Eigen::Vector3f baseline = first.rotation.transpose() * (second.centre_m - first.centre_m);
  const Eigen::Vector3f ray2 =
      first.rotation.transpose() *
      (second.rotation * Eigen::Vector3f(normalized2.x(), normalized2.y(), 1.0F));
  if (!(ray2.z() > 1e-6F)) {
    return false;
  }
  const float tan_theta = normalized1.y();
  const float tan_theta2 = ray2.y() / ray2.z();
  const float denom = tan_theta - tan_theta2;
  if (std::fabs(denom) < 1e-9F) {
    return false;
  }
  const float z = (baseline.y() - baseline.z() * tan_theta2) / denom;
  if (!(z > 0.0F)) {
    return false;
  }
  point_camera1_m = Eigen::Vector3f(z * normalized1.x(), z * tan_theta, z);
  return true;
}

bool remove_inverse_range_bias(const Eigen::Vector3f& centre_m, float bias_per_m, float max_range_m,
                               Eigen::Vector3f& point_m) {
  const Eigen::Vector3f ray = point_m - centre_m;
  const float range_m = ray.norm();
  if (!(range_m > 0.0F)) return false;
  const float inverse = 1.0F / range_m - bias_per_m;  // 1/r = 1/r̂ − b
  if (!(inverse > 1.0F / max_range_m)) return false;
  point_m = centre_m + ray * (1.0F / (inverse * range_m));
  return true;
}

evidence::Reading reading_from_point(const Eigen::Vector3f& point_ptu_m, float evidence_m,
                                     const Eigen::Vector3f& view_ptu_m) {
  evidence::Reading reading =
      evidence::reading_at(point_ptu_m.x(), point_ptu_m.y(), point_ptu_m.z(), evidence_m);
  reading.view_x_m = view_ptu_m.x();
  reading.view_y_m = view_ptu_m.y();
  reading.view_z_m = view_ptu_m.z();
  return reading;
}

bool epipolar_line(const CameraPose& first, const CameraPose& second,
                   const CameraIntrinsics& intrinsics, float i_px, float j_px, float& slope_k,
                   float& offset_b_px) {
  // Two points of the line: the image of the ray's point at infinity (its direction) and
  // the epipole (the first centre) — both as homogeneous directions in camera 2.
  const Eigen::Vector2f pixel(i_px + intrinsics.principal_x_px, j_px + intrinsics.principal_y_px);
  const Eigen::Vector3f ray = RigModel::ray_ptu(first, intrinsics, pixel);
  const Eigen::Vector3f far_dir = second.rotation.transpose() * ray;
  const Eigen::Vector3f epipole = second.to_camera(first.centre_m);
  // Line through the two projective points: l = p × q; i' = K j' + B in centred pixels.
  const Eigen::Vector3f p(far_dir.x(), far_dir.y(), far_dir.z());
  const Eigen::Vector3f q(epipole.x(), epipole.y(), epipole.z());
  const Eigen::Vector3f l = p.cross(q);  // l·(x, y, 1) = 0 in normalised coordinates
  if (std::fabs(l.x()) < 1e-12F) {
    return false;
  }
  // Normalised x = −(l.y·y + l.z)/l.x; centred pixels scale both by F.
  slope_k = -l.y() / l.x();
  offset_b_px = -l.z() / l.x() * intrinsics.focal_px;
  return true;
}

}  // namespace boticelli::stereo
