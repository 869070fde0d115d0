// The ALN trainer's robust M-estimators (Huber, Tukey): each sample's refit weight and loss.
#pragma once

#include <cmath>

#include "algo/aln/trainer_config.h"

namespace boticelli::aln {
namespace train_detail {

inline constexpr double kHuber = 1.345;
inline constexpr double kTukey = 4.685;

// The IRLS weight of residual r at the piece's residual scale s (1 without robust weights).
inline double robust_weight(RobustWeighting robust, double r, double s) {
  if (robust == RobustWeighting::kNone || !std::isfinite(s)) return 1.0;
  const double u = std::fabs(r) / s;
  if (robust == RobustWeighting::kHuber) return u <= kHuber ? 1.0 : kHuber / u;
  if (u >= kTukey) return 0.0;
  const double t = 1.0 - (u / kTukey) * (u / kTukey);
  return t * t;
}

// rho(r / s) s^2 of the M-estimator whose weights robust_weight() gives, at the fixed scale
// s the trainer compares models at (Trainer::base_scale()): Huber r^2 / 2 inside k s, then
// linear; Tukey rising to c^2 s^2 / 6 at c s, then constant, so a residual pushed out of the
// window costs the most, not nothing. Only for robust weights (Huber, else Tukey).
inline double robust_loss(RobustWeighting robust, double r, double s) {
  if (!(s > 0.0)) return r * r;
  const double u = std::fabs(r) / s;
  if (robust == RobustWeighting::kHuber) {
    return u <= kHuber ? 0.5 * r * r : s * s * kHuber * (u - 0.5 * kHuber);
  }
  constexpr double kTukeyMax = kTukey * kTukey / 6.0;
  if (u >= kTukey) return kTukeyMax * s * s;
  const double t = 1.0 - (u / kTukey) * (u / kTukey);
  return kTukeyMax * (1.0 - t * t * t) * s * s;
}

}  // namespace train_detail
}  // namespace boticelli::aln
