// ScanMatcher: correlative search and Gauss–Newton refinement of a look's pose (scan_matcher.h).
#include "algo/worldmap/scan_matcher.h"

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>

#include "algo/core/angles.h"

namespace boticelli::worldmap {

void ScanMatcher::start(const GridMap& map, const core::Pose2& initial,
                        const mapping::StarPolygon& free, const mapping::StarPolygon& evidence,
                        const ScanMatcherParams& params) {
  map_ = &map;
  params_ = params;
  result_ = Registration{};
  result_.initial = initial;
  result_.pose = initial;
  const float cell = map.cell_m();
  // The raster must hold every point at every shift: clamp the range to what it can.
  const float half_m = 0.5F * static_cast<float>(kMatchFieldCells - 4) * cell;
  params_.max_range_m = std::min(params_.max_range_m, half_m - params_.linear_window_m);
  // 1. The scan: evidence that backs the polygon's boundary, as the fusion marks it.
  count_ = 0;
  weight_sum_ = 0.0F;
  float farthest = cell;
  const std::size_t n = std::min(free.vertex_count(), evidence.vertex_count());
  for (std::size_t k = 0; k < n && count_ < kMaxScanPoints; ++k) {
    const float e = evidence.rho_m(k);
    if (!std::isfinite(e) || e > params_.max_range_m || e > free.rho_m(k) + params_.backing_m) {
      continue;
    }
    const float a = evidence.angle_rad(k);
    const float r = e / params_.range_scale_m;
    points_[count_] = {e * std::cos(a), e * std::sin(a)};
    weights_[count_] = 1.0F / (1.0F + r * r);
    rays_[count_] = static_cast<std::uint16_t>(k);
    weight_sum_ += weights_[count_];
    farthest = std::max(farthest, e);
    ++count_;
  }
  result_.points = count_;
  fit_normals();
  // 2. The field's raster, centred on the look.
  const float reach = params_.max_range_m + params_.linear_window_m + params_.truncate_m;
  side_ = std::min(kMatchFieldCells, 2 * static_cast<int>(std::ceil(reach / cell)) + 3);
  const Cell centre = map.cell_of({initial.x_m, initial.y_m});
  origin_ = {centre.ix - side_ / 2, centre.iy - side_ / 2};
  line_ = 0;
  // 3. The search's lattice.
  shifts_ = static_cast<int>(std::floor(params_.linear_window_m / cell + 1e-3F));
  angle_step_rad_ = std::min(std::acos(1.0F - 0.5F * (cell * cell) / (farthest * farthest)),
                             std::max(params_.angular_window_rad, 1e-4F));
  angles_ = 2 * static_cast<int>(std::ceil(params_.angular_window_rad / angle_step_rad_)) + 1;
  angle_step_rad_ =
      angles_ > 1 ? 2.0F * params_.angular_window_rad / static_cast<float>(angles_ - 1) : 0.0F;
  angle_ = 0;
  best_score_ = -1.0F;
  best_ = initial;
  phase_ = count_ < params_.min_points ? Phase::kDone : Phase::kRaster;
}

void ScanMatcher::fit_normals() {
  const auto reach = static_cast<std::size_t>(std::max(params_.normal_neighbours, 1));
  const float reach2 = params_.normal_reach_m * params_.normal_reach_m;
  for (std::size_t k = 0; k < count_; ++k) {
    normals_[k] = {0.0F, 0.0F};
    // The neighbours on the rays either side (points are in ray order; ray gaps end them).
    const std::size_t lo = k >= reach ? k - reach : 0;
    const std::size_t hi = std::min(count_ - 1, k + reach);
    float sx = 0.0F;
    float sy = 0.0F;
    int n = 0;
    for (std::size_t m = lo; m <= hi; ++m) {
      const int gap = std::abs(static_cast<int>(rays_[m]) - static_cast<int>(rays_[k]));
      const float dx = points_[m].x_m - points_[k].x_m;
      const float dy = points_[m].y_m - points_[k].y_m;
      if (gap > params_.normal_neighbours || dx * dx + dy * dy > reach2) continue;
      sx += points_[m].x_m;
      sy += points_[m].y_m;
      ++n;
    }
    if (n < 3) continue;
    const float mx = sx / static_cast<float>(n);
    const float my = sy / static_cast<float>(n);
    float cxx = 0.0F;
    float cxy = 0.0F;
    float cyy = 0.0F;
    for (std::size_t m = lo; m <= hi; ++m) {
      const int gap = std::abs(static_cast<int>(rays_[m]) - static_cast<int>(rays_[k]));
      const float dx = points_[m].x_m - points_[k].x_m;
      const float dy = points_[m].y_m - points_[k].y_m;
      if (gap > params_.normal_neighbours || dx * dx + dy * dy > reach2) continue;
      const float ux = points_[m].x_m - mx;
      const float uy = points_[m].y_m - my;
      cxx += ux * ux;
      cxy += ux * uy;
      cyy += uy * uy;
    }
    // The line's direction is the covariance's major axis; the normal is across it. A blob
    // (no clear line) gives no normal.
    const float tr = cxx + cyy;
    const float det = cxx * cyy - cxy * cxy;
    const float disc = std::sqrt(std::max(0.25F * tr * tr - det, 0.0F));
    const float major = 0.5F * tr + disc;
    const float minor = 0.5F * tr - disc;
    if (major <= 0.0F || minor > 0.25F * major) continue;
    const float angle = 0.5F * std::atan2(2.0F * cxy, cxx - cyy);  // of the major axis
    normals_[k] = {-std::sin(angle), std::cos(angle)};
  }
}

Eigen::Matrix3f ScanMatcher::surface_information(const core::Pose2& pose) const {
  Eigen::Matrix3f h = Eigen::Matrix3f::Zero();
  const float c = std::cos(pose.yaw_rad);
  const float s = std::sin(pose.yaw_rad);
  for (std::size_t k = 0; k < count_; ++k) {
    const core::Point2& n = normals_[k];
    if (n.x_m == 0.0F && n.y_m == 0.0F) continue;
    const core::Point2& p = points_[k];
    float d = 0.0F;
    float gx = 0.0F;
    float gy = 0.0F;
    const float qx = c * p.x_m - s * p.y_m;
    const float qy = s * p.x_m + c * p.y_m;
    if (!distance_at(pose.x_m + qx, pose.y_m + qy, d, gx, gy) || d >= params_.truncate_m) {
      continue;  // an outlier constrains nothing
    }
    const float nx = c * n.x_m - s * n.y_m;
    const float ny = s * n.x_m + c * n.y_m;
    const Eigen::Vector3f j(nx, ny, -nx * qy + ny * qx);
    h.noalias() += weights_[k] * j * j.transpose();
  }
  return h;
}

bool ScanMatcher::run_unit() {
  if (phase_ == Phase::kIdle || phase_ == Phase::kDone) return true;
  ++result_.units;
  switch (phase_) {
    case Phase::kRaster:
      raster_rows();
      break;
    case Phase::kColumns:
      distance_columns();
      break;
    case Phase::kRows:
      distance_rows();
      break;
    case Phase::kSearch:
      search_rotation();
      break;
    case Phase::kRefine:
      refine();
      break;
    default:
      break;
  }
  return phase_ == Phase::kDone;
}

void ScanMatcher::raster_rows() {
  const int end = std::min(side_, line_ + params_.rows_per_unit);
  const auto s = static_cast<std::size_t>(side_);
  for (; line_ < end; ++line_) {
    for (int i = 0; i < side_; ++i) {
      const Cell c{origin_.ix + i, origin_.iy + line_};
      const bool occupied = map_->state(c) == CellState::kOccupied;
      dist_[static_cast<std::size_t>(line_) * s + static_cast<std::size_t>(i)] =
          occupied ? 0.0F : kFar;
      if (occupied) ++result_.map_cells;
    }
  }
  if (line_ < side_) return;
  line_ = 0;
  phase_ = result_.map_cells < params_.min_points ? Phase::kDone : Phase::kColumns;
}

// Felzenszwalb & Huttenlocher's lower envelope of parabolas, over the finite sites only.
void ScanMatcher::transform_line(std::size_t first, std::size_t stride, int n) {
  for (int q = 0; q < n; ++q) {
    line_f_[static_cast<std::size_t>(q)] = dist_[first + static_cast<std::size_t>(q) * stride];
  }
  int k = -1;
  for (int q = 0; q < n; ++q) {
    const float fq = line_f_[static_cast<std::size_t>(q)];
    if (fq >= kFar) continue;
    const auto qf = static_cast<float>(q);
    if (k < 0) {
      k = 0;
      line_v_[0] = q;
      line_z_[0] = -kFar;
      line_z_[1] = kFar;
      continue;
    }
    float s = 0.0F;
    while (true) {
      const int v = line_v_[static_cast<std::size_t>(k)];
      const auto vf = static_cast<float>(v);
      s = ((fq + qf * qf) - (line_f_[static_cast<std::size_t>(v)] + vf * vf)) / (2.0F * (qf - vf));
      if (s > line_z_[static_cast<std::size_t>(k)] || k == 0) break;
      --k;
    }
    if (s <= line_z_[static_cast<std::size_t>(k)]) {
      // Only possible at k == 0: this parabola is lower everywhere.
      line_v_[0] = q;
      line_z_[0] = -kFar;
      line_z_[1] = kFar;
      continue;
    }
    ++k;
    line_v_[static_cast<std::size_t>(k)] = q;
    line_z_[static_cast<std::size_t>(k)] = s;
    line_z_[static_cast<std::size_t>(k) + 1] = kFar;
  }
  if (k < 0) return;  // no site: the line stays far
  int j = 0;
  for (int q = 0; q < n; ++q) {
    const auto qf = static_cast<float>(q);
    while (line_z_[static_cast<std::size_t>(j) + 1] < qf) ++j;
    const int v = line_v_[static_cast<std::size_t>(j)];
    const float d = qf - static_cast<float>(v);
    dist_[first + static_cast<std::size_t>(q) * stride] =
        d * d + line_f_[static_cast<std::size_t>(v)];
  }
}

void ScanMatcher::distance_columns() {
  const int end = std::min(side_, line_ + params_.rows_per_unit);
  for (; line_ < end; ++line_) {
    transform_line(static_cast<std::size_t>(line_), static_cast<std::size_t>(side_), side_);
  }
  if (line_ < side_) return;
  line_ = 0;
  phase_ = Phase::kRows;
}

void ScanMatcher::distance_rows() {
  const int end = std::min(side_, line_ + params_.rows_per_unit);
  const float cell = map_->cell_m();
  const float two_sigma2 = 2.0F * params_.field_sigma_m * params_.field_sigma_m;
  for (; line_ < end; ++line_) {
    const std::size_t first = static_cast<std::size_t>(line_) * static_cast<std::size_t>(side_);
    transform_line(first, 1, side_);
    for (std::size_t k = first; k < first + static_cast<std::size_t>(side_); ++k) {
      const float d = dist_[k] >= kFar ? params_.truncate_m
                                       : std::min(std::sqrt(dist_[k]) * cell, params_.truncate_m);
      dist_[k] = d;
      score_[k] = static_cast<std::uint8_t>(std::lround(255.0F * std::exp(-d * d / two_sigma2)));
    }
  }
  if (line_ < side_) return;
  phase_ = Phase::kSearch;
}

void ScanMatcher::search_rotation() {
  const core::Pose2& p0 = result_.initial;
  const float cell = map_->cell_m();
  const float dtheta = -params_.angular_window_rad + static_cast<float>(angle_) * angle_step_rad_;
  const float yaw = p0.yaw_rad + dtheta;
  const float c = std::cos(yaw);
  const float s = std::sin(yaw);
  for (std::size_t k = 0; k < count_; ++k) {
    const core::Point2& p = points_[k];
    const float x = p0.x_m + c * p.x_m - s * p.y_m;
    const float y = p0.y_m + s * p.x_m + c * p.y_m;
    cell_i_[k] = static_cast<int>(std::floor(x / cell)) - origin_.ix;
    cell_j_[k] = static_cast<int>(std::floor(y / cell)) - origin_.iy;
  }
  const float norm = 1.0F / (255.0F * weight_sum_);
  const auto s_side = static_cast<std::size_t>(side_);
  for (int ty = -shifts_; ty <= shifts_; ++ty) {
    for (int tx = -shifts_; tx <= shifts_; ++tx) {
      float sum = 0.0F;
      for (std::size_t k = 0; k < count_; ++k) {
        const int i = cell_i_[k] + tx;
        const int j = cell_j_[k] + ty;
        if (i < 0 || j < 0 || i >= side_ || j >= side_) continue;
        sum += weights_[k] *
               static_cast<float>(
                   score_[static_cast<std::size_t>(j) * s_side + static_cast<std::size_t>(i)]);
      }
      const float tx_m = static_cast<float>(tx) * cell;
      const float ty_m = static_cast<float>(ty) * cell;
      const float score =
          sum * norm *
          std::exp(-params_.prior_weight * (tx_m * tx_m + ty_m * ty_m + dtheta * dtheta));
      if (score > best_score_) {
        best_score_ = score;
        best_ = {p0.x_m + tx_m, p0.y_m + ty_m, core::wrap_pi(yaw)};
      }
    }
  }
  if (++angle_ < angles_) return;
  result_.searched = best_;
  result_.score = best_score_;
  phase_ = Phase::kRefine;
}

bool ScanMatcher::distance_at(float x_m, float y_m, float& d_m, float& gx, float& gy) const {
  const float cell = map_->cell_m();
  // Raster coordinates with cell centres on whole numbers.
  const float u = x_m / cell - static_cast<float>(origin_.ix) - 0.5F;
  const float v = y_m / cell - static_cast<float>(origin_.iy) - 0.5F;
  const float fi = std::floor(u);
  const float fj = std::floor(v);
  const int i = static_cast<int>(fi);
  const int j = static_cast<int>(fj);
  if (i < 0 || j < 0 || i + 1 >= side_ || j + 1 >= side_) return false;
  const float a = u - fi;
  const float b = v - fj;
  const auto s = static_cast<std::size_t>(side_);
  const std::size_t k = static_cast<std::size_t>(j) * s + static_cast<std::size_t>(i);
  const float d00 = dist_[k];
  const float d10 = dist_[k + 1];
  const float d01 = dist_[k + s];
  const float d11 = dist_[k + s + 1];
  d_m = (1.0F - b) * ((1.0F - a) * d00 + a * d10) + b * ((1.0F - a) * d01 + a * d11);
  gx = ((1.0F - b) * (d10 - d00) + b * (d11 - d01)) / cell;
  gy = ((1.0F - a) * (d01 - d00) + a * (d11 - d10)) / cell;
  return true;
}

void ScanMatcher::normal_equations(const core::Pose2& pose, Eigen::Matrix3f& h, Eigen::Vector3f& g,
                                   float& inlier_weight, float& squares) const {
  h.setZero();
  g.setZero();
  inlier_weight = 0.0F;
  squares = 0.0F;
  const float c = std::cos(pose.yaw_rad);
  const float s = std::sin(pose.yaw_rad);
  for (std::size_t k = 0; k < count_; ++k) {
    const core::Point2& p = points_[k];
    const float qx = c * p.x_m - s * p.y_m;  // the point rotated, from the robot [m]
    const float qy = s * p.x_m + c * p.y_m;
    float d = 0.0F;
    float gx = 0.0F;
    float gy = 0.0F;
    if (!distance_at(pose.x_m + qx, pose.y_m + qy, d, gx, gy)) continue;
    if (d >= params_.truncate_m) continue;  // an outlier: no pull
    const float w = weights_[k];
    inlier_weight += w;
    squares += w * d * d;
    const Eigen::Vector3f j(gx, gy, -gx * qy + gy * qx);
    h.noalias() += w * j * j.transpose();
    g.noalias() += w * d * j;
  }
}

void ScanMatcher::refine() {
  core::Pose2 pose = best_;
  const core::Pose2& p0 = result_.initial;
  Eigen::Matrix3f h;
  Eigen::Vector3f g;
  float inliers = 0.0F;
  float squares = 0.0F;
  for (int it = 0; it < params_.refine_iterations; ++it) {
    normal_equations(pose, h, g, inliers, squares);
    // Levenberg's damping keeps an unconstrained direction from running off.
    const float mu = 1e-3F * std::max(h.trace(), 1e-3F);
    const Eigen::Matrix3f a = h + mu * Eigen::Matrix3f::Identity();
    const Eigen::Vector3f step = -a.ldlt().solve(g);
    if (!step.allFinite()) break;
    pose.x_m = std::clamp(pose.x_m + step.x(), p0.x_m - params_.linear_window_m,
                          p0.x_m + params_.linear_window_m);
    pose.y_m = std::clamp(pose.y_m + step.y(), p0.y_m - params_.linear_window_m,
                          p0.y_m + params_.linear_window_m);
    const float dyaw = std::clamp(core::wrap_pi(pose.yaw_rad + step.z() - p0.yaw_rad),
                                  -params_.angular_window_rad, params_.angular_window_rad);
    pose.yaw_rad = core::wrap_pi(p0.yaw_rad + dyaw);
    if (step.head<2>().norm() < 1e-4F && std::fabs(step.z()) < 1e-5F) break;
  }
  // 5. What the scan constrains at the result, and the correction kept along that only.
  normal_equations(pose, h, g, inliers, squares);
  result_.refined = pose;
  result_.residual_m = inliers > 0.0F ? std::sqrt(squares / inliers) : params_.truncate_m;
  h = surface_information(pose);
  result_.information = h;
  result_.inlier_share = weight_sum_ > 0.0F ? inliers / weight_sum_ : 0.0F;
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix3f> eigen;
  eigen.computeDirect(h);
  result_.eigenvalues = eigen.eigenvalues();
  result_.eigenvectors = eigen.eigenvectors();
  const Eigen::Vector3f delta(pose.x_m - p0.x_m, pose.y_m - p0.y_m,
                              core::wrap_pi(pose.yaw_rad - p0.yaw_rad));
  Eigen::Vector3f kept = Eigen::Vector3f::Zero();
  result_.constrained = 0;
  for (int k = 0; k < 3; ++k) {
    if (result_.eigenvalues(k) < params_.min_information) continue;
    const Eigen::Vector3f e = result_.eigenvectors.col(k);
    kept += e * e.dot(delta);
    ++result_.constrained;
  }
  result_.matched = result_.inlier_share >= params_.min_inlier_share && result_.constrained > 0;
  if (result_.matched) {
    result_.pose = {p0.x_m + kept.x(), p0.y_m + kept.y(), core::wrap_pi(p0.yaw_rad + kept.z())};
  }
  phase_ = Phase::kDone;
}

}  // namespace boticelli::worldmap
