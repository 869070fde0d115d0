// Calibration self-check: stereo ranges against the floor cue's (see range_check.h).
#include "algo/stereo/range_check.h"

#include <algorithm>
#include <cmath>

namespace boticelli::stereo {

std::size_t RangeCheck::add_view(const FloorCue& cue, float pan_rad, float tilt_rad,
                                 const StereoPoint* points, std::size_t point_count) {
  const CameraPose pose = rig_.camera_pose(pan_rad, tilt_rad);
  const float cx = pose.centre_m.x();
  const float cy = pose.centre_m.y();
  const float floor_z = -rig_.params().ptu_height_m;
  std::size_t added = 0;
  for (std::size_t i = 0; i < cue.column_count(); ++i) {
    const FloorColumn& col = cue.column(i);
    if (col.end != FloorColumn::End::kBoundary || col.base_rho_m < params_.min_base_m ||
        col.base_rho_m > params_.max_base_m) {
      continue;
    }
    // The walk's plane: through the optical centre, along the azimuth; the base's distance
    // along it from the centre, s with |c + s·a| = ρ.
    const float ax = std::cos(col.azimuth_rad);
    const float ay = std::sin(col.azimuth_rad);
    const float along_c = cx * ax + cy * ay;
    const float disc = along_c * along_c - (cx * cx + cy * cy) + col.base_rho_m * col.base_rho_m;
    if (!(disc > 0.0F)) continue;
    const float s_base = -along_c + std::sqrt(disc);
    if (!(s_base > 0.0F)) continue;
    for (std::size_t k = 0; k < point_count; ++k) {
      const Eigen::Vector3f& p = points[k].point_ptu_m;
      const float height = p.z() - floor_z;
      if (height < params_.min_height_m || height > params_.max_height_m) continue;
      const float dx = p.x() - cx;
      const float dy = p.y() - cy;
      const float s = dx * ax + dy * ay;
      if (!(s > 0.0F)) continue;
      if (std::fabs(dx * ay - dy * ax) > params_.lateral_m + params_.lateral_per_m * s) continue;
      const float ratio = s / s_base;
      if (ratio < params_.min_ratio || ratio > params_.max_ratio) continue;
      if (count_ < kCapacity) {
        ratios_[count_++] = ratio;
        ++added;
      }
    }
  }
  return added;
}

bool RangeCheck::median(float& ratio, std::size_t& count) {
  count = count_;
  if (count_ == 0) return false;
  const auto middle = ratios_.begin() + static_cast<std::ptrdiff_t>(count_ / 2);
  std::nth_element(ratios_.begin(), middle, ratios_.begin() + static_cast<std::ptrdiff_t>(count_));
  ratio = *middle;
  return true;
}

}  // namespace boticelli::stereo
