// Frame-pair processing: features → epipolar tracks → triangulation → Readings (Eq 3.8).
#include "algo/stereo/stereo_processor.h"

#include <cmath>

#include "algo/evidence/sensor_model.h"
#include "algo/stereo/triangulation.h"

namespace boticelli::stereo {

StereoProcessor::StereoProcessor(const RigModel& rig, const StereoParams& params)
    : rig_(rig), params_(params), selector_(params.features), target_detector_(params.target) {}

std::size_t StereoProcessor::process_yuyv(const std::uint8_t* first_yuyv,
                                          const std::uint8_t* second_yuyv,
                                          std::uint32_t stride_bytes, const PairPose& pose,
                                          core::FixedVectorBase<evidence::Reading>& readings) {
  const CameraIntrinsics& camera = rig_.camera();
  const std::uint32_t factor = rig_.params().downsample_factor;
  if (!image::downsample_yuyv(first_yuyv, camera.width_px, camera.height_px, stride_bytes, factor,
                              first_) ||
      !image::downsample_yuyv(second_yuyv, camera.width_px, camera.height_px, stride_bytes, factor,
                              second_)) {
    features_.clear();
    points_.clear();
    return 0;
  }
  return process(first_, second_, pose, readings);
}

bool StereoProcessor::epipolar_segment(const CameraPose& first, const CameraPose& second,
                                       const Eigen::Vector2f& first_px,
                                       image::EpipolarSegment& segment) const {
  const CameraIntrinsics& camera = rig_.low_res_camera();
  const Eigen::Vector3f ray = RigModel::ray_ptu(first, camera, first_px);
  Eigen::Vector2f far_px;
  Eigen::Vector2f near_px;
  // The point at infinity projects like a point along the direction from the second centre.
  if (!RigModel::project_ptu(second, camera, second.centre_m + ray, far_px) ||
      !RigModel::project_ptu(second, camera, first.centre_m + params_.min_range_m * ray, near_px)) {
    return false;
  }
  segment = {far_px.x(), far_px.y(), near_px.x(), near_px.y()};
  return true;
}

bool StereoProcessor::triangulate(const CameraPose& first, const CameraPose& second,
                                  const Eigen::Vector2f& first_px, const Eigen::Vector2f& second_px,
                                  Eigen::Vector3f& point_ptu_m) const {
  const CameraIntrinsics& camera = rig_.low_res_camera();
  if (params_.fast_triangulation) {
    Eigen::Vector3f point_camera;
    if (!triangulate_fast(first, second, camera.normalized_from_pixel(first_px),
                          camera.normalized_from_pixel(second_px), point_camera)) {
      return false;
    }
    point_ptu_m = first.to_ptu(point_camera);
    return true;
  }
  return triangulate_exact(first.centre_m, RigModel::ray_ptu(first, camera, first_px),
                           second.centre_m, RigModel::ray_ptu(second, camera, second_px),
                           point_ptu_m);
}

std::size_t StereoProcessor::process(const image::LowResFrame& first,
                                     const image::LowResFrame& second, const PairPose& pose,
                                     core::FixedVectorBase<evidence::Reading>& readings) {
  features_.clear();
  points_.clear();
  const CameraIntrinsics& camera = rig_.low_res_camera();
  if (first.width != camera.width_px || first.height != camera.height_px ||
      second.width != first.width || second.height != first.height) {
    return 0;
  }
  const CameraPose pose1 = rig_.camera_pose(pose.pan_rad, pose.first_tilt_rad);
  const CameraPose pose2 = rig_.camera_pose(pose.pan_rad, pose.second_tilt_rad);
  const float baseline = (pose2.centre_m - pose1.centre_m).norm();
  selector_.select(first, {camera.principal_x_px, camera.principal_y_px, camera.focal_px},
                   features_);
  std::size_t appended = 0;
  for (const image::Feature& feature : features_) {
    const Eigen::Vector2f first_px(static_cast<float>(feature.u_px),
                                   static_cast<float>(feature.v_px));
    image::EpipolarSegment segment;
    if (!epipolar_segment(pose1, pose2, first_px, segment)) {
      continue;
    }
    const image::Track track =
        image::track_feature(first, feature.u_px, feature.v_px, second, segment, params_.tracking);
    if (!track.found) {
      continue;
    }
    StereoPoint point;
    point.first_px = first_px;
    point.second_px = Eigen::Vector2f(track.u_px, track.v_px);
    point.match_error = track.match_error;
    if (!triangulate(pose1, pose2, point.first_px, point.second_px, point.point_ptu_m)) {
      continue;
    }
    point.range_camera_m = (point.point_ptu_m - pose1.centre_m).norm();
    if (point.range_camera_m < params_.min_range_m) {
      continue;
    }
    point.range_error_m =
        evidence::range_error_m(point.range_camera_m, baseline, camera.focal_px);  // Eq 3.7
    point.reading = reading_from_point(
        point.point_ptu_m,
        evidence::evidence_from_match_error(track.match_error, params_.match_error_max));  // Eq 3.8
    if (!points_.push_back(point)) {
      break;
    }
    if (readings.push_back(point.reading)) {
      ++appended;
    }
  }
  return appended;
}

TargetFix StereoProcessor::locate_target(const image::LowResFrame& first,
                                         const image::LowResFrame& second, const PairPose& pose) {
  TargetFix fix;
  fix.first = target_detector_.detect(first);
  if (!fix.first.found) {
    return fix;
  }
  fix.second = target_detector_.detect(second);
  if (!fix.second.found) {
    return fix;
  }
  const CameraPose pose1 = rig_.camera_pose(pose.pan_rad, pose.first_tilt_rad);
  const CameraPose pose2 = rig_.camera_pose(pose.pan_rad, pose.second_tilt_rad);
  if (!triangulate(pose1, pose2, Eigen::Vector2f(fix.first.u_px, fix.first.v_px),
                   Eigen::Vector2f(fix.second.u_px, fix.second.v_px), fix.point_ptu_m)) {
    return fix;
  }
  fix.confidence =
      fix.first.confidence < fix.second.confidence ? fix.first.confidence : fix.second.confidence;
  fix.reading = reading_from_point(fix.point_ptu_m, fix.confidence);
  fix.found = true;
  return fix;
}

}  // namespace boticelli::stereo
