// BaseOdriveCan: hal::Base for two ODrive axes (left and right wheel) on SocketCAN, "CAN Simple".
#pragma once

#include <cstdint>

#include "hal/base.h"
#include "hal/clock.h"
#include "hal/codec/diff_drive.h"
#include "hal/codec/odrive_can_codec.h"

namespace boticelli::hal_linux {

struct BaseOdriveCanConfig {
  const char* interface = "can0";  // SocketCAN interface (can0, vcan0)
  // An already-open socket carrying struct can_frame (a test's socketpair); −1 = open a raw
  // CAN socket on `interface`. The driver owns and closes it.
  int socket_fd = -1;
  std::uint8_t left_node_id = 0;  // ODrive axis node ids (0..63)
  std::uint8_t right_node_id = 1;
  codec::DiffDriveGeometry geometry{0.08F, 0.40F, 1.0F, -1.0F};  // wheel radius, track [m]
  float max_wheel_turns_s = 8.0F;            // motor setpoints are clamped to ± this [turns/s]
  std::uint32_t heartbeat_timeout_ms = 300;  // no heartbeat from an axis that long: stop
  std::uint32_t startup_timeout_ms = 3000;   // both axes in closed loop by then, or stop
  std::uint32_t state_resend_ms = 250;       // Set_Axis_State repeated while starting
  std::uint32_t stop_resend_ms = 100;        // the stop's frames repeated while stopped
  // A controlled stop (stop(), a lost encoder stream) brakes in closed loop with setpoint 0
  // and idles the axes once both measured wheel speeds are below standstill_turns_s, or after
  // brake_timeout_ms at the latest (stop category 1).
  std::uint32_t brake_timeout_ms = 500;
  float standstill_turns_s = 0.05F;  // [turns/s]
  // A wheel that does not follow its setpoint (a jammed wheel, or estimates that stopped
  // changing: a frozen encoder): measured speed in the setpoint's direction below
  // follow_ratio of a setpoint of at least follow_min_turns_s, for follow_timeout_ms.
  std::uint32_t follow_timeout_ms = 1000;
  float follow_min_turns_s = 0.1F;  // [turns/s]
  float follow_ratio = 0.25F;
  std::uint32_t encoder_timeout_ms = 100;  // no encoder estimate from an axis that long: stop
  bool request_encoder = false;            // send an RTR for Get_Encoder_Estimates every update()
                                           // (when the ODrives do not send it cyclically)
};

// Non-blocking: update() drains the socket (bounded), runs the start-up sequence
// (Clear_Errors, Set_Controller_Mode velocity/passthrough, Set_Input_Vel 0, Set_Axis_State
// closed loop, then both heartbeats must report closed loop without error), re-sends the
// velocity setpoint every call (so the ODrive's own watchdog stays fed) and integrates the
// odometry from Get_Encoder_Estimates. A missing heartbeat or encoder stream, an axis leaving
// closed loop, an axis error, a bus-off error frame or a socket error stop the base and set
// error(). How it stops depends on the cause (docs/protocols.md, "Stopping"):
// - braked (stop(), encoder estimates stopped): Set_Input_Vel(0) at once and on every
//   update(), the ODrives' velocity controllers brake; once both wheels are at rest (measured)
//   or after brake_timeout_ms, Set_Axis_State(IDLE); a heartbeat lost or an axis error while
//   braking turns it into the next kind;
// - idled at once (heartbeat lost, axis error, an axis out of closed loop, bus-off, a socket
//   error, a failed start-up, a wheel not following its setpoint): Set_Input_Vel(0) and
//   Estop; the axes are out of closed loop or out of reach, or their loop cannot be trusted,
//   so braking cannot work or help, and both wheels coast.
// While stopped the final frames (Set_Input_Vel(0) and IDLE or Estop) go to both axes every
// stop_resend_ms (a stop that could not be sent, e.g. with the link down, is sent once the
// link is back).
// resume() refuses while the controller is bus-off or the interface is down or gone, and
// opens a new socket when the interface was deleted and added again.
class BaseOdriveCan final : public hal::Base {
 public:
  BaseOdriveCan(const BaseOdriveCanConfig& config, hal::Clock& clock);
  ~BaseOdriveCan() override;

  bool init() override;
  void update() override;
  void set_velocity(float v_m_s, float omega_rad_s) override;
  void stop() override;
  bool resume() override;
  hal::BaseHealth health() const override { return health_; }
  hal::Odometry odometry() const override { return odometry_; }
  const char* error() const override { return error_; }
  // Set_Input_Vel(0) to both axes, written as prepared at construction: in closed loop the
  // ODrives' velocity controllers brake the wheels to a stop, and once the setpoints stop
  // coming their watchdog (if enabled) idles the axes. Not Estop: that idles at once and
  // the robot coasts.
  void last_gasp_stop() noexcept override;

  // Diagnostics.
  std::uint32_t rejected_frames() const { return rejected_frames_; }
  std::uint32_t error_frames() const { return error_frames_; }
  std::uint32_t sent_frames() const { return sent_frames_; }
  std::uint32_t send_failures() const { return send_failures_; }  // frames the socket refused
  bool bus_off() const { return bus_off_; }  // bus-off seen and no restart since
  bool braking() const { return braking_; }  // a controlled stop is braking the wheels

 private:
  struct Axis {
    std::uint8_t node_id = 0;
    std::uint64_t last_heartbeat_us = 0;
    bool heartbeat_seen = false;
    codec::odrive::Heartbeat heartbeat{};
    codec::odrive::EncoderEstimates encoder{};
    bool encoder_seen = false;
    bool encoder_fresh = false;
    std::uint64_t last_encoder_us = 0;
    std::uint64_t behind_since_us = 0;  // not following its setpoint since (0: following)
  };
  void send(const codec::odrive::CanFrame& frame);
  void receive(std::uint64_t now_us);
  void handle_error_frame(std::uint32_t can_id, const std::uint8_t* data);
  void begin_startup(std::uint64_t now_us);
  void send_startup_commands();
  enum class StopKind : std::uint8_t { kIdle, kBrake };
  void fault(const char* what, const char* side = nullptr, std::uint32_t value = 0,
             StopKind kind = StopKind::kIdle);
  void send_stop_frames();
  void update_braking(std::uint64_t now_us);
  void update_odometry(std::uint64_t now_us);
  void close_socket();
  bool open_socket();
  bool interface_usable();
  bool encoders_current(std::uint64_t now_us) const;
  bool wheel_behind(Axis& a, float setpoint_turns_s, std::uint64_t now_us);

  BaseOdriveCanConfig config_;
  hal::Clock& clock_;
  int fd_ = -1;
  Axis axes_[2];  // left, right
  hal::BaseHealth health_ = hal::BaseHealth::kStopped;
  std::uint64_t startup_deadline_us_ = 0;
  std::uint64_t next_state_send_us_ = 0;
  std::uint64_t next_stop_send_us_ = 0;
  std::uint64_t ready_since_us_ = 0;
  bool braking_ = false;           // a controlled stop under way (closed loop, setpoint 0)
  bool idled_by_request_ = false;  // the stop ended braked: IDLE, not Estop, is re-sent
  std::uint64_t brake_deadline_us_ = 0;
  bool owns_interface_ = false;  // opened `interface` itself (not a socket handed in)
  int ifindex_ = 0;              // the interface the socket is bound to
  codec::WheelTurns setpoint_turns_s_{};
  codec::DiffDriveOdometry integrator_;
  hal::Odometry odometry_{};
  bool bus_off_ = false;
  std::uint32_t rejected_frames_ = 0;
  std::uint32_t error_frames_ = 0;
  std::uint32_t sent_frames_ = 0;
  std::uint32_t send_failures_ = 0;
  char error_[160] = "not initialised";
  codec::odrive::CanFrame last_gasp_frames_[2]{};
};

}  // namespace boticelli::hal_linux
