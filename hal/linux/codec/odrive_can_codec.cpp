// ODrive "CAN Simple" codec (pure).
#include "hal/codec/odrive_can_codec.h"

#include <bit>
#include <cmath>

namespace boticelli::codec::odrive {

void put_u32(std::uint8_t* p, std::uint32_t v) {
  for (unsigned i = 0; i < 4; ++i) p[i] = static_cast<std::uint8_t>(v >> (8U * i));
}

std::uint32_t get_u32(const std::uint8_t* p) {
  std::uint32_t v = 0;
  for (unsigned i = 0; i < 4; ++i) v |= static_cast<std::uint32_t>(p[i]) << (8U * i);
  return v;
}

void put_f32(std::uint8_t* p, float v) {
  put_u32(p, std::bit_cast<std::uint32_t>(v));
}
float get_f32(const std::uint8_t* p) {
  return std::bit_cast<float>(get_u32(p));
}

namespace {

CanFrame frame(std::uint8_t node_id, Command c, std::uint8_t dlc) {
  CanFrame f;
  f.id = make_id(node_id, c);
  f.dlc = dlc;
  return f;
}

}  // namespace

CanFrame encode_estop(std::uint8_t node_id) {
  return frame(node_id, Command::kEstop, 0);
}

CanFrame encode_set_axis_state(std::uint8_t node_id, AxisState state) {
  CanFrame f = frame(node_id, Command::kSetAxisState, 4);
  put_u32(f.data.data(), static_cast<std::uint32_t>(state));
  return f;
}

CanFrame encode_set_controller_mode(std::uint8_t node_id, ControlMode control, InputMode input) {
  CanFrame f = frame(node_id, Command::kSetControllerMode, 8);
  put_u32(f.data.data(), static_cast<std::uint32_t>(control));
  put_u32(f.data.data() + 4, static_cast<std::uint32_t>(input));
  return f;
}

CanFrame encode_set_input_vel(std::uint8_t node_id, float vel_turns_s, float torque_ff_nm) {
  CanFrame f = frame(node_id, Command::kSetInputVel, 8);
  put_f32(f.data.data(), vel_turns_s);
  put_f32(f.data.data() + 4, torque_ff_nm);
  return f;
}

CanFrame encode_clear_errors(std::uint8_t node_id) {
  CanFrame f = frame(node_id, Command::kClearErrors, 1);
  f.data[0] = 0;  // identify = false
  return f;
}

CanFrame encode_encoder_request(std::uint8_t node_id) {
  CanFrame f = frame(node_id, Command::kGetEncoderEstimates, 8);
  f.remote = true;
  return f;
}

CanFrame encode_heartbeat(std::uint8_t node_id, const Heartbeat& hb) {
  CanFrame f = frame(node_id, Command::kHeartbeat, 8);
  put_u32(f.data.data(), hb.axis_error);
  f.data[4] = hb.axis_state;
  f.data[5] = hb.procedure_result;
  f.data[6] = hb.trajectory_done ? 1U : 0U;
  return f;
}

CanFrame encode_encoder_estimates(std::uint8_t node_id, const EncoderEstimates& e) {
  CanFrame f = frame(node_id, Command::kGetEncoderEstimates, 8);
  put_f32(f.data.data(), e.pos_turns);
  put_f32(f.data.data() + 4, e.vel_turns_s);
  return f;
}

DecodeStatus decode(const CanFrame& f, Message& out) {
  if (f.extended) return DecodeStatus::kExtendedId;
  if (f.dlc > 8) return DecodeStatus::kBadDlc;
  out.node_id = node_of(f.id);
  const std::uint8_t cmd = command_of(f.id);
  const std::uint8_t* d = f.data.data();
  auto need = [&](std::uint8_t dlc) { return f.dlc == dlc; };
  switch (cmd) {
    case static_cast<std::uint8_t>(Command::kHeartbeat):
      out.command = Command::kHeartbeat;
      if (f.remote) return DecodeStatus::kRemoteRequest;
      if (!need(8)) return DecodeStatus::kWrongLength;
      out.heartbeat.axis_error = get_u32(d);
      out.heartbeat.axis_state = d[4];
      out.heartbeat.procedure_result = d[5];
      out.heartbeat.trajectory_done = (d[6] & 1U) != 0;
      return DecodeStatus::kOk;
    case static_cast<std::uint8_t>(Command::kEstop):
      out.command = Command::kEstop;
      if (f.remote) return DecodeStatus::kRemoteRequest;
      return need(0) ? DecodeStatus::kOk : DecodeStatus::kWrongLength;
    case static_cast<std::uint8_t>(Command::kSetAxisState):
      out.command = Command::kSetAxisState;
      if (f.remote) return DecodeStatus::kRemoteRequest;
      if (!need(4)) return DecodeStatus::kWrongLength;
      out.requested_state = get_u32(d);
      return DecodeStatus::kOk;
    case static_cast<std::uint8_t>(Command::kGetEncoderEstimates): {
      out.command = Command::kGetEncoderEstimates;
      if (f.remote) return DecodeStatus::kRemoteRequest;
      if (!need(8)) return DecodeStatus::kWrongLength;
      const float pos = get_f32(d);
      const float vel = get_f32(d + 4);
      if (!std::isfinite(pos) || !std::isfinite(vel)) return DecodeStatus::kNotFinite;
      out.encoder.pos_turns = pos;
      out.encoder.vel_turns_s = vel;
      return DecodeStatus::kOk;
    }
    case static_cast<std::uint8_t>(Command::kSetControllerMode):
      out.command = Command::kSetControllerMode;
      if (f.remote) return DecodeStatus::kRemoteRequest;
      if (!need(8)) return DecodeStatus::kWrongLength;
      out.control_mode = get_u32(d);
      out.input_mode = get_u32(d + 4);
      return DecodeStatus::kOk;
    case static_cast<std::uint8_t>(Command::kSetInputVel): {
      out.command = Command::kSetInputVel;
      if (f.remote) return DecodeStatus::kRemoteRequest;
      if (!need(8)) return DecodeStatus::kWrongLength;
      const float vel = get_f32(d);
      const float torque = get_f32(d + 4);
      if (!std::isfinite(vel) || !std::isfinite(torque)) return DecodeStatus::kNotFinite;
      out.input_vel_turns_s = vel;
      out.input_torque_ff_nm = torque;
      return DecodeStatus::kOk;
    }
    case static_cast<std::uint8_t>(Command::kClearErrors):
      out.command = Command::kClearErrors;
      if (f.remote) return DecodeStatus::kRemoteRequest;
      return f.dlc <= 1 ? DecodeStatus::kOk : DecodeStatus::kWrongLength;
    default:
      return DecodeStatus::kUnknownCommand;
  }
}

const char* to_string(DecodeStatus s) {
  switch (s) {
    case DecodeStatus::kOk:
      return "ok";
    case DecodeStatus::kExtendedId:
      return "extended id";
    case DecodeStatus::kBadDlc:
      return "dlc above 8";
    case DecodeStatus::kUnknownCommand:
      return "unknown command id";
    case DecodeStatus::kWrongLength:
      return "wrong payload length";
    case DecodeStatus::kNotFinite:
      return "non-finite float";
    case DecodeStatus::kRemoteRequest:
      return "remote request";
  }
  return "?";
}

}  // namespace boticelli::codec::odrive
