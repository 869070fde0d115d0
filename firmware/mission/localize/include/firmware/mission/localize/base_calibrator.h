// BaseCalibrator: UMBmark's two systematic odometry errors (Borenstein & Feng 1996), the
// effective track width and the wheels' diameter ratio, estimated from the looks' registrations.
#pragma once

#include <cstdint>

namespace boticelli::firmware::mission {

// The estimate, in the wheel counters' units (the encoders' turns at the nominal diameter).
struct BaseCalibration {
  bool valid = false;           // enough intervals, turning and driving to say anything
  std::uint32_t intervals = 0;  // registration-to-registration intervals used
  float turned_rad = 0.0F;      // |heading change| summed over them, by the odometry
  float driven_m = 0.0F;        // |distance| summed over them
  float track_m = 0.0F;         // effective track width [m] (valid only)
  float track_sd_m = 0.0F;      // its standard error [m]
  float diameter_ratio = 1.0F;  // right wheel's effective diameter / the left's (UMBmark E_d)
  float diameter_ratio_sd = 0.0F;
};

// Between two registered looks the robot's true heading changed by what the registrations
// say: y = Θ + c₀ + δ₁ − δ₀ (Θ the odometry's heading change, δ each registration's heading
// residual, c₀ the correction the first one applied). A differential drive with an effective
// track b and wheels whose effective diameters differ by the ratio E_d turns by
//   y = (u + g·s) / b,  u = Δr − Δl,  s = (Δr + Δl)/2,  g = 2(E_d − 1)/(E_d + 1)
// in the counters' wheel travels Δl, Δr (exact for any path). Least squares over the
// intervals gives 1/b and g/b. Fixed size, no allocation.
class BaseCalibrator {
 public:
  // Valid only with at least this much evidence.
  static constexpr std::uint32_t kMinIntervals = 4;
  static constexpr float kMinTurnedRad = 6.2831853F;  // a whole turn
  static constexpr float kMinDrivenM = 2.0F;

  // Forgets everything.
  void clear();
  // The odometry starts again where its counters are unknown (a new or resumed mission): the
  // interval under way is dropped; the sums stay.
  void restart();
  // A move (a turn, then straight) ended: the odometry's heading change over it, wrapped to
  // (−π, π] [rad], and the wheel counters now [m].
  void moved(float turned_rad, bool wheels_known, double left_m, double right_m);
  // A look was registered with the counters at these values: δ = registered − odometry
  // heading [rad], c = the correction applied to the pose [rad].
  void registered(bool wheels_known, double left_m, double right_m, float residual_rad,
                  float correction_rad);
  [[nodiscard]] BaseCalibration estimate() const;

 private:
  // The counters moved since the last event without a move being reported (a step cut short
  // by a hold): the interval cannot be used.
  bool counters_moved(double left_m, double right_m) const;

  // The interval under way: it began at a registration (counters known since), and every
  // move in it was reported.
  bool have_reference_ = false;  // counters at the last event
  double left_ref_m_ = 0.0;
  double right_ref_m_ = 0.0;
  double u_m_ = 0.0;        // Δr − Δl
  double s_m_ = 0.0;        // (Δr + Δl)/2
  double theta_rad_ = 0.0;  // the odometry's heading change, unwrapped
  double driven_m_ = 0.0;
  // The registration that began it.
  float last_residual_rad_ = 0.0F;
  float last_correction_rad_ = 0.0F;
  // Normal equations of y = p·u + q·s.
  double suu_ = 0.0, sus_ = 0.0, sss_ = 0.0, suy_ = 0.0, ssy_ = 0.0, syy_ = 0.0;
  std::uint32_t n_ = 0;
  double turned_sum_rad_ = 0.0;
  double driven_sum_m_ = 0.0;
};

}  // namespace boticelli::firmware::mission
