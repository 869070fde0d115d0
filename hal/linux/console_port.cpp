// ConsolePort: console line selection and pseudo-terminal set-up (see console_port.h).
#include "hal/linux/console_port.h"

#include <fcntl.h>
#include <stdlib.h>
#include <unistd.h>

#include <cerrno>
#include <cstdio>
#include <cstring>

namespace boticelli::hal_linux {

ConsolePort::ConsolePort(const char* default_device, std::uint32_t baud)
    : default_device_(default_device), baud_(baud) {}

ConsolePort::~ConsolePort() {
  if (pty_slave_fd_ >= 0) ::close(pty_slave_fd_);
}

void ConsolePort::select(ConsoleMode mode, const char* device_path) {
  mode_ = mode;
  switch (mode) {
    case ConsoleMode::kStdio:
      active_ = &stdio_;
      break;
    case ConsoleMode::kPty:
      // Opening the multiplexer creates a new pair; the termios port holds the master.
      tty_.emplace(SerialConfig{"/dev/ptmx", baud_});
      active_ = &*tty_;
      break;
    case ConsoleMode::kDevice:
      tty_.emplace(SerialConfig{device_path != nullptr ? device_path : default_device_, baud_});
      active_ = &*tty_;
      break;
  }
}

bool ConsolePort::open() {
  error_[0] = '\0';
  // A second open() makes a new pair: the old slave goes (it used to leak).
  if (pty_slave_fd_ >= 0) ::close(pty_slave_fd_);
  pty_slave_fd_ = -1;
  if (!active_->open()) return false;
  if (mode_ != ConsoleMode::kPty) return true;
  const int master = tty_->fd();
  char slave[128] = "";
  if (::grantpt(master) != 0 || ::unlockpt(master) != 0 ||
      ::ptsname_r(master, slave, sizeof slave) != 0) {
    std::snprintf(error_, sizeof error_, "pty: %s", std::strerror(errno));
    return false;
  }
  pty_slave_fd_ = ::open(slave, O_RDWR | O_NOCTTY | O_CLOEXEC);
  if (pty_slave_fd_ < 0) {
    std::snprintf(error_, sizeof error_, "pty %s: %s", slave, std::strerror(errno));
    return false;
  }
  std::fprintf(stderr, "boticelli: console on %s\n", slave);
  return true;
}

std::ptrdiff_t ConsolePort::read(std::uint8_t* buffer, std::size_t max) {
  return active_->read(buffer, max);
}

std::ptrdiff_t ConsolePort::write(const std::uint8_t* data, std::size_t size) {
  return active_->write(data, size);
}

const char* ConsolePort::error() const {
  return error_[0] != '\0' ? error_ : active_->error();
}

}  // namespace boticelli::hal_linux
