// SimConsole: console selection and pseudo-terminal set-up for the sim board (see sim_console.h).
#include "sim_console.h"

#include <fcntl.h>
#include <stdlib.h>
#include <unistd.h>

#include <cerrno>
#include <cstdio>
#include <cstring>

namespace boticelli::boards::sim {

SimConsole::~SimConsole() {
  if (pty_slave_fd_ >= 0) ::close(pty_slave_fd_);
}

void SimConsole::select(firmware::ConsoleKind kind, const char* path) {
  kind_ = kind;
  if (kind == firmware::ConsoleKind::kStdio) {
    active_ = &stdio_;
    return;
  }
  const char* device = kind == firmware::ConsoleKind::kPty ? "/dev/ptmx" : path;
  tty_.emplace(hal_linux::SerialConfig{device != nullptr ? device : "/dev/tty", baud_});
  active_ = &*tty_;
}

bool SimConsole::open() {
  error_[0] = '\0';
  if (!active_->open()) return false;
  if (kind_ != firmware::ConsoleKind::kPty) return true;
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

std::ptrdiff_t SimConsole::read(std::uint8_t* buffer, std::size_t max) {
  return active_->read(buffer, max);
}

std::ptrdiff_t SimConsole::write(const std::uint8_t* data, std::size_t size) {
  return active_->write(data, size);
}

const char* SimConsole::error() const {
  return error_[0] != '\0' ? error_ : active_->error();
}

}  // namespace boticelli::boards::sim
