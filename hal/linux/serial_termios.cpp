// SerialTermios / SerialStdio: non-blocking byte streams on a tty or on stdin/stdout.
#include "hal/linux/serial_termios.h"

#include <fcntl.h>
#include <poll.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstdio>

#include "hal/linux/error_text.h"

namespace boticelli::hal_linux {

bool baud_to_speed(std::uint32_t baud, speed_t& speed) {
  struct Rate {
    std::uint32_t baud;
    speed_t speed;
  };
  static constexpr Rate kRates[] = {
      {1200, B1200},     {2400, B2400},     {4800, B4800},     {9600, B9600},
      {19200, B19200},   {38400, B38400},   {57600, B57600},   {115200, B115200},
      {230400, B230400}, {460800, B460800}, {500000, B500000}, {921600, B921600},
  };
  for (const Rate& r : kRates) {
    if (r.baud == baud) {
      speed = r.speed;
      return true;
    }
  }
  return false;
}

namespace {

std::ptrdiff_t read_fd(int fd, std::uint8_t* buffer, std::size_t max, bool& eof, int& err) {
  err = 0;
  if (max == 0) return 0;
  for (;;) {
    const ssize_t n = ::read(fd, buffer, max);
    if (n > 0) return static_cast<std::ptrdiff_t>(n);
    if (n == 0) {
      eof = true;  // a regular file or pipe at its end; a raw tty (VMIN=0) with no data
      return 0;
    }
    if (errno == EINTR) continue;
    if (errno == EAGAIN || errno == EWOULDBLOCK) return 0;
    err = errno;
    return -1;
  }
}

std::ptrdiff_t write_fd(int fd, const std::uint8_t* data, std::size_t size, int& err) {
  err = 0;
  if (size == 0) return 0;
  for (;;) {
    const ssize_t n = ::write(fd, data, size);
    if (n >= 0) return static_cast<std::ptrdiff_t>(n);
    if (errno == EINTR) continue;
    if (errno == EAGAIN || errno == EWOULDBLOCK) return 0;
    err = errno;
    return -1;
  }
}

}  // namespace

SerialTermios::SerialTermios(const SerialConfig& config) : config_(config) {}

SerialTermios::~SerialTermios() {
  close();
}

bool SerialTermios::open() {
  close();
  speed_t speed{};
  if (!baud_to_speed(config_.baud, speed)) {
    set_error(error_, "serial: unsupported baud rate");
    return false;
  }
  fd_ = ::open(config_.device, O_RDWR | O_NOCTTY | O_NONBLOCK | O_CLOEXEC);
  if (fd_ < 0) {
    // Name the device: the message is what an operator sees in the journal.
    char what[160];
    std::snprintf(what, sizeof what, "serial %s: open failed", config_.device);
    set_error(error_, what, errno);
    return false;
  }
  if (::tcgetattr(fd_, &saved_) != 0) {
    char what[160];
    std::snprintf(what, sizeof what, "serial %s: not a terminal", config_.device);
    set_error(error_, what, errno);
    close();
    return false;
  }
  saved_valid_ = true;
  termios t = saved_;
  ::cfmakeraw(&t);  // no echo, no canonical mode, no signals, 8 bits
  t.c_cflag &= ~static_cast<tcflag_t>(PARENB | CSTOPB | CSIZE | CRTSCTS);
  t.c_cflag |= static_cast<tcflag_t>(CS8 | CLOCAL | CREAD);
  t.c_iflag &= ~static_cast<tcflag_t>(IXON | IXOFF | IXANY);
  t.c_cc[VMIN] = 0;
  t.c_cc[VTIME] = 0;
  if (::cfsetispeed(&t, speed) != 0 || ::cfsetospeed(&t, speed) != 0 ||
      ::tcsetattr(fd_, TCSANOW, &t) != 0) {
    set_error(error_, "serial: cannot configure the line", errno);
    close();
    return false;
  }
  error_[0] = '\0';
  return true;
}

void SerialTermios::close() {
  if (fd_ >= 0) {
    if (saved_valid_) ::tcsetattr(fd_, TCSANOW, &saved_);
    ::close(fd_);
  }
  fd_ = -1;
  saved_valid_ = false;
}

void SerialTermios::flush_input() {
  if (fd_ >= 0) ::tcflush(fd_, TCIFLUSH);
}

std::ptrdiff_t SerialTermios::read(std::uint8_t* buffer, std::size_t max) {
  if (fd_ < 0) {
    set_error(error_, "serial: not open");
    return -1;
  }
  bool eof = false;
  int err = 0;
  std::ptrdiff_t n = read_fd(fd_, buffer, max, eof, err);
  if (n == 0) {
    // A raw tty with VMIN = 0 reads 0 both for "no data" and, on a pty, after the other
    // side closed; a zero-timeout poll tells them apart (POLLHUP / POLLERR).
    pollfd p{fd_, POLLIN, 0};
    if (::poll(&p, 1, 0) > 0 && (p.revents & (POLLHUP | POLLERR | POLLNVAL)) != 0) {
      err = EIO;
      n = -1;
    }
  }
  if (n < 0) set_error(error_, "serial: read failed (line hung up or device gone)", err);
  return n;
}

std::ptrdiff_t SerialTermios::write(const std::uint8_t* data, std::size_t size) {
  if (fd_ < 0) {
    set_error(error_, "serial: not open");
    return -1;
  }
  int err = 0;
  const std::ptrdiff_t n = write_fd(fd_, data, size, err);
  if (n < 0) set_error(error_, "serial: write failed", err);
  return n;
}

SerialStdio::~SerialStdio() {
  close();
}

namespace {

// A descriptor of its own for stdin or stdout that is non-blocking without touching the
// shared one: O_NONBLOCK belongs to the open file description, which the parent shell
// shares and would keep after a crash (its next read fails with EAGAIN). A terminal or pipe
// is opened anew through /proc/self/fd (a new description); a regular file never blocks
// and is duplicated (a new open would start at offset 0); anything else (a socket) is
// duplicated and `guarded`: read and written only when poll() says it will not block.
int private_stdio_fd(int fd, int access, bool& guarded) {
  guarded = false;
  struct stat st {};
  if (::fstat(fd, &st) != 0) return -1;
  if (S_ISREG(st.st_mode)) return ::fcntl(fd, F_DUPFD_CLOEXEC, 3);
  if (S_ISCHR(st.st_mode) || S_ISFIFO(st.st_mode)) {
    char path[32];
    std::snprintf(path, sizeof path, "/proc/self/fd/%d", fd);
    const int own = ::open(path, access | O_NONBLOCK | O_NOCTTY | O_CLOEXEC);
    if (own >= 0) return own;
  }
  guarded = true;
  return ::fcntl(fd, F_DUPFD_CLOEXEC, 3);
}

bool ready_for(int fd, short events) {
  pollfd p{fd, events, 0};
  return ::poll(&p, 1, 0) > 0 && (p.revents & (events | POLLHUP | POLLERR)) != 0;
}

}  // namespace

bool SerialStdio::open() {
  close();
  in_fd_ = private_stdio_fd(STDIN_FILENO, O_RDONLY, in_guarded_);
  out_fd_ = private_stdio_fd(STDOUT_FILENO, O_WRONLY, out_guarded_);
  if (in_fd_ < 0 || out_fd_ < 0) {
    set_error(error_, "stdio: stdin/stdout not open", errno);
    close_fds();
    return false;
  }
  stdin_tty_ = ::isatty(in_fd_) == 1;
  if (stdin_tty_ && ::tcgetattr(in_fd_, &saved_) == 0) {
    saved_valid_ = true;
    termios t = saved_;
    // Raw input for a console: no echo, byte at a time, but keep output post-processing
    // (\n -> \r\n) and ISIG so Ctrl-C still stops the process.
    t.c_lflag &= ~static_cast<tcflag_t>(ICANON | ECHO | ECHONL | IEXTEN);
    t.c_iflag &= ~static_cast<tcflag_t>(IXON | ICRNL | INLCR | IGNCR);
    t.c_cc[VMIN] = 0;
    t.c_cc[VTIME] = 0;
    ::tcsetattr(in_fd_, TCSANOW, &t);
  }
  open_ = true;
  eof_ = false;
  error_[0] = '\0';
  return true;
}

void SerialStdio::close_fds() {
  if (in_fd_ >= 0) ::close(in_fd_);
  if (out_fd_ >= 0) ::close(out_fd_);
  in_fd_ = out_fd_ = -1;
}

void SerialStdio::close() {
  if (!open_) return;
  if (saved_valid_) ::tcsetattr(in_fd_, TCSANOW, &saved_);
  saved_valid_ = false;
  close_fds();
  open_ = false;
}

std::ptrdiff_t SerialStdio::read(std::uint8_t* buffer, std::size_t max) {
  if (!open_) {
    set_error(error_, "stdio: not open");
    return -1;
  }
  if (eof_) return 0;  // stdin closed (pipe at its end): nothing more will come
  if (in_guarded_ && !ready_for(in_fd_, POLLIN)) return 0;
  int err = 0;
  bool eof = false;
  const std::ptrdiff_t n = read_fd(in_fd_, buffer, max, eof, err);
  // On a terminal in raw mode (VMIN = 0) a 0 only means "nothing typed yet".
  if (eof && !stdin_tty_) eof_ = true;
  if (n < 0) set_error(error_, "stdio: read failed", err);
  return n;
}

std::ptrdiff_t SerialStdio::write(const std::uint8_t* data, std::size_t size) {
  if (!open_) {
    set_error(error_, "stdio: not open");
    return -1;
  }
  if (out_guarded_) {
    // Blocking descriptor: write only what fits without waiting (POLLOUT promises at
    // least PIPE_BUF bytes on a pipe or socket buffer of the usual size).
    if (!ready_for(out_fd_, POLLOUT)) return 0;
    size = std::min<std::size_t>(size, 512);
  }
  int err = 0;
  const std::ptrdiff_t n = write_fd(out_fd_, data, size, err);
  if (n < 0) set_error(error_, "stdio: write failed", err);
  return n;
}

}  // namespace boticelli::hal_linux
