// Rig model of single-camera stereo: pan-tilt unit, L-shaped camera support and camera intrinsics.
#pragma once

#include <cstdint>

#include <Eigen/Core>

namespace boticelli::stereo {

// ---------------------------------------------------------------------------------------
// Frames (all right-handed, SI units):
//
// PTU frame (the robot frame of the readings): origin at the PTU centre, the point where
//   the pan axis meets the horizontal plane of the tilt axis; x forward (the robot's
//   heading), y left, z up. It does not pan or tilt. Readings {α, h, r} are taken about it.
//
// Camera frame: origin at the optical centre; x right, y down, z along the optical axis.
//
// Pixel coordinates (u, v): u column to the right, v row downwards; integer values are
//   pixel centres, (0, 0) is the centre of the top-left pixel. The thesis's centred
//   coordinates (§3.4.1, App. A) are i = u − principal_x (horizontal) and
//   j = v − principal_y (vertical, here positive downwards).
//
// Kinematics (App. A generalised): pan ψ turns about +z (counter-clockwise seen from above,
// i.e. positive pans left); tilt τ turns about the panned y axis, positive tilt raises the
// optical axis (looks up). The tilt axis passes through (tilt_axis_forward_m, 0,
// tilt_axis_up_m) of the panned frame. The L-shaped support holds the optical centre at
// distance L (lever_m) from the tilt axis; at zero tilt the lever points forward and is
// raised by the support angle Ω above the optical axis direction: the optical centre is at
// tilt axis + L·(cos Ω, 0, sin Ω) and the optical axis is horizontal (+x). Tilting rotates
// the lever and the camera together, so the second stereo frame, grabbed after tilting
// down by Φ (§3.4.1), sees from a centre moved by the baseline 2·L·sin(Φ/2) (≈ 2.8 cm for
// L = 21 cm, Φ = 7.7°).
// ---------------------------------------------------------------------------------------

// Pinhole camera with OpenCV's radial-tangential distortion (Brown-Conrady; the five
// coefficients calibrateCamera and ROS camera_calibration report, in their order k1, k2, p1,
// p2, k3), at one image resolution. With (x, y) undistorted normalised coordinates and
// ρ² = x² + y², the distorted ones are
//   x_d = x·(1 + k1·ρ² + k2·ρ⁴ + k3·ρ⁶) + 2·p1·x·y + p2·(ρ² + 2·x²)
//   y_d = y·(1 + k1·ρ² + k2·ρ⁴ + k3·ρ⁶) + p1·(ρ² + 2·y²) + 2·p2·x·y
// The coefficients are the same at every resolution (normalised coordinates).
struct CameraIntrinsics {
  float focal_px = 600.0F;        // F [px]
  float principal_x_px = 319.5F;  // principal point [px]
  float principal_y_px = 239.5F;
  float k1 = 0.0F;  // radial, ρ²
  float k2 = 0.0F;  // radial, ρ⁴
  float p1 = 0.0F;  // tangential
  float p2 = 0.0F;
  float k3 = 0.0F;  // radial, ρ⁶
  std::uint32_t width_px = 640;
  std::uint32_t height_px = 480;

  // Only k1 is set (or none): the one-term model, computed as it always was.
  [[nodiscard]] bool radial_k1_only() const {
    return k2 == 0.0F && p1 == 0.0F && p2 == 0.0F && k3 == 0.0F;
  }
  // Distorted normalised coordinates of undistorted ones (the model above).
  [[nodiscard]] Eigen::Vector2f distort(const Eigen::Vector2f& undistorted) const;

  // The camera seen through an image averaged in factor x factor blocks (low-resolution
  // pixel (u, v) covers full-resolution pixels [f·u, f·u + f) x [f·v, f·v + f)).
  [[nodiscard]] CameraIntrinsics downsampled(std::uint32_t factor) const;

  // Undistorted normalised coordinates (x/z, y/z) of a pixel: the model inverted by a fixed
  // number of fixed-point steps (as OpenCV's undistortPoints), point by point, allocation-free.
  [[nodiscard]] Eigen::Vector2f normalized_from_pixel(const Eigen::Vector2f& pixel) const;
  // Pixel of undistorted normalised coordinates (applies the distortion).
  [[nodiscard]] Eigen::Vector2f pixel_from_normalized(const Eigen::Vector2f& normalized) const;
  // Camera-frame point [m] → pixel; false (pixel untouched) if the point is not in front.
  [[nodiscard]] bool project(const Eigen::Vector3f& point_camera_m, Eigen::Vector2f& pixel) const;
  // Pixel → unit ray direction in the camera frame.
  [[nodiscard]] Eigen::Vector3f back_project(const Eigen::Vector2f& pixel) const;
};

// What a board declares about its rig (values of the thesis's robot by default).
struct RigParams {
  CameraIntrinsics camera;           // at full resolution (what the driver delivers)
  float lever_m = 0.21F;             // L: tilt axis to optical centre [m]
  float support_angle_rad = 0.0F;    // Ω: lever raised above the optical axis [rad]
  float tilt_axis_forward_m = 0.0F;  // tilt axis ahead of the pan axis [m]
  float tilt_axis_up_m =
      0.0F;                   // tilt axis above the PTU centre [m] (0 by definition of the centre)
  float ptu_height_m = 0.6F;  // PTU centre above the floor [m]
  float tilt_step_rad = 0.134390352F;   // Φ = 7.7°: tilt down between the two frames [rad]
  std::uint32_t downsample_factor = 4;  // full resolution → processing resolution (640 → 160)
};

// Pose of the camera in the PTU frame.
struct CameraPose {
  Eigen::Matrix3f rotation = Eigen::Matrix3f::Identity();  // camera frame → PTU frame
  Eigen::Vector3f centre_m = Eigen::Vector3f::Zero();      // optical centre in the PTU frame [m]

  [[nodiscard]] Eigen::Vector3f to_ptu(const Eigen::Vector3f& point_camera_m) const {
    return rotation * point_camera_m + centre_m;
  }
  [[nodiscard]] Eigen::Vector3f to_camera(const Eigen::Vector3f& point_ptu_m) const {
    return rotation.transpose() * (point_ptu_m - centre_m);
  }
};

class RigModel {
 public:
  RigModel() : RigModel(RigParams{}) {}
  explicit RigModel(const RigParams& params);

  [[nodiscard]] const RigParams& params() const { return params_; }
  // Intrinsics at full resolution and at the processing resolution (downsampled).
  [[nodiscard]] const CameraIntrinsics& camera() const { return params_.camera; }
  [[nodiscard]] const CameraIntrinsics& low_res_camera() const { return low_res_; }

  // Camera pose for pan ψ and tilt τ [rad] (see the frame description above).
  [[nodiscard]] CameraPose camera_pose(float pan_rad, float tilt_rad) const;
  // The pose of the second stereo frame: same pan, tilt − Φ.
  [[nodiscard]] CameraPose second_pose(float pan_rad, float tilt_rad) const {
    return camera_pose(pan_rad, tilt_rad - params_.tilt_step_rad);
  }
  // Stereo baseline |C(τ) − C(τ − Φ)| = 2·L·sin(Φ/2) [m].
  [[nodiscard]] float baseline_m() const;

  // Ray of a pixel (of `intrinsics`, full or low resolution) in the PTU frame: unit direction.
  [[nodiscard]] static Eigen::Vector3f ray_ptu(const CameraPose& pose,
                                               const CameraIntrinsics& intrinsics,
                                               const Eigen::Vector2f& pixel) {
    return pose.rotation * intrinsics.back_project(pixel);
  }
  // PTU-frame point → pixel of `intrinsics`; false if the point is behind the camera.
  [[nodiscard]] static bool project_ptu(const CameraPose& pose, const CameraIntrinsics& intrinsics,
                                        const Eigen::Vector3f& point_ptu_m,
                                        Eigen::Vector2f& pixel) {
    return intrinsics.project(pose.to_camera(point_ptu_m), pixel);
  }

 private:
  RigParams params_;
  CameraIntrinsics low_res_;
};

}  // namespace boticelli::stereo
