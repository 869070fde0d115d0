// Frame-pair processing: features → epipolar tracks → triangulation → Readings (Eq 3.8).
#include "algo/stereo/stereo_processor.h"

#include <algorithm>
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
    point.normalized_error = track.normalized_error;
    if (!triangulate(pose1, pose2, point.first_px, point.second_px, point.point_ptu_m)) {
      continue;
    }
    if (inverse_range_bias_ != 0.0F &&
        !remove_inverse_range_bias(pose1.centre_m, inverse_range_bias_,
                                   params_.self_calibration_max_range_m, point.point_ptu_m)) {
      continue;
    }
    point.range_camera_m = (point.point_ptu_m - pose1.centre_m).norm();
    if (point.range_camera_m < params_.min_range_m) {
      continue;
    }
    point.range_error_m =
        evidence::range_error_m(point.range_camera_m, baseline, camera.focal_px);  // Eq 3.7
    const float evidence = std::max(                                               // Eq 3.8
        evidence::evidence_from_match_error(track.match_error, params_.match_error_max),
        evidence::evidence_from_normalized_error(track.normalized_error,
                                                 params_.normalized_error_max));
    point.reading = reading_from_point(point.point_ptu_m, evidence, pose1.centre_m);
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
  if (params_.target_range_from_edges) {
    refine_target_range(first, second, pose1, pose2, fix);
  }
  if (inverse_range_bias_ != 0.0F &&
      !remove_inverse_range_bias(pose1.centre_m, inverse_range_bias_,
                                 params_.self_calibration_max_range_m, fix.point_ptu_m)) {
    return fix;
  }
  fix.range_error_m = evidence::range_error_m((fix.point_ptu_m - pose1.centre_m).norm(),
                                              (pose2.centre_m - pose1.centre_m).norm(),
                                              rig_.low_res_camera().focal_px);  // Eq 3.7
  fix.confidence =
      fix.first.confidence < fix.second.confidence ? fix.first.confidence : fix.second.confidence;
  fix.reading = reading_from_point(fix.point_ptu_m, fix.confidence);
  fix.found = true;
  return fix;
}

TargetFix StereoProcessor::locate_target_across(const TargetSighting& earlier,
                                                const TargetSighting& later) const {
  TargetFix fix;
  fix.first = earlier.detection;
  fix.second = later.detection;
  if (!earlier.detection.found || !later.detection.found) {
    return fix;
  }
  const CameraIntrinsics& camera = rig_.low_res_camera();
  const CameraPose pose1 = rig_.camera_pose(earlier.pan_rad, earlier.tilt_rad);
  const CameraPose pose2 = rig_.camera_pose(later.pan_rad, later.tilt_rad);
  const float baseline = (pose2.centre_m - pose1.centre_m).norm();
  if (!(baseline > rig_.baseline_m())) {
    return fix;
  }
  const Eigen::Vector3f d1 = RigModel::ray_ptu(
      pose1, camera, Eigen::Vector2f(earlier.detection.u_px, earlier.detection.v_px));
  const Eigen::Vector3f d2 =
      RigModel::ray_ptu(pose2, camera, Eigen::Vector2f(later.detection.u_px, later.detection.v_px));
  Eigen::Vector3f point;
  if (!triangulate_exact(pose1.centre_m, d1, pose2.centre_m, d2, point)) {
    return fix;
  }
  const float range = (point - pose1.centre_m).norm();
  if (range < params_.min_range_m) {
    return fix;
  }
  // The midpoint lies half the rays' gap from each: the gap against the pixel's footprint.
  const Eigen::Vector3f off = point - pose1.centre_m;
  const float gap = 2.0F * (off - off.dot(d1) * d1).norm();
  if (!(gap <= params_.target_across_max_gap_px * range / camera.focal_px)) {
    return fix;
  }
  fix.point_ptu_m = point;
  fix.range_error_m = evidence::range_error_m(range, baseline, camera.focal_px);  // Eq 3.7
  fix.confidence = earlier.detection.confidence < later.detection.confidence
                       ? earlier.detection.confidence
                       : later.detection.confidence;
  fix.reading = reading_from_point(fix.point_ptu_m, fix.confidence);
  fix.found = true;
  return fix;
}

void StereoProcessor::refine_target_range(const image::LowResFrame& first,
                                          const image::LowResFrame& second, const CameraPose& pose1,
                                          const CameraPose& pose2, TargetFix& fix) {
  // Edge pixels of the triangle (its box grown by one): strong vertical derivative, tracked
  // along their epipolar lines, triangulated; their horizontal distance from the PTU axis.
  // The paper is upright, so the vertex shares the distance of the triangle's middle, which
  // the median of a symmetric set of edges gives.
  const image::TargetDetection& d = fix.first;
  const std::uint32_t u0 = d.box_u_min > 0 ? d.box_u_min - 1 : 0;
  const std::uint32_t v0 = d.box_v_min > 0 ? d.box_v_min - 1 : 0;
  const std::uint32_t u1 = std::min(d.box_u_max + 1, first.width - 1);
  const std::uint32_t v1 = std::min(d.box_v_max + 1, first.height - 1);
  std::size_t n = 0;
  for (std::uint32_t v = std::max(v0, 3U); v <= v1 && v + 3 < first.height; ++v) {
    for (std::uint32_t u = std::max(u0, 3U); u <= u1 && u + 3 < first.width; ++u) {
      if (n >= edge_rho_.size()) break;
      const float g = 0.5F * std::fabs(first.y(u, v + 1) - first.y(u, v - 1));
      if (g < params_.target_edge_min_strength) continue;
      const Eigen::Vector2f px(static_cast<float>(u), static_cast<float>(v));
      image::EpipolarSegment segment;
      if (!epipolar_segment(pose1, pose2, px, segment)) continue;
      const image::Track t = image::track_feature(first, u, v, second, segment, params_.tracking);
      if (!t.found) continue;
      Eigen::Vector3f p;
      if (!triangulate(pose1, pose2, px, Eigen::Vector2f(t.u_px, t.v_px), p)) continue;
      edge_rho_[n++] = std::hypot(p.x(), p.y());
    }
  }
  // The vertex's own triangulation sets the window the edges may refine it in: a fraction of
  // the range error of one pixel of disparity (Eq 3.7) around its horizontal distance. Edges
  // outside it matched something else (near the target, many of a pair's edges can land on
  // the background and pull the median off by most of a metre).
  const float vertex_rho = std::hypot(fix.point_ptu_m.x(), fix.point_ptu_m.y());
  const float window = params_.target_edge_window *
                       evidence::range_error_m((fix.point_ptu_m - pose1.centre_m).norm(),
                                               (pose2.centre_m - pose1.centre_m).norm(),
                                               rig_.low_res_camera().focal_px);
  std::size_t inliers = 0;
  for (std::size_t i = 0; i < n; ++i) {
    if (std::fabs(edge_rho_[i] - vertex_rho) <= window) edge_rho_[inliers++] = edge_rho_[i];
  }
  n = inliers;
  if (n < params_.target_min_edges || n == 0) return;
  const auto mid = edge_rho_.begin() + static_cast<std::ptrdiff_t>(n / 2);
  std::nth_element(edge_rho_.begin(), mid, edge_rho_.begin() + static_cast<std::ptrdiff_t>(n));
  const float rho = *mid;
  // The vertex on its first-frame line of sight c + t·d at horizontal distance ρ:
  // |c_xy + t·d_xy|² = ρ², the far root (the line leaves the PTU axis outwards).
  const Eigen::Vector3f dir =
      RigModel::ray_ptu(pose1, rig_.low_res_camera(), Eigen::Vector2f(d.u_px, d.v_px));
  const Eigen::Vector2f c(pose1.centre_m.x(), pose1.centre_m.y());
  const Eigen::Vector2f e(dir.x(), dir.y());
  const float a = e.squaredNorm();
  const float b = 2.0F * c.dot(e);
  const float k = c.squaredNorm() - rho * rho;
  const float disc = b * b - 4.0F * a * k;
  if (!(a > 1e-9F) || !(disc >= 0.0F)) return;
  const float t = (-b + std::sqrt(disc)) / (2.0F * a);
  if (!(t > 0.0F)) return;
  fix.point_ptu_m = pose1.centre_m + t * dir;
  fix.edges = n;
}

}  // namespace boticelli::stereo
