// SerialTermios / SerialStdio: hal::SerialPort on a tty (UART, pty) via termios, or on
// stdin/stdout.
#pragma once

#include <termios.h>

#include <cstddef>
#include <cstdint>

#include "hal/serial_port.h"

namespace boticelli::hal_linux {

struct SerialConfig {
  const char* device = "/dev/ttyAMA0";  // any tty: UART, USB serial, pty slave
  std::uint32_t baud = 115200;          // 1200 ... 921600 (standard termios rates only)
  // Raw 8N1, no flow control, no echo, VMIN = VTIME = 0 (reads never wait).
};

// Opens `device` O_NONBLOCK, saves its termios, sets raw 8N1 at `baud`; the saved settings are
// restored by close() and the destructor. read()/write() never block: 0 when nothing can be
// moved now (EAGAIN), −1 on a fault (hang-up, EIO), EINTR retried.
class SerialTermios final : public hal::SerialPort {
 public:
  explicit SerialTermios(const SerialConfig& config);
  ~SerialTermios() override;

  bool open() override;
  std::ptrdiff_t read(std::uint8_t* buffer, std::size_t max) override;
  std::ptrdiff_t write(const std::uint8_t* data, std::size_t size) override;
  const char* error() const override { return error_; }

  void close();
  int fd() const { return fd_; }
  // Discards unread input (after a resync).
  void flush_input();

 private:
  SerialConfig config_;
  int fd_ = -1;
  bool saved_valid_ = false;
  termios saved_{};
  char error_[128] = "";
};

// The host console: reads stdin, writes stdout, without blocking and without setting
// O_NONBLOCK on the descriptors it shares with the parent shell (which would keep it after
// a crash): a terminal or pipe is opened anew through /proc/self/fd, non-blocking; other
// kinds are read and written only when poll() says so. Raw mode (no echo, no line
// buffering) only when stdin is a terminal, restored by close() and the destructor.
class SerialStdio final : public hal::SerialPort {
 public:
  SerialStdio() = default;
  ~SerialStdio() override;

  bool open() override;
  std::ptrdiff_t read(std::uint8_t* buffer, std::size_t max) override;
  std::ptrdiff_t write(const std::uint8_t* data, std::size_t size) override;
  const char* error() const override { return error_; }
  void close();

 private:
  void close_fds();
  bool open_ = false;
  bool eof_ = false;
  bool stdin_tty_ = false;
  int in_fd_ = -1;
  int out_fd_ = -1;
  bool in_guarded_ = false;
  bool out_guarded_ = false;
  bool saved_valid_ = false;
  termios saved_{};
  char error_[128] = "";
};

// Maps a numeric rate to the termios speed constant; false when it is not a standard rate.
bool baud_to_speed(std::uint32_t baud, speed_t& speed);

}  // namespace boticelli::hal_linux
