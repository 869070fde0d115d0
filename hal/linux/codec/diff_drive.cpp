// Differential-drive kinematics and odometry (pure).
#include "hal/codec/diff_drive.h"

#include <cmath>
#include <numbers>

namespace boticelli::codec {

namespace {
constexpr double kTwoPi = 2.0 * std::numbers::pi;
}

WheelTurns body_to_wheels(float v_m_s, float omega_rad_s, const DiffDriveGeometry& g) {
  const double half = 0.5 * static_cast<double>(g.track_width_m);
  const double v_left = static_cast<double>(v_m_s) - static_cast<double>(omega_rad_s) * half;
  const double v_right = static_cast<double>(v_m_s) + static_cast<double>(omega_rad_s) * half;
  const double per_turn = kTwoPi * static_cast<double>(g.wheel_radius_m);  // [m/turn]
  const double per_turn_left = per_turn * static_cast<double>(g.left_scale);
  const double per_turn_right = per_turn * static_cast<double>(g.right_scale);
  WheelTurns w;
  w.left = static_cast<float>(static_cast<double>(g.left_direction) * v_left / per_turn_left);
  w.right = static_cast<float>(static_cast<double>(g.right_direction) * v_right / per_turn_right);
  return w;
}

void wheels_to_body(const WheelTurns& m, const DiffDriveGeometry& g, float& v_m_s,
                    float& omega_rad_s) {
  const double per_turn = kTwoPi * static_cast<double>(g.wheel_radius_m);
  const double v_left = static_cast<double>(m.left) * static_cast<double>(g.left_direction) *
                        per_turn * static_cast<double>(g.left_scale);
  const double v_right = static_cast<double>(m.right) * static_cast<double>(g.right_direction) *
                         per_turn * static_cast<double>(g.right_scale);
  v_m_s = static_cast<float>(0.5 * (v_left + v_right));
  omega_rad_s = static_cast<float>((v_right - v_left) / static_cast<double>(g.track_width_m));
}

void DiffDriveOdometry::update(const WheelTurns& pos) {
  if (!have_reference_) {
    last_ = pos;
    have_reference_ = true;
    return;
  }
  const double per_turn = kTwoPi * static_cast<double>(geometry_.wheel_radius_m);
  const double d_left = static_cast<double>(pos.left - last_.left) *
                        static_cast<double>(geometry_.left_direction) * per_turn *
                        static_cast<double>(geometry_.left_scale);
  const double d_right = static_cast<double>(pos.right - last_.right) *
                         static_cast<double>(geometry_.right_direction) * per_turn *
                         static_cast<double>(geometry_.right_scale);
  last_ = pos;
  const double ds = 0.5 * (d_left + d_right);
  const double dyaw = (d_right - d_left) / static_cast<double>(geometry_.track_width_m);
  const double mid = yaw_rad_ + 0.5 * dyaw;
  x_m_ += ds * std::cos(mid);
  y_m_ += ds * std::sin(mid);
  yaw_rad_ = std::remainder(yaw_rad_ + dyaw, kTwoPi);
}

}  // namespace boticelli::codec
