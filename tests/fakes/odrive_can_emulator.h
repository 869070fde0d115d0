// OdriveCanEmulator: two ODrive axes on the far end of a fake CAN bus (a SOCK_SEQPACKET
// socketpair) or of a real SocketCAN interface (vcan0 in the kernel-in-the-loop test).
#pragma once

#include <cstdint>
#include <vector>

#include "hal/codec/odrive_can_codec.h"

namespace boticelli::fakes {

struct OdriveCanEmulatorConfig {
  std::uint8_t node_ids[2] = {0, 1};
  std::uint64_t heartbeat_period_us = 100000;  // the ODrive default is 100 ms
  std::uint64_t encoder_period_us = 10000;     // cyclic Get_Encoder_Estimates (0 = only on RTR)
  std::uint64_t closed_loop_delay_us = 50000;  // time from Set_Axis_State to closed loop
  std::uint64_t watchdog_timeout_us = 0;       // ODrive axis watchdog (0 = disabled)
  // The wheel's speed follows the setpoint at this rate in closed loop, and slows at
  // coast_turns_s2 when idle (0: at once, a perfect velocity controller) [turns/s²].
  float accel_turns_s2 = 0.0F;
  float coast_turns_s2 = 0.0F;
};

// service(now) reads what the driver sent, integrates each axis's position from its velocity
// setpoint (exactly, as a perfect velocity controller) and sends heartbeats and encoder
// estimates on time. The test can silence heartbeats, inject axis errors, bus-off error
// frames and malformed frames.
class OdriveCanEmulator {
 public:
  static constexpr std::uint32_t kErrorWatchdogExpired =
      0x00000800;                                                    // 0.5.x WATCHDOG_TIMER_EXPIRED
  static constexpr std::uint32_t kErrorEstopRequested = 0x00004000;  // 0.5.x ESTOP_REQUESTED

  explicit OdriveCanEmulator(const OdriveCanEmulatorConfig& config = {});
  ~OdriveCanEmulator();
  OdriveCanEmulator(const OdriveCanEmulator&) = delete;
  OdriveCanEmulator& operator=(const OdriveCanEmulator&) = delete;

  // Creates the bus; driver_fd() is handed to the driver (which then owns it).
  bool open();
  // Speaks through its own raw CAN socket on `interface` instead (the driver opens its own;
  // driver_fd() stays −1). Called again, it closes the old socket first (an interface that
  // was deleted and re-added needs a new one).
  bool open_can(const char* interface);
  int driver_fd() const { return driver_fd_; }
  void service(std::uint64_t now_us);

  // Fault injection.
  void silence_heartbeats(int axis, bool silent) { axes_[axis].silent = silent; }
  // The axis goes on with its heartbeats but stops sending encoder estimates.
  void silence_encoder(int axis, bool silent) { axes_[axis].encoder_silent = silent; }
  // The wheel cannot turn (jammed): its speed stays 0 whatever the setpoint.
  void jam(int axis, bool jammed) { axes_[axis].jammed = jammed; }
  // The estimates keep coming but stop changing (a frozen encoder): the last ones again.
  void freeze_encoder(int axis, bool frozen);
  void set_axis_error(int axis, std::uint32_t error);
  void send_bus_off();
  // Any error frame (CAN_ERR_FLAG is added), e.g. CAN_ERR_PROT | CAN_ERR_BUSERROR.
  void send_error_frame(std::uint32_t error_class);
  void send_frame(const codec::odrive::CanFrame& frame);
  void send_bytes(const void* data, std::size_t size);  // arbitrary (malformed) datagram

  // Inspection.
  std::uint8_t axis_state(int axis) const { return axes_[axis].state; }
  std::uint32_t axis_error(int axis) const { return axes_[axis].error; }
  float vel_setpoint(int axis) const { return axes_[axis].vel_setpoint; }
  float velocity(int axis) const { return axes_[axis].vel; }  // the wheel's measured speed
  // Every frame the driver sent, in order (node, command), since the last clear_log().
  struct Sent {
    std::uint8_t node;
    codec::odrive::Command command;
    float input_vel;      // Set_Input_Vel's setpoint
    std::uint32_t state;  // Set_Axis_State's requested state
    float wheel_vel[2];   // both wheels' speed when it came
  };
  const std::vector<Sent>& log() const { return log_; }
  void clear_log() { log_.clear(); }
  double pos_turns(int axis) const { return axes_[axis].pos; }
  std::uint32_t control_mode(int axis) const { return axes_[axis].control_mode; }
  std::uint32_t input_mode(int axis) const { return axes_[axis].input_mode; }
  std::uint32_t count(int axis, codec::odrive::Command c) const;
  std::uint32_t estops(int axis) const { return count(axis, codec::odrive::Command::kEstop); }
  std::uint32_t undecodable_frames() const { return undecodable_; }

 private:
  struct AxisSim {
    std::uint8_t node = 0;
    std::uint8_t state = 1;  // idle
    std::uint32_t error = 0;
    std::uint32_t control_mode = 0;
    std::uint32_t input_mode = 0;
    float vel_setpoint = 0.0F;
    float vel = 0.0F;
    double pos = 0.0;
    bool silent = false;
    bool encoder_silent = false;
    bool jammed = false;
    bool frozen = false;
    codec::odrive::EncoderEstimates frozen_at{};
    bool closed_loop_pending = false;
    std::uint64_t closed_loop_at_us = 0;
    std::uint64_t last_input_us = 0;
    std::uint64_t next_heartbeat_us = 0;
    std::uint64_t next_encoder_us = 0;
    std::vector<std::uint32_t> counts = std::vector<std::uint32_t>(32, 0);
  };
  void handle(const codec::odrive::CanFrame& f, std::uint64_t now_us);
  void send_heartbeat(AxisSim& a);
  void send_encoder(AxisSim& a);

  OdriveCanEmulatorConfig config_;
  int fd_ = -1;
  int driver_fd_ = -1;
  AxisSim axes_[2];
  std::uint64_t last_us_ = 0;
  bool have_time_ = false;
  std::uint32_t undecodable_ = 0;
  std::vector<Sent> log_;
};

}  // namespace boticelli::fakes
