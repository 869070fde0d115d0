// Ptu46Emulator: PTU-D46 command interpreter and motion model on a pseudo-terminal.
#include "ptu46_emulator.h"

#include <fcntl.h>
#include <unistd.h>

#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstdlib>

namespace boticelli::fakes {

Ptu46Emulator::Ptu46Emulator(const Ptu46EmulatorConfig& config)
    : config_(config), echo_(config.echo), terse_(config.terse) {
  axes_[0].min = config.pan_min;
  axes_[0].max = config.pan_max;
  axes_[0].speed = config.pan_speed;
  axes_[0].arcsec = config.pan_arcsec_per_count;
  axes_[1].min = config.tilt_min;
  axes_[1].max = config.tilt_max;
  axes_[1].speed = config.tilt_speed;
  axes_[1].arcsec = config.tilt_arcsec_per_count;
}

Ptu46Emulator::~Ptu46Emulator() {
  unplug();
}

bool Ptu46Emulator::open() {
  master_ = ::posix_openpt(O_RDWR | O_NOCTTY);
  if (master_ < 0) return false;
  if (::grantpt(master_) != 0 || ::unlockpt(master_) != 0 ||
      ::ptsname_r(master_, slave_path_, sizeof slave_path_) != 0) {
    unplug();
    return false;
  }
  ::fcntl(master_, F_SETFL, ::fcntl(master_, F_GETFL) | O_NONBLOCK);
  return true;
}

void Ptu46Emulator::unplug() {
  if (master_ >= 0) ::close(master_);
  master_ = -1;
}

void Ptu46Emulator::send_raw(std::string_view bytes) {
  output_.append(bytes);
  flush_output();
}

void Ptu46Emulator::flush_output() {
  while (master_ >= 0 && !output_.empty()) {
    const ssize_t n = ::write(master_, output_.data(), output_.size());
    if (n <= 0) break;
    output_.erase(0, static_cast<std::size_t>(n));
  }
}

std::size_t Ptu46Emulator::count_commands(std::string_view text) const {
  std::size_t n = 0;
  for (const std::string& c : commands_) n += c == text ? 1U : 0U;
  return n;
}

void Ptu46Emulator::hit_pan_limit() {
  axes_[0].position = axes_[0].max;
  axes_[0].target = axes_[0].max;
  send_raw("!P\r\n");
}

bool Ptu46Emulator::at_targets() const {
  for (const AxisSim& a : axes_) {
    if (std::lround(a.position) != a.target) return false;
  }
  return true;
}

void Ptu46Emulator::advance(std::uint64_t now_us) {
  if (!have_time_) {
    last_us_ = now_us;
    have_time_ = true;
  }
  const double dt_s = static_cast<double>(now_us - last_us_) * 1e-6;
  last_us_ = now_us;
  for (AxisSim& a : axes_) {
    const double diff = a.target - a.position;
    const double step = a.speed * dt_s;
    a.position = std::fabs(diff) <= step ? a.target : a.position + (diff > 0 ? step : -step);
  }
  if (resetting_ && now_us >= reset_done_us_) {
    resetting_ = false;
    for (AxisSim& a : axes_) a.position = a.target = 0;
    send_raw("!T!T!P!P*\r\n");
  }
  if (awaiting_ && at_targets()) {
    awaiting_ = false;
    reply_ok("", false, 0);
  }
}

void Ptu46Emulator::service(std::uint64_t now_us) {
  if (master_ < 0) return;
  advance(now_us);
  char buf[128];
  for (;;) {
    const ssize_t n = ::read(master_, buf, sizeof buf);
    if (n <= 0) break;
    for (ssize_t i = 0; i < n; ++i) {
      const char c = buf[i];
      if (silent_) continue;
      if (echo_) output_.push_back(c);
      if (c == ' ' || c == '\r' || c == '\n') {
        if (!input_.empty()) {
          // While awaiting or resetting the unit does not process commands; they queue.
          execute(input_);
          input_.clear();
        }
      } else {
        input_.push_back(c);
      }
    }
  }
  flush_output();
}

void Ptu46Emulator::reply_ok(std::string_view verbose_text, bool with_value, long long value) {
  char line[96];
  if (terse_ || verbose_text.empty()) {
    if (with_value) {
      std::snprintf(line, sizeof line, "* %lld\r\n", value);
    } else {
      std::snprintf(line, sizeof line, "*\r\n");
    }
  } else if (with_value) {
    std::snprintf(line, sizeof line, "* %.*s %lld\r\n", static_cast<int>(verbose_text.size()),
                  verbose_text.data(), value);
  } else {
    std::snprintf(line, sizeof line, "* %.*s\r\n", static_cast<int>(verbose_text.size()),
                  verbose_text.data());
  }
  output_.append(line);
}

void Ptu46Emulator::reply_ok_text(std::string_view value_text) {
  output_.append("* ");
  output_.append(value_text);
  output_.append("\r\n");
}

void Ptu46Emulator::reply_error(std::string_view message) {
  output_.append("! ");
  output_.append(message);
  output_.append("\r\n");
}

void Ptu46Emulator::execute(const std::string& raw) {
  std::string cmd;
  for (char c : raw) cmd.push_back(c >= 'a' && c <= 'z' ? static_cast<char>(c - 'a' + 'A') : c);
  commands_.push_back(cmd);
  if (!pending_error_.empty()) {
    reply_error(pending_error_);
    pending_error_.clear();
    return;
  }
  if (cmd == "FT") {
    terse_ = true;
    reply_ok("Terse feedback", false, 0);
    return;
  }
  if (cmd == "FV") {
    terse_ = false;
    reply_ok("Verbose feedback", false, 0);
    return;
  }
  if (cmd == "ED") {
    echo_ = false;
    reply_ok("Echo disabled", false, 0);
    return;
  }
  if (cmd == "EE") {
    echo_ = true;
    reply_ok("Echo enabled", false, 0);
    return;
  }
  if (cmd == "CI") {
    reply_ok("Independent control mode", false, 0);
    return;
  }
  if (cmd == "H") {
    for (AxisSim& a : axes_)
      a.target = static_cast<std::int32_t>(std::lround(a.position)), a.position = a.target;
    reply_ok("Halted", false, 0);
    return;
  }
  if (cmd == "A") {
    if (at_targets()) {
      reply_ok("", false, 0);
    } else {
      awaiting_ = true;
    }
    return;
  }
  if (cmd == "R") {
    resetting_ = true;
    reset_done_us_ = last_us_ + config_.reset_duration_us;
    return;  // answered "!T!T!P!P*" when done
  }
  if (cmd.size() >= 2 && (cmd[0] == 'P' || cmd[0] == 'T')) {
    AxisSim& a = axes_[cmd[0] == 'P' ? 0 : 1];
    const char* axis_name = cmd[0] == 'P' ? "Pan" : "Tilt";
    const std::string arg = cmd.substr(2);
    char text[64];
    if (arg.empty()) {
      switch (cmd[1]) {
        case 'P':
          std::snprintf(text, sizeof text, "Current %s position is", axis_name);
          reply_ok(text, true, std::lround(a.position));
          return;
        case 'R': {
          char v[32];
          std::snprintf(v, sizeof v, "%.4f", a.arcsec);
          reply_ok_text(v);
          return;
        }
        case 'N':
          reply_ok("Minimum position is", true, a.min);
          return;
        case 'X':
          reply_ok("Maximum position is", true, a.max);
          return;
        case 'S':
          reply_ok("Target speed is", true, a.speed);
          return;
        case 'U':
          reply_ok("Upper speed limit is", true, config_.max_speed);
          return;
        default:
          break;
      }
    } else if (cmd[1] == 'P' || cmd[1] == 'S') {
      char* end = nullptr;
      const long v = std::strtol(arg.c_str(), &end, 10);
      if (end == arg.c_str() || *end != '\0') {
        reply_error("Illegal Command Argument");
        return;
      }
      if (cmd[1] == 'P') {
        if (v > a.max) {
          std::snprintf(text, sizeof text, "Maximum allowable %s position exceeded", axis_name);
          reply_error(text);
          return;
        }
        if (v < a.min) {
          std::snprintf(text, sizeof text, "Minimum allowable %s position exceeded", axis_name);
          reply_error(text);
          return;
        }
        a.target = static_cast<std::int32_t>(v);
        reply_ok("", false, 0);
        return;
      }
      if (v <= 0 || v > config_.max_speed) {
        reply_error("Illegal Command Argument");
        return;
      }
      a.speed = static_cast<std::int32_t>(v);
      reply_ok("", false, 0);
      return;
    }
  }
  reply_error("Illegal Command");
}

}  // namespace boticelli::fakes
