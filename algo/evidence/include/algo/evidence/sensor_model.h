// Sensor model of single-camera stereo: evidence from match error (Eq 3.8), range error (Eq 3.7).
#pragma once

namespace boticelli::evidence {

// Eq 3.8: m = 1 − (E/E_max)² for E < E_max, else 0. E is the match error of Eq 3.1
// (sum of squared differences of centre-removed 5x5 windows, in squared grey levels).
inline float evidence_from_match_error(float match_error, float match_error_max) {
  if (!(match_error_max > 0.0F) || !(match_error < match_error_max)) {
    return 0.0F;
  }
  const float q = match_error < 0.0F ? 0.0F : match_error / match_error_max;
  return 1.0F - q * q;
}

// Eq 3.8 with the match's normalised error n (epipolar tracker: the refined residual over the
// feature window's own contrast) in place of E: m = 1 − (n/n_max)² for 0 ≤ n < n_max, else 0.
// For strong texture, whose E exceeds E_max even when the match is right.
inline float evidence_from_normalized_error(float normalized_error, float normalized_error_max) {
  if (!(normalized_error >= 0.0F)) {
    return 0.0F;
  }
  return evidence_from_match_error(normalized_error, normalized_error_max);
}

// Eq 3.7: range error of a one-pixel disparity error, δr = 2r² / (b·F + r), with the
// range r and the stereo baseline b in metres and the focal length F in pixels (≈ 0.38 m
// at r = 1 m for b = 2.8 cm, F = 150 px).
inline float range_error_m(float r_m, float baseline_m, float focal_px) {
  return 2.0F * r_m * r_m / (baseline_m * focal_px + r_m);
}

// The thesis's sensor model (§3.7.3) uses the simpler δr = 0.1 r.
inline float model_range_error_m(float r_m) {
  return 0.1F * r_m;
}

}  // namespace boticelli::evidence
