// OdriveCanEmulator: ODrive CAN Simple behaviour (states, setpoints, heartbeats, encoder) on a
// socketpair or a raw CAN socket.
#include "odrive_can_emulator.h"

#include <fcntl.h>
#include <linux/can.h>
#include <linux/can/error.h>
#include <net/if.h>
#include <sys/ioctl.h>
#include <sys/socket.h>
#include <unistd.h>

#include <algorithm>
#include <cstdio>
#include <cstring>

namespace boticelli::fakes {

namespace odrive = codec::odrive;

OdriveCanEmulator::OdriveCanEmulator(const OdriveCanEmulatorConfig& config) : config_(config) {
  axes_[0].node = config.node_ids[0];
  axes_[1].node = config.node_ids[1];
}

OdriveCanEmulator::~OdriveCanEmulator() {
  if (fd_ >= 0) ::close(fd_);
}

bool OdriveCanEmulator::open() {
  int sv[2];
  if (::socketpair(AF_UNIX, SOCK_SEQPACKET, 0, sv) != 0) return false;
  fd_ = sv[0];
  driver_fd_ = sv[1];
  ::fcntl(fd_, F_SETFL, ::fcntl(fd_, F_GETFL) | O_NONBLOCK);
  return true;
}

bool OdriveCanEmulator::open_can(const char* interface) {
  if (fd_ >= 0) ::close(fd_);
  fd_ = ::socket(PF_CAN, SOCK_RAW | SOCK_NONBLOCK | SOCK_CLOEXEC, CAN_RAW);
  if (fd_ < 0) return false;
  ifreq ifr{};
  std::snprintf(ifr.ifr_name, IFNAMSIZ, "%s", interface);
  sockaddr_can addr{};
  addr.can_family = AF_CAN;
  if (::ioctl(fd_, SIOCGIFINDEX, &ifr) != 0) return false;
  addr.can_ifindex = ifr.ifr_ifindex;
  return ::bind(fd_, reinterpret_cast<sockaddr*>(&addr), sizeof addr) == 0;
}

std::uint32_t OdriveCanEmulator::count(int axis, odrive::Command c) const {
  return axes_[axis].counts[static_cast<std::size_t>(c)];
}

void OdriveCanEmulator::set_axis_error(int axis, std::uint32_t error) {
  axes_[axis].error = error;
  axes_[axis].state = 1;  // an error disarms the axis: idle
  axes_[axis].vel_setpoint = 0.0F;
}

void OdriveCanEmulator::send_bytes(const void* data, std::size_t size) {
  if (fd_ >= 0) (void)::send(fd_, data, size, MSG_DONTWAIT);
}

void OdriveCanEmulator::send_frame(const odrive::CanFrame& f) {
  can_frame out{};
  out.can_id = f.id | (f.extended ? CAN_EFF_FLAG : 0U) | (f.remote ? CAN_RTR_FLAG : 0U);
  out.len = f.dlc;
  std::memcpy(out.data, f.data.data(), 8);
  send_bytes(&out, sizeof out);
}

void OdriveCanEmulator::send_bus_off() {
  can_frame err{};
  err.can_id = CAN_ERR_FLAG | CAN_ERR_BUSOFF;
  err.len = CAN_ERR_DLC;
  send_bytes(&err, sizeof err);
}

void OdriveCanEmulator::send_error_frame(std::uint32_t error_class) {
  can_frame err{};
  err.can_id = CAN_ERR_FLAG | (error_class & CAN_ERR_MASK);
  err.len = CAN_ERR_DLC;
  send_bytes(&err, sizeof err);
}

void OdriveCanEmulator::send_heartbeat(AxisSim& a) {
  odrive::Heartbeat hb;
  hb.axis_error = a.error;
  hb.axis_state = a.state;
  send_frame(odrive::encode_heartbeat(a.node, hb));
}

void OdriveCanEmulator::freeze_encoder(int axis, bool frozen) {
  AxisSim& a = axes_[axis];
  a.frozen = frozen;
  a.frozen_at.pos_turns = static_cast<float>(a.pos);
  a.frozen_at.vel_turns_s = 0.0F;  // the estimate of a position that no longer changes
}

void OdriveCanEmulator::send_encoder(AxisSim& a) {
  if (a.frozen) {
    send_frame(odrive::encode_encoder_estimates(a.node, a.frozen_at));
    return;
  }
  odrive::EncoderEstimates e;
  e.pos_turns = static_cast<float>(a.pos);
  const bool perfect = (a.state == 8 ? config_.accel_turns_s2 : config_.coast_turns_s2) <= 0.0F;
  e.vel_turns_s = perfect ? (a.state == 8 && !a.jammed ? a.vel_setpoint : 0.0F) : a.vel;
  send_frame(odrive::encode_encoder_estimates(a.node, e));
}

void OdriveCanEmulator::handle(const odrive::CanFrame& f, std::uint64_t now_us) {
  odrive::Message m;
  const odrive::DecodeStatus st = odrive::decode(f, m);
  AxisSim* a = nullptr;
  for (AxisSim& x : axes_) {
    if (x.node == odrive::node_of(f.id)) a = &x;
  }
  if (a == nullptr) return;  // another node's frame
  if (st == odrive::DecodeStatus::kRemoteRequest &&
      m.command == odrive::Command::kGetEncoderEstimates) {
    ++a->counts[static_cast<std::size_t>(m.command)];
    send_encoder(*a);
    return;
  }
  if (st != odrive::DecodeStatus::kOk) {
    ++undecodable_;
    return;
  }
  ++a->counts[static_cast<std::size_t>(m.command)];
  log_.push_back(
      {a->node, m.command, m.input_vel_turns_s, m.requested_state, {axes_[0].vel, axes_[1].vel}});
  switch (m.command) {
    case odrive::Command::kEstop:
      a->error |= kErrorEstopRequested;
      a->state = 1;
      a->vel_setpoint = 0.0F;
      break;
    case odrive::Command::kClearErrors:
      a->error = 0;
      break;
    case odrive::Command::kSetControllerMode:
      a->control_mode = m.control_mode;
      a->input_mode = m.input_mode;
      break;
    case odrive::Command::kSetInputVel:
      a->vel_setpoint = m.input_vel_turns_s;
      a->last_input_us = now_us;
      break;
    case odrive::Command::kSetAxisState:
      if (m.requested_state == 8) {
        // Closed loop only without errors and in velocity control (as the driver asks).
        if (a->error == 0 && a->state != 8) {
          a->closed_loop_pending = true;
          a->closed_loop_at_us = now_us + config_.closed_loop_delay_us;
          a->last_input_us = now_us;
        }
      } else if (m.requested_state == 1) {
        a->state = 1;
        a->closed_loop_pending = false;
      }
      break;
    default:
      break;
  }
}

void OdriveCanEmulator::service(std::uint64_t now_us) {
  if (fd_ < 0) return;
  if (!have_time_) {
    last_us_ = now_us;
    have_time_ = true;
    for (AxisSim& a : axes_) a.next_heartbeat_us = a.next_encoder_us = now_us;
  }
  // Motion up to now with the setpoints in force so far.
  const double dt_s = static_cast<double>(now_us - last_us_) * 1e-6;
  last_us_ = now_us;
  for (AxisSim& a : axes_) {
    const float v0 = a.vel;
    const bool closed = a.state == 8;
    const float target = closed && !a.jammed ? a.vel_setpoint : 0.0F;
    const float rate = closed ? config_.accel_turns_s2 : config_.coast_turns_s2;
    if (rate <= 0.0F) {
      a.vel = target;
    } else {
      const float dv = rate * static_cast<float>(dt_s);
      a.vel += std::clamp(target - a.vel, -dv, dv);
    }
    // Exact for a perfect controller; trapezoidal while the speed changes.
    a.pos +=
        (rate <= 0.0F ? static_cast<double>(a.vel) : 0.5 * static_cast<double>(v0 + a.vel)) * dt_s;
  }
  for (;;) {
    can_frame frame{};
    const ssize_t n = ::recv(fd_, &frame, sizeof frame, MSG_DONTWAIT);
    if (n <= 0) break;
    if (n != static_cast<ssize_t>(sizeof frame)) {
      ++undecodable_;
      continue;
    }
    odrive::CanFrame f;
    f.extended = (frame.can_id & CAN_EFF_FLAG) != 0;
    f.remote = (frame.can_id & CAN_RTR_FLAG) != 0;
    f.id = frame.can_id & (f.extended ? CAN_EFF_MASK : CAN_SFF_MASK);
    f.dlc = frame.len;
    std::memcpy(f.data.data(), frame.data, 8);
    handle(f, now_us);
  }
  for (AxisSim& a : axes_) {
    if (a.closed_loop_pending && now_us >= a.closed_loop_at_us) {
      a.closed_loop_pending = false;
      if (a.error == 0) a.state = 8;
    }
    if (config_.watchdog_timeout_us > 0 && a.state == 8 &&
        now_us - a.last_input_us > config_.watchdog_timeout_us) {
      a.error |= kErrorWatchdogExpired;
      a.state = 1;
      a.vel_setpoint = 0.0F;
    }
    if (!a.silent && now_us >= a.next_heartbeat_us) {
      send_heartbeat(a);
      a.next_heartbeat_us = now_us + config_.heartbeat_period_us;
    }
    if (config_.encoder_period_us > 0 && !a.encoder_silent && now_us >= a.next_encoder_us) {
      send_encoder(a);
      a.next_encoder_us = now_us + config_.encoder_period_us;
    }
  }
}

}  // namespace boticelli::fakes
