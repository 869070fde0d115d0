// BaseCalibrator: the base's effective track and wheel diameter ratio from registrations.
#include "firmware/mission/localize/base_calibrator.h"

#include <cmath>
#include <numbers>

namespace boticelli::firmware::mission {

namespace {
constexpr double kCountersStillM = 1e-3;  // counters this close count as not moved [m]
}

void BaseCalibrator::clear() {
  *this = BaseCalibrator{};
}

void BaseCalibrator::restart() {
  have_reference_ = false;
}

bool BaseCalibrator::counters_moved(double left_m, double right_m) const {
  return std::fabs(left_m - left_ref_m_) + std::fabs(right_m - right_ref_m_) > kCountersStillM;
}

void BaseCalibrator::moved(float turned_rad, bool wheels_known, double left_m, double right_m) {
  if (!wheels_known || !have_reference_) {
    restart();
    return;
  }
  const double dl = left_m - left_ref_m_;
  const double dr = right_m - right_ref_m_;
  left_ref_m_ = left_m;
  right_ref_m_ = right_m;
  const double u = dr - dl;
  // A half turn's wrapped change may come out on the wrong side of ±π: the wheels say which
  // way the robot turned.
  double theta = static_cast<double>(turned_rad);
  if (std::fabs(theta) > 0.5 * std::numbers::pi && std::fabs(u) > kCountersStillM &&
      (theta > 0.0) != (u > 0.0)) {
    theta += u > 0.0 ? 2.0 * std::numbers::pi : -2.0 * std::numbers::pi;
  }
  u_m_ += u;
  s_m_ += 0.5 * (dl + dr);
  theta_rad_ += theta;
  driven_m_ += std::fabs(0.5 * (dl + dr));
}

void BaseCalibrator::registered(bool wheels_known, double left_m, double right_m,
                                float residual_rad, float correction_rad) {
  if (!wheels_known) {
    restart();
    return;
  }
  if (have_reference_ && !counters_moved(left_m, right_m)) {
    const double y = theta_rad_ + static_cast<double>(last_correction_rad_) +
                     static_cast<double>(residual_rad) - static_cast<double>(last_residual_rad_);
    suu_ += u_m_ * u_m_;
    sus_ += u_m_ * s_m_;
    sss_ += s_m_ * s_m_;
    suy_ += u_m_ * y;
    ssy_ += s_m_ * y;
    syy_ += y * y;
    ++n_;
    turned_sum_rad_ += std::fabs(theta_rad_);
    driven_sum_m_ += driven_m_;
  }
  // The next interval begins here.
  have_reference_ = true;
  left_ref_m_ = left_m;
  right_ref_m_ = right_m;
  u_m_ = s_m_ = theta_rad_ = driven_m_ = 0.0;
  last_residual_rad_ = residual_rad;
  last_correction_rad_ = correction_rad;
}

BaseCalibration BaseCalibrator::estimate() const {
  BaseCalibration e;
  e.intervals = n_;
  e.turned_rad = static_cast<float>(turned_sum_rad_);
  e.driven_m = static_cast<float>(driven_sum_m_);
  if (n_ < kMinIntervals || turned_sum_rad_ < static_cast<double>(kMinTurnedRad) ||
      driven_sum_m_ < static_cast<double>(kMinDrivenM)) {
    return e;
  }
  const double det = suu_ * sss_ - sus_ * sus_;
  if (!(det > 1e-12 * suu_ * sss_)) return e;
  // [p q] = N⁻¹ [Σuy Σsy]; p = 1/b, q = g/b.
  const double p = (sss_ * suy_ - sus_ * ssy_) / det;
  const double q = (suu_ * ssy_ - sus_ * suy_) / det;
  if (!(p > 0.0)) return e;
  const double g = q / p;
  if (!(std::fabs(g) < 1.0)) return e;
  // The residuals' variance, and the parameters' covariance σ²N⁻¹.
  const double sse = std::fmax(syy_ - p * suy_ - q * ssy_, 0.0);
  const double var = n_ > 2 ? sse / static_cast<double>(n_ - 2) : 0.0;
  const double var_p = var * sss_ / det;
  const double var_q = var * suu_ / det;
  const double cov_pq = -var * sus_ / det;
  e.valid = true;
  e.track_m = static_cast<float>(1.0 / p);
  e.track_sd_m = static_cast<float>(std::sqrt(var_p) / (p * p));
  e.diameter_ratio = static_cast<float>((2.0 + g) / (2.0 - g));
  // g = q/p to first order; E_d = (2 + g)/(2 − g) has dE_d/dg = 4/(2 − g)².
  const double var_g = std::fmax(
      var_q / (p * p) + q * q * var_p / (p * p * p * p) - 2.0 * q * cov_pq / (p * p * p), 0.0);
  e.diameter_ratio_sd = static_cast<float>(std::sqrt(var_g) * 4.0 / ((2.0 - g) * (2.0 - g)));
  return e;
}

}  // namespace boticelli::firmware::mission
