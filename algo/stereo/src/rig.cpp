// Rig kinematics and the pinhole camera with radial-tangential distortion (App. A generalised).
#include "algo/stereo/rig.h"

#include <cmath>

#include <Eigen/Geometry>

namespace boticelli::stereo {

CameraIntrinsics CameraIntrinsics::downsampled(std::uint32_t factor) const {
  if (factor <= 1) {
    return *this;
  }
  const auto f = static_cast<float>(factor);
  // Block centre in full-resolution pixels: f·u + (f − 1)/2.
  const float offset = 0.5F * (f - 1.0F);
  CameraIntrinsics out = *this;
  out.focal_px = focal_px / f;
  out.principal_x_px = (principal_x_px - offset) / f;
  out.principal_y_px = (principal_y_px - offset) / f;
  out.width_px = width_px / factor;
  out.height_px = height_px / factor;
  return out;
}

Eigen::Vector2f CameraIntrinsics::normalized_from_pixel(const Eigen::Vector2f& pixel) const {
  Eigen::Vector2f distorted((pixel.x() - principal_x_px) / focal_px,
                            (pixel.y() - principal_y_px) / focal_px);
  if (radial_k1_only()) {
    if (k1 == 0.0F) {
      return distorted;
    }
    // Fixed point of x = x_d / (1 + k1·|x|²); converges fast for the mild k1 of webcams.
    Eigen::Vector2f x = distorted;
    for (int iteration = 0; iteration < 8; ++iteration) {
      x = distorted / (1.0F + k1 * x.squaredNorm());
    }
    return x;
  }
  // Fixed point of x = (x_d − tangential(x)) / radial(x), OpenCV's undistortPoints iteration
  // (there 5 steps by default); 20 settle calibrated webcam lenses to well under 1e-5 (a
  // hundredth of a pixel at F = 600 px) across the image.
  const float x0 = distorted.x();
  const float y0 = distorted.y();
  float x = x0;
  float y = y0;
  for (int iteration = 0; iteration < 20; ++iteration) {
    const float r2 = x * x + y * y;
    const float radial = 1.0F + ((k3 * r2 + k2) * r2 + k1) * r2;
    const float dx = 2.0F * p1 * x * y + p2 * (r2 + 2.0F * x * x);
    const float dy = p1 * (r2 + 2.0F * y * y) + 2.0F * p2 * x * y;
    x = (x0 - dx) / radial;
    y = (y0 - dy) / radial;
  }
  return {x, y};
}

Eigen::Vector2f CameraIntrinsics::distort(const Eigen::Vector2f& undistorted) const {
  const float x = undistorted.x();
  const float y = undistorted.y();
  const float r2 = x * x + y * y;
  const float radial = 1.0F + ((k3 * r2 + k2) * r2 + k1) * r2;
  return {x * radial + 2.0F * p1 * x * y + p2 * (r2 + 2.0F * x * x),
          y * radial + p1 * (r2 + 2.0F * y * y) + 2.0F * p2 * x * y};
}

Eigen::Vector2f CameraIntrinsics::pixel_from_normalized(const Eigen::Vector2f& normalized) const {
  if (radial_k1_only()) {
    const float scale = 1.0F + k1 * normalized.squaredNorm();
    return {principal_x_px + focal_px * scale * normalized.x(),
            principal_y_px + focal_px * scale * normalized.y()};
  }
  const Eigen::Vector2f d = distort(normalized);
  return {principal_x_px + focal_px * d.x(), principal_y_px + focal_px * d.y()};
}

bool CameraIntrinsics::project(const Eigen::Vector3f& point_camera_m,
                               Eigen::Vector2f& pixel) const {
  if (!(point_camera_m.z() > 1e-6F)) {
    return false;
  }
  pixel = pixel_from_normalized(point_camera_m.head<2>() / point_camera_m.z());
  return true;
}

Eigen::Vector3f CameraIntrinsics::back_project(const Eigen::Vector2f& pixel) const {
  const Eigen::Vector2f n = normalized_from_pixel(pixel);
  return Eigen::Vector3f(n.x(), n.y(), 1.0F).normalized();
}

RigModel::RigModel(const RigParams& params)
    : params_(params), low_res_(params.camera.downsampled(params.downsample_factor)) {}

CameraPose RigModel::camera_pose(float pan_rad, float tilt_rad) const {
  // Camera axes at zero pan and tilt, in the PTU frame: x right = −y, y down = −z, z = +x.
  Eigen::Matrix3f camera_at_rest;
  camera_at_rest << 0.0F, 0.0F, 1.0F,  //
      -1.0F, 0.0F, 0.0F,               //
      0.0F, -1.0F, 0.0F;
  const Eigen::Matrix3f pan =
      Eigen::AngleAxisf(pan_rad, Eigen::Vector3f::UnitZ()).toRotationMatrix();
  // Positive tilt raises the optical axis: a turn about −y of the panned frame.
  const Eigen::Matrix3f tilt =
      Eigen::AngleAxisf(-tilt_rad, Eigen::Vector3f::UnitY()).toRotationMatrix();
  const Eigen::Vector3f axis_point(params_.tilt_axis_forward_m, 0.0F, params_.tilt_axis_up_m);
  const Eigen::Vector3f lever =
      params_.lever_m * Eigen::Vector3f(std::cos(params_.support_angle_rad), 0.0F,
                                        std::sin(params_.support_angle_rad));
  CameraPose pose;
  pose.rotation = pan * tilt * camera_at_rest;
  pose.centre_m = pan * (axis_point + tilt * lever);
  return pose;
}

float RigModel::baseline_m() const {
  return 2.0F * params_.lever_m * std::sin(0.5F * params_.tilt_step_rad);
}

}  // namespace boticelli::stereo
