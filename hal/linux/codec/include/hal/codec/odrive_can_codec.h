// ODrive "CAN Simple" codec: frames to and from the messages the base uses, pure (no I/O, no OS
// headers).
#pragma once

#include <array>
#include <cstdint>

namespace boticelli::codec::odrive {

// Facts (docs/protocols.md): 11-bit ids, id = node_id << 5 | command_id, node ids 0..63;
// payloads little-endian, floats IEEE 754 binary32.
enum class Command : std::uint8_t {
  kHeartbeat = 0x01,            // ODrive -> host, 8 bytes: u32 axis_error, u8 axis_state,
                                // u8 procedure_result, u8 trajectory_done, u8 reserved
  kEstop = 0x02,                // host -> ODrive, no payload
  kSetAxisState = 0x07,         // host -> ODrive, 4 bytes: u32 requested state
  kGetEncoderEstimates = 0x09,  // ODrive -> host, 8 bytes: f32 pos [turns], f32 vel [turns/s];
                                // the host may request it with a remote (RTR) frame
  kSetControllerMode = 0x0B,    // host -> ODrive, 8 bytes: u32 control mode, u32 input mode
  kSetInputVel = 0x0D,          // host -> ODrive, 8 bytes: f32 vel [turns/s], f32 torque ff [Nm]
  kClearErrors = 0x18,          // host -> ODrive, 0 or 1 byte (identify flag)
};

enum class AxisState : std::uint8_t { kUndefined = 0, kIdle = 1, kClosedLoopControl = 8 };
enum class ControlMode : std::uint32_t { kVelocityControl = 2 };
enum class InputMode : std::uint32_t { kPassthrough = 1, kVelRamp = 2 };

inline constexpr std::uint8_t kMaxNodeId = 0x3F;
inline constexpr std::uint32_t kStandardIdMask = 0x7FF;

// A classic CAN frame, independent of the OS's struct can_frame.
struct CanFrame {
  std::uint32_t id = 0;  // 11-bit standard id (29-bit when extended)
  bool extended = false;
  bool remote = false;   // RTR
  std::uint8_t dlc = 0;  // 0..8
  std::array<std::uint8_t, 8> data{};
};

struct Heartbeat {
  std::uint32_t axis_error = 0;
  std::uint8_t axis_state = 0;
  std::uint8_t procedure_result = 0;
  bool trajectory_done = false;
};

struct EncoderEstimates {
  float pos_turns = 0.0F;
  float vel_turns_s = 0.0F;
};

enum class DecodeStatus : std::uint8_t {
  kOk,
  kExtendedId,      // CAN Simple uses standard ids only
  kBadDlc,          // dlc > 8
  kUnknownCommand,  // a command id this codec does not handle
  kWrongLength,     // the payload length does not match the command
  kNotFinite,       // a float that is NaN or infinite
  kRemoteRequest,   // an RTR frame (a request, no payload)
};

// A decoded frame. Only the field of `command` is meaningful.
struct Message {
  std::uint8_t node_id = 0;
  Command command = Command::kHeartbeat;
  Heartbeat heartbeat{};
  EncoderEstimates encoder{};
  std::uint32_t requested_state = 0;  // kSetAxisState
  std::uint32_t control_mode = 0;     // kSetControllerMode
  std::uint32_t input_mode = 0;
  float input_vel_turns_s = 0.0F;  // kSetInputVel
  float input_torque_ff_nm = 0.0F;
};

constexpr std::uint32_t make_id(std::uint8_t node_id, Command command) {
  return (static_cast<std::uint32_t>(node_id & kMaxNodeId) << 5U) |
         static_cast<std::uint32_t>(command);
}
constexpr std::uint8_t node_of(std::uint32_t id) {
  return static_cast<std::uint8_t>((id >> 5U) & kMaxNodeId);
}
constexpr std::uint8_t command_of(std::uint32_t id) {
  return static_cast<std::uint8_t>(id & 0x1FU);
}

// Host -> ODrive.
CanFrame encode_estop(std::uint8_t node_id);
CanFrame encode_set_axis_state(std::uint8_t node_id, AxisState state);
CanFrame encode_set_controller_mode(std::uint8_t node_id, ControlMode control, InputMode input);
CanFrame encode_set_input_vel(std::uint8_t node_id, float vel_turns_s, float torque_ff_nm = 0.0F);
CanFrame encode_clear_errors(std::uint8_t node_id);
CanFrame encode_encoder_request(std::uint8_t node_id);  // RTR for Get_Encoder_Estimates

// ODrive -> host (used by the emulator and the tests).
CanFrame encode_heartbeat(std::uint8_t node_id, const Heartbeat& heartbeat);
CanFrame encode_encoder_estimates(std::uint8_t node_id, const EncoderEstimates& estimates);

// Decodes any of the seven commands, validating length and values. On an error `out` keeps
// only node_id and command (when they could be read).
DecodeStatus decode(const CanFrame& frame, Message& out);
const char* to_string(DecodeStatus status);

// Little-endian field access (exposed for the tests).
void put_u32(std::uint8_t* p, std::uint32_t v);
std::uint32_t get_u32(const std::uint8_t* p);
void put_f32(std::uint8_t* p, float v);
float get_f32(const std::uint8_t* p);

}  // namespace boticelli::codec::odrive
