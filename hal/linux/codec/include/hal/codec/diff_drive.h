// Differential-drive kinematics and wheel odometry, pure (no I/O): (v, ω) <-> wheel turns.
#pragma once

#include <cstdint>

namespace boticelli::codec {

struct DiffDriveGeometry {
  float wheel_radius_m = 0.0F;  // both wheels, nominal
  float track_width_m = 0.0F;   // effective distance between the wheel contact points
  // +1 or −1: the sign of a motor's turns for the wheel rolling the robot forward (mirrored
  // motors usually make one side −1).
  float left_direction = 1.0F;
  float right_direction = -1.0F;
  // Each wheel's effective radius over the nominal one (the odometry's calibration: 1, 1 for
  // equal wheels).
  float left_scale = 1.0F;
  float right_scale = 1.0F;
};

struct WheelTurns {
  float left = 0.0F;  // [turns/s] (or [turns] for positions), motor frame
  float right = 0.0F;
};

// v_l = v − ω·b/2, v_r = v + ω·b/2; motor turns/s = direction · v_wheel / (2π r · scale).
WheelTurns body_to_wheels(float v_m_s, float omega_rad_s, const DiffDriveGeometry& g);
// Inverse: v = (v_r + v_l)/2, ω = (v_r − v_l)/b.
void wheels_to_body(const WheelTurns& motor_turns_s, const DiffDriveGeometry& g, float& v_m_s,
                    float& omega_rad_s);

// Integrates the pose from motor positions [turns] (midpoint rule on each step: the heading
// at the middle of the step is used, exact for constant-curvature steps up to O(Δθ³)).
class DiffDriveOdometry {
 public:
  explicit DiffDriveOdometry(const DiffDriveGeometry& g) : geometry_(g) {}
  // Forgets the last sample; the next update() only records its positions.
  void reset_reference() { have_reference_ = false; }
  void update(const WheelTurns& motor_pos_turns);
  double x_m() const { return x_m_; }
  double y_m() const { return y_m_; }
  double yaw_rad() const { return yaw_rad_; }

 private:
  DiffDriveGeometry geometry_;
  bool have_reference_ = false;
  WheelTurns last_{};
  double x_m_ = 0.0;
  double y_m_ = 0.0;
  double yaw_rad_ = 0.0;
};

}  // namespace boticelli::codec
