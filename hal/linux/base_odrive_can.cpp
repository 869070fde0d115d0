// BaseOdriveCan: SocketCAN transport, start-up sequence, setpoints, heartbeat watchdog, odometry.
#include "hal/linux/base_odrive_can.h"

#include <fcntl.h>
#include <linux/can.h>
#include <linux/can/error.h>
#include <linux/can/raw.h>
#include <net/if.h>
#include <sys/ioctl.h>
#include <sys/socket.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstring>

#include "hal/linux/error_text.h"

namespace boticelli::hal_linux {

namespace odrive = codec::odrive;

namespace {

constexpr const char* kSide[2] = {"left", "right"};
// Encoder estimates beyond these are corrupt, not motion (finite, as the codec checks, but
// they would overflow the odometry to infinity): 1e7 turns is where a float position no
// longer resolves a turn; 1000 turns/s (60000 rpm) is beyond any wheel motor.
constexpr float kMaxPlausiblePosTurns = 1e7F;
constexpr float kMaxPlausibleVelTurnsS = 1000.0F;

can_frame to_os(const odrive::CanFrame& f) {
  can_frame out{};
  out.can_id = f.id & (f.extended ? CAN_EFF_MASK : CAN_SFF_MASK);
  if (f.extended) out.can_id |= CAN_EFF_FLAG;
  if (f.remote) out.can_id |= CAN_RTR_FLAG;
  out.len = f.dlc;
  std::memcpy(out.data, f.data.data(), 8);
  return out;
}

odrive::CanFrame from_os(const can_frame& f) {
  odrive::CanFrame out;
  out.extended = (f.can_id & CAN_EFF_FLAG) != 0;
  out.remote = (f.can_id & CAN_RTR_FLAG) != 0;
  out.id = f.can_id & (out.extended ? CAN_EFF_MASK : CAN_SFF_MASK);
  out.dlc = f.len;
  std::memcpy(out.data.data(), f.data, 8);
  return out;
}

float clamp_abs(float v, float limit) {
  return std::clamp(v, -limit, limit);
}

}  // namespace

BaseOdriveCan::BaseOdriveCan(const BaseOdriveCanConfig& config, hal::Clock& clock)
    : config_(config), clock_(clock), integrator_(config.geometry) {
  axes_[0].node_id = config.left_node_id;
  axes_[1].node_id = config.right_node_id;
  for (int k = 0; k < 2; ++k)
    last_gasp_frames_[k] = odrive::encode_set_input_vel(axes_[k].node_id, 0.0F);
}

BaseOdriveCan::~BaseOdriveCan() {
  close_socket();
}

void BaseOdriveCan::close_socket() {
  if (fd_ >= 0) ::close(fd_);
  fd_ = -1;
}

bool BaseOdriveCan::init() {
  const auto& g = config_.geometry;
  if (!(g.wheel_radius_m > 0.0F) || !(g.track_width_m > 0.0F) || !(g.left_scale > 0.0F) ||
      !(g.right_scale > 0.0F) || config_.left_node_id > odrive::kMaxNodeId ||
      config_.right_node_id > odrive::kMaxNodeId || config_.left_node_id == config_.right_node_id) {
    set_error(error_,
              "base: bad configuration (wheel radius, track width, wheel scales or node ids)");
    health_ = hal::BaseHealth::kStopped;
    return false;
  }
  close_socket();
  if (config_.socket_fd >= 0) {
    fd_ = config_.socket_fd;
    config_.socket_fd = -1;  // owned now; a second init() opens the interface
    owns_interface_ = false;
  } else if (!open_socket()) {
    return false;
  }
  ::fcntl(fd_, F_SETFL, ::fcntl(fd_, F_GETFL) | O_NONBLOCK);
  integrator_ = codec::DiffDriveOdometry(config_.geometry);
  odometry_ = {};
  bus_off_ = false;
  begin_startup(clock_.now_us());
  return true;
}

bool BaseOdriveCan::open_socket() {
  close_socket();
  owns_interface_ = true;
  fd_ = ::socket(PF_CAN, SOCK_RAW | SOCK_NONBLOCK | SOCK_CLOEXEC, CAN_RAW);
  if (fd_ < 0) {
    set_error(error_, "base: cannot open a CAN socket", errno);
    return false;
  }
  // Kernel filters: only frames from the two nodes (any command), plus the error frames the
  // driver acts on. Bus errors (CAN_ERR_PROT, CAN_ERR_BUSERROR, ...) are left out: on a bad
  // bus they come by the thousand and would crowd the heartbeats out of the bounded drain.
  can_filter filters[2];
  for (int i = 0; i < 2; ++i) {
    filters[i].can_id = static_cast<canid_t>(axes_[i].node_id) << 5U;
    filters[i].can_mask = (static_cast<canid_t>(odrive::kMaxNodeId) << 5U) | CAN_EFF_FLAG;
  }
  const can_err_mask_t err_mask = CAN_ERR_BUSOFF | CAN_ERR_RESTARTED;
  if (::setsockopt(fd_, SOL_CAN_RAW, CAN_RAW_FILTER, filters, sizeof filters) != 0 ||
      ::setsockopt(fd_, SOL_CAN_RAW, CAN_RAW_ERR_FILTER, &err_mask, sizeof err_mask) != 0) {
    set_error(error_, "base: cannot set CAN filters", errno);
    close_socket();
    return false;
  }
  ifreq ifr{};
  std::snprintf(ifr.ifr_name, IFNAMSIZ, "%s", config_.interface);
  if (::ioctl(fd_, SIOCGIFINDEX, &ifr) != 0) {
    char what[80];
    std::snprintf(what, sizeof what, "base: no such CAN interface %s", ifr.ifr_name);
    set_error(error_, what, errno);
    close_socket();
    return false;
  }
  sockaddr_can addr{};
  addr.can_family = AF_CAN;
  addr.can_ifindex = ifr.ifr_ifindex;
  if (::bind(fd_, reinterpret_cast<sockaddr*>(&addr), sizeof addr) != 0) {
    set_error(error_, "base: cannot bind the CAN socket", errno);
    close_socket();
    return false;
  }
  ifindex_ = ifr.ifr_ifindex;
  bus_off_ = false;  // a new socket on a (re-added) interface: its controller starts afresh
  return true;
}

// True when the interface the socket should use exists and is up; a socket bound to an
// interface that was deleted (and maybe added again under the same name, with a new index)
// is dead for good, so a new one is opened.
bool BaseOdriveCan::interface_usable() {
  ifreq ifr{};
  std::snprintf(ifr.ifr_name, IFNAMSIZ, "%s", config_.interface);
  char what[80];
  if (fd_ < 0 || ::ioctl(fd_, SIOCGIFINDEX, &ifr) != 0) {
    if (!open_socket()) return false;
  } else if (ifr.ifr_ifindex != ifindex_ && !open_socket()) {
    return false;
  }
  if (::ioctl(fd_, SIOCGIFFLAGS, &ifr) != 0) {
    std::snprintf(what, sizeof what, "base: cannot read the state of %s", ifr.ifr_name);
    set_error(error_, what, errno);
    return false;
  }
  if ((ifr.ifr_flags & IFF_UP) == 0) {
    std::snprintf(error_, sizeof error_, "base: CAN interface %s is down", ifr.ifr_name);
    return false;
  }
  return true;
}

void BaseOdriveCan::begin_startup(std::uint64_t now_us) {
  health_ = hal::BaseHealth::kStarting;
  error_[0] = '\0';
  braking_ = false;
  idled_by_request_ = false;
  setpoint_turns_s_ = {};
  for (Axis& a : axes_) {
    a.heartbeat_seen = false;
    a.encoder_seen = false;
    a.encoder_fresh = false;
    a.behind_since_us = 0;
  }
  startup_deadline_us_ = now_us + std::uint64_t{config_.startup_timeout_ms} * 1000U;
  send_startup_commands();
  next_state_send_us_ = now_us + std::uint64_t{config_.state_resend_ms} * 1000U;
}

void BaseOdriveCan::send_startup_commands() {
  for (const Axis& a : axes_) {
    send(odrive::encode_clear_errors(a.node_id));
    send(odrive::encode_set_controller_mode(a.node_id, odrive::ControlMode::kVelocityControl,
                                            odrive::InputMode::kPassthrough));
    send(odrive::encode_set_input_vel(a.node_id, 0.0F));
    send(odrive::encode_set_axis_state(a.node_id, odrive::AxisState::kClosedLoopControl));
  }
}

void BaseOdriveCan::send(const odrive::CanFrame& f) {
  if (fd_ < 0) return;
  const can_frame frame = to_os(f);
  for (;;) {
    const ssize_t n = ::write(fd_, &frame, sizeof frame);
    if (n == static_cast<ssize_t>(sizeof frame)) {
      ++sent_frames_;
      return;
    }
    if (n < 0 && errno == EINTR) continue;
    // ENOBUFS / EAGAIN: the TX queue is full (no ACK on the bus, bus-off); the setpoint is
    // re-sent next cycle anyway. Counted; the heartbeat watchdog decides about stopping.
    ++send_failures_;
    return;
  }
}

void BaseOdriveCan::fault(const char* what, const char* side, std::uint32_t value, StopKind kind) {
  if (side != nullptr) {
    std::snprintf(error_, sizeof error_, "base: %s axis: %s (0x%08x)", side, what,
                  static_cast<unsigned>(value));
  } else {
    std::snprintf(error_, sizeof error_, "base: %s", what);
  }
  const std::uint64_t now = clock_.now_us();
  if (health_ == hal::BaseHealth::kReady && kind == StopKind::kBrake) {
    // Stop category 1: setpoint 0 in closed loop, the velocity controllers brake; the axes
    // are idled once the wheels are at rest (update_braking()).
    braking_ = true;
    idled_by_request_ = false;
    brake_deadline_us_ = now + std::uint64_t{config_.brake_timeout_ms} * 1000U;
    for (const Axis& a : axes_) send(odrive::encode_set_input_vel(a.node_id, 0.0F));
  } else if (health_ != hal::BaseHealth::kStopped || braking_) {
    // Braking cannot work (an axis out of closed loop or out of reach): idle both at once,
    // also a brake under way.
    braking_ = false;
    idled_by_request_ = false;
    for (const Axis& a : axes_) {
      send(odrive::encode_set_input_vel(a.node_id, 0.0F));
      send(odrive::encode_estop(a.node_id));
    }
  }
  health_ = hal::BaseHealth::kStopped;
  next_stop_send_us_ = now + std::uint64_t{config_.stop_resend_ms} * 1000U;
  setpoint_turns_s_ = {};
  odometry_.v_m_s = 0.0F;
  odometry_.omega_rad_s = 0.0F;
}

void BaseOdriveCan::send_stop_frames() {
  for (const Axis& a : axes_) {
    send(odrive::encode_set_input_vel(a.node_id, 0.0F));
    send(idled_by_request_ ? odrive::encode_set_axis_state(a.node_id, odrive::AxisState::kIdle)
                           : odrive::encode_estop(a.node_id));
  }
}

// A controlled stop under way: setpoint 0 on every call (it also feeds the ODrives' own
// watchdog), IDLE once both measured wheel speeds are at rest or the brake time is over. An
// axis that stops answering or reports an error while braking is idled at once (Estop).
void BaseOdriveCan::update_braking(std::uint64_t now_us) {
  for (int k = 0; k < 2; ++k) {
    const Axis& a = axes_[k];
    if (now_us - a.last_heartbeat_us > std::uint64_t{config_.heartbeat_timeout_ms} * 1000U) {
      fault("heartbeat lost while braking", kSide[k], 0);
      return;
    }
    if (a.heartbeat.axis_error != 0) {
      fault("ODrive reports an axis error while braking", kSide[k], a.heartbeat.axis_error);
      return;
    }
  }
  bool at_rest = encoders_current(now_us);
  for (const Axis& a : axes_) {
    at_rest = at_rest && std::fabs(a.encoder.vel_turns_s) < config_.standstill_turns_s;
  }
  if (at_rest || now_us >= brake_deadline_us_) {
    braking_ = false;
    idled_by_request_ = true;
    for (const Axis& a : axes_) {
      send(odrive::encode_set_axis_state(a.node_id, odrive::AxisState::kIdle));
    }
    next_stop_send_us_ = now_us + std::uint64_t{config_.stop_resend_ms} * 1000U;
    return;
  }
  for (const Axis& a : axes_) send(odrive::encode_set_input_vel(a.node_id, 0.0F));
}

void BaseOdriveCan::handle_error_frame(std::uint32_t can_id, const std::uint8_t* data) {
  ++error_frames_;
  if ((can_id & CAN_ERR_BUSOFF) != 0) {
    bus_off_ = true;
    fault("CAN bus-off (controller stopped transmitting)");
    return;
  }
  if ((can_id & CAN_ERR_RESTARTED) != 0) bus_off_ = false;
  if ((can_id & CAN_ERR_CRTL) != 0 &&
      (data[1] & (CAN_ERR_CRTL_RX_OVERFLOW | CAN_ERR_CRTL_TX_OVERFLOW)) != 0) {
    // Lost frames: not fatal by itself; the heartbeat watchdog catches a dead link.
    return;
  }
}

void BaseOdriveCan::receive(std::uint64_t now_us) {
  if (fd_ < 0) return;
  for (int i = 0; i < 64; ++i) {  // bounded: at 1 Mbit/s at most ~8 frames per ms arrive
    can_frame frame{};
    const ssize_t n = ::read(fd_, &frame, sizeof frame);
    if (n < 0) {
      if (errno == EINTR) continue;
      if (errno != EAGAIN && errno != EWOULDBLOCK) {
        // ENETDOWN: the link went down (ip link set can0 down); bringing it up again starts
        // the controller afresh, so a bus-off seen before is over. ENODEV: it was deleted.
        if (errno == ENETDOWN || errno == ENODEV) bus_off_ = false;
        char text[120];
        set_error(text, "CAN read failed", errno);
        fault(text);
      }
      return;
    }
    if (n != static_cast<ssize_t>(sizeof frame) || frame.len > CAN_MAX_DLEN) {
      ++rejected_frames_;  // CAN FD or truncated: not CAN Simple
      continue;
    }
    if ((frame.can_id & CAN_ERR_FLAG) != 0) {
      handle_error_frame(frame.can_id, frame.data);
      continue;
    }
    const odrive::CanFrame f = from_os(frame);
    odrive::Message m;
    const odrive::DecodeStatus st = odrive::decode(f, m);
    int side = -1;
    for (int k = 0; k < 2; ++k) {
      if (!f.extended && m.node_id == axes_[k].node_id) side = k;
    }
    if (st != odrive::DecodeStatus::kOk || side < 0) {
      ++rejected_frames_;  // unknown node or command, wrong length, NaN, RTR from others
      continue;
    }
    Axis& a = axes_[side];
    if (m.command == odrive::Command::kHeartbeat) {
      a.heartbeat = m.heartbeat;
      a.heartbeat_seen = true;
      a.last_heartbeat_us = now_us;
    } else if (m.command == odrive::Command::kGetEncoderEstimates) {
      if (!(std::fabs(m.encoder.pos_turns) <= kMaxPlausiblePosTurns &&
            std::fabs(m.encoder.vel_turns_s) <= kMaxPlausibleVelTurnsS)) {
        ++rejected_frames_;
        continue;
      }
      a.encoder = m.encoder;
      a.encoder_seen = true;
      a.encoder_fresh = true;
      a.last_encoder_us = now_us;
    } else {
      ++rejected_frames_;  // a host -> ODrive command seen on the bus (another master)
    }
  }
}

bool BaseOdriveCan::encoders_current(std::uint64_t now_us) const {
  const std::uint64_t limit = std::uint64_t{config_.encoder_timeout_ms} * 1000U;
  for (const Axis& a : axes_) {
    if (!a.encoder_seen || now_us - a.last_encoder_us > limit) return false;
  }
  return true;
}

void BaseOdriveCan::update_odometry(std::uint64_t now_us) {
  // Only with a new estimate from both wheels: a wheel whose stream stopped would otherwise
  // be integrated as standing still while the other moves (a phantom turn). Its silence
  // stops the base after encoder_timeout_ms (update()).
  if (!encoders_current(now_us)) return;
  if (!axes_[0].encoder_fresh || !axes_[1].encoder_fresh) return;
  axes_[0].encoder_fresh = axes_[1].encoder_fresh = false;
  integrator_.update({axes_[0].encoder.pos_turns, axes_[1].encoder.pos_turns});
  odometry_.x_m = integrator_.x_m();
  odometry_.y_m = integrator_.y_m();
  odometry_.yaw_rad = integrator_.yaw_rad();
  codec::wheels_to_body({axes_[0].encoder.vel_turns_s, axes_[1].encoder.vel_turns_s},
                        config_.geometry, odometry_.v_m_s, odometry_.omega_rad_s);
  odometry_.timestamp_us = now_us;
  // The ODrives' own position estimates as wheel travel: they keep counting while no
  // firmware runs (a resumed mission dead-reckons from them).
  const double per_turn_m =
      2.0 * 3.14159265358979323846 * static_cast<double>(config_.geometry.wheel_radius_m);
  odometry_.wheels_known = true;
  odometry_.wheel_left_m = static_cast<double>(axes_[0].encoder.pos_turns) *
                           static_cast<double>(config_.geometry.left_direction) * per_turn_m;
  odometry_.wheel_right_m = static_cast<double>(axes_[1].encoder.pos_turns) *
                            static_cast<double>(config_.geometry.right_direction) * per_turn_m;
}

// True once the wheel has been behind its setpoint for follow_timeout_ms: its measured speed
// in the setpoint's direction below follow_ratio of it (a setpoint below follow_min_turns_s
// is not judged; a ramp from rest or a reversal is over well within the time).
bool BaseOdriveCan::wheel_behind(Axis& a, float setpoint_turns_s, std::uint64_t now_us) {
  const float want = std::fabs(setpoint_turns_s);
  const float got = std::copysign(1.0F, setpoint_turns_s) * a.encoder.vel_turns_s;
  if (want < config_.follow_min_turns_s || got >= config_.follow_ratio * want) {
    a.behind_since_us = 0;
    return false;
  }
  if (a.behind_since_us == 0) a.behind_since_us = now_us;
  return now_us - a.behind_since_us > std::uint64_t{config_.follow_timeout_ms} * 1000U;
}

void BaseOdriveCan::update() {
  if (fd_ < 0) return;
  const std::uint64_t now = clock_.now_us();
  receive(now);
  update_odometry(now);
  if (health_ == hal::BaseHealth::kStarting) {
    bool ready = true;
    for (const Axis& a : axes_) {
      ready = ready && a.heartbeat_seen && a.heartbeat.axis_error == 0 &&
              a.heartbeat.axis_state ==
                  static_cast<std::uint8_t>(odrive::AxisState::kClosedLoopControl);
    }
    if (ready) {
      health_ = hal::BaseHealth::kReady;
      ready_since_us_ = now;
    } else if (now >= startup_deadline_us_) {
      for (int k = 0; k < 2; ++k) {
        const Axis& a = axes_[k];
        if (!a.heartbeat_seen) {
          fault("no heartbeat during start-up", kSide[k], 0);
          return;
        }
        if (a.heartbeat.axis_error != 0) {
          fault("error during start-up", kSide[k], a.heartbeat.axis_error);
          return;
        }
        if (a.heartbeat.axis_state !=
            static_cast<std::uint8_t>(odrive::AxisState::kClosedLoopControl)) {
          fault("did not enter closed loop; axis state", kSide[k], a.heartbeat.axis_state);
          return;
        }
      }
      return;
    } else if (now >= next_state_send_us_) {
      send_startup_commands();
      next_state_send_us_ = now + std::uint64_t{config_.state_resend_ms} * 1000U;
      return;
    }
  }
  if (health_ == hal::BaseHealth::kStopped) {
    if (braking_) {
      update_braking(now);
      return;
    }
    // Keep commanding the stop: one that was refused (link down, full TX queue) or lost
    // gets through later, and an ODrive that came back on its own is stopped again.
    if (now >= next_stop_send_us_) {
      send_stop_frames();
      next_stop_send_us_ = now + std::uint64_t{config_.stop_resend_ms} * 1000U;
    }
    return;
  }
  if (health_ != hal::BaseHealth::kReady) return;
  const std::uint64_t encoder_limit_us = std::uint64_t{config_.encoder_timeout_ms} * 1000U;
  for (int k = 0; k < 2; ++k) {
    const Axis& a = axes_[k];
    const std::uint64_t encoder_since = a.encoder_seen ? a.last_encoder_us : ready_since_us_;
    if (now - encoder_since > encoder_limit_us) {
      // The ODrive's own loop runs on its own encoder, which the CAN stream's silence does not
      // say is gone (a failed encoder is an axis error): brake, for the brake time (no
      // measurement to see the rest by).
      fault("encoder estimates stopped", kSide[k], 0, StopKind::kBrake);
      return;
    }
    if (now - a.last_heartbeat_us > std::uint64_t{config_.heartbeat_timeout_ms} * 1000U) {
      fault("heartbeat lost", kSide[k], 0);
      return;
    }
    if (a.heartbeat.axis_error != 0) {
      fault("ODrive reports an axis error", kSide[k], a.heartbeat.axis_error);
      return;
    }
    if (a.heartbeat.axis_state !=
        static_cast<std::uint8_t>(odrive::AxisState::kClosedLoopControl)) {
      fault("left closed-loop control; axis state", kSide[k], a.heartbeat.axis_state);
      return;
    }
    if (wheel_behind(axes_[k], k == 0 ? setpoint_turns_s_.left : setpoint_turns_s_.right, now)) {
      // Jammed (the motor cannot turn it) or a frozen encoder (the ODrive's own loop is blind
      // and would wind up): its loop cannot be trusted to brake, so both axes are idled.
      fault("wheel not following its setpoint", kSide[k], 0);
      return;
    }
  }
  // Re-sent every cycle: the ODrive's watchdog (if configured) stops the motor otherwise.
  send(odrive::encode_set_input_vel(axes_[0].node_id, setpoint_turns_s_.left));
  send(odrive::encode_set_input_vel(axes_[1].node_id, setpoint_turns_s_.right));
  if (config_.request_encoder) {
    for (const Axis& a : axes_) send(odrive::encode_encoder_request(a.node_id));
  }
}

void BaseOdriveCan::set_velocity(float v_m_s, float omega_rad_s) {
  if (health_ != hal::BaseHealth::kReady) return;
  if (!std::isfinite(v_m_s) || !std::isfinite(omega_rad_s)) return;
  codec::WheelTurns w = codec::body_to_wheels(v_m_s, omega_rad_s, config_.geometry);
  // Clamp both wheels by the same factor, so the path's curvature is kept.
  const float peak = std::max(std::fabs(w.left), std::fabs(w.right));
  if (peak > config_.max_wheel_turns_s) {
    const float scale = config_.max_wheel_turns_s / peak;
    w.left *= scale;
    w.right *= scale;
  }
  setpoint_turns_s_.left = clamp_abs(w.left, config_.max_wheel_turns_s);
  setpoint_turns_s_.right = clamp_abs(w.right, config_.max_wheel_turns_s);
}

void BaseOdriveCan::stop() {
  if (health_ == hal::BaseHealth::kStopped) {
    // Already stopped (maybe by a fault): update() goes on commanding the stop every
    // stop_resend_ms (a link that is back gets it then) and a brake under way goes on. Asked
    // again (the e-stop task asks every frame while the button is held) nothing more is
    // sent: four frames a frame were bus load and system calls on the e-stop's budget.
    return;
  }
  fault("stopped by request", nullptr, 0, StopKind::kBrake);
}

bool BaseOdriveCan::resume() {
  if (fd_ < 0 && !owns_interface_) return false;
  if (health_ != hal::BaseHealth::kStopped) return true;
  if (bus_off_) {
    // The controller leaves bus-off by itself with restart-ms set (CAN_ERR_RESTARTED), or by
    // `ip link set can0 type can restart`; until then nothing can be sent.
    set_error(error_, "base: the CAN controller is bus-off; resume after it restarts");
    return false;
  }
  if (owns_interface_ && !interface_usable()) return false;
  integrator_.reset_reference();
  begin_startup(clock_.now_us());
  return true;
}

void BaseOdriveCan::last_gasp_stop() noexcept {
  const int fd = fd_;
  if (fd < 0) return;
  for (const odrive::CanFrame& f : last_gasp_frames_) {
    const can_frame frame = to_os(f);  // plain stores: async-signal-safe
    for (int tries = 0; tries < 3; ++tries) {
      if (::write(fd, &frame, sizeof frame) >= 0 || errno != EINTR) break;
    }
  }
}

}  // namespace boticelli::hal_linux
