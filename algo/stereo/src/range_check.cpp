// Calibration self-check: stereo ranges against the floor cue's (see range_check.h).
#include "algo/stereo/range_check.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace boticelli::stereo {

std::size_t RangeCheck::add_view(const FloorCue& cue, float pan_rad, float tilt_rad,
                                 const StereoPoint* points, std::size_t point_count) {
  const CameraPose pose = rig_.camera_pose(pan_rad, tilt_rad);
  const float cx = pose.centre_m.x();
  const float cy = pose.centre_m.y();
  const float floor_z = -rig_.params().ptu_height_m;
  // The walks' planes: through the optical centre, along the azimuth; the base's distance
  // along it from the centre, s with |c + s·a| = ρ.
  std::size_t planes = 0;
  for (std::size_t i = 0; i < cue.column_count() && planes < planes_.size(); ++i) {
    const FloorColumn& col = cue.column(i);
    if (col.end != FloorColumn::End::kBoundary || col.base_rho_m < params_.min_base_m ||
        col.base_rho_m > params_.max_base_m) {
      continue;
    }
    const float ax = std::cos(col.azimuth_rad);
    const float ay = std::sin(col.azimuth_rad);
    const float along_c = cx * ax + cy * ay;
    const float disc = along_c * along_c - (cx * cx + cy * cy) + col.base_rho_m * col.base_rho_m;
    if (!(disc > 0.0F)) continue;
    const float s_base = -along_c + std::sqrt(disc);
    if (!(s_base > 0.0F)) continue;
    planes_[planes++] = {ax, ay, s_base};
  }
  std::size_t added = 0;
  for (std::size_t k = 0; k < point_count && count_ < kCapacity; ++k) {
    const Eigen::Vector3f& p = points[k].point_ptu_m;
    const float height = p.z() - floor_z;
    if (height < params_.min_height_m || height > params_.max_height_m) continue;
    const float dx = p.x() - cx;
    const float dy = p.y() - cy;
    // The walk whose plane the point is nearest, within a column's width.
    float best_lateral = std::numeric_limits<float>::infinity();
    float best_ratio = 0.0F;
    for (std::size_t j = 0; j < planes; ++j) {
      const Plane& w = planes_[j];
      const float s = dx * w.ax + dy * w.ay;
      if (!(s > 0.0F)) continue;
      const float lateral = std::fabs(dx * w.ay - dy * w.ax);
      if (lateral > params_.lateral_m + params_.lateral_per_m * s || lateral >= best_lateral) {
        continue;
      }
      best_lateral = lateral;
      best_ratio = s / w.s_base_m;
    }
    if (best_ratio < params_.min_ratio || best_ratio > params_.max_ratio) continue;
    const float range_m = (p - pose.centre_m).norm();
    inverse_biases_[count_] = (1.0F - best_ratio) / range_m;
    ratios_[count_++] = best_ratio;
    ++added;
  }
  return added;
}

namespace {

// The median of the first `count` values (reordered); false when there are none.
template <std::size_t N>
bool median_of(std::array<float, N>& values, std::size_t count, float& median) {
  if (count == 0) return false;
  const auto middle = values.begin() + static_cast<std::ptrdiff_t>(count / 2);
  std::nth_element(values.begin(), middle, values.begin() + static_cast<std::ptrdiff_t>(count));
  median = *middle;
  return true;
}

}  // namespace

float updated_inverse_bias(float in_use_per_m, float residual_per_m, std::size_t pairs,
                           const StereoParams& params) {
  if (!params.self_calibration || pairs < params.self_calibration_min_pairs) return in_use_per_m;
  const float limit = params.self_calibration_max_bias_per_m;
  const float bias = std::clamp(in_use_per_m + residual_per_m, -limit, limit);
  return std::fabs(bias) < params.self_calibration_min_bias_per_m ? 0.0F : bias;
}

float bias_as_focal_scale(float bias_per_m, const RigParams& rig) {
  return 1.0F + bias_per_m * rig.lever_m;
}

float bias_as_tilt_step_error_rad(float bias_per_m, const RigParams& rig) {
  return bias_per_m * rig.lever_m * rig.tilt_step_rad;
}

bool RangeCheck::median(float& ratio, std::size_t& count) {
  count = count_;
  return median_of(ratios_, count_, ratio);
}

bool RangeCheck::inverse_bias(float& bias_per_m, std::size_t& count) {
  count = count_;
  return median_of(inverse_biases_, count_, bias_per_m);
}

}  // namespace boticelli::stereo
