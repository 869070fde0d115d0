// ConsolePort: the console line of a Linux board — stdio, any tty/UART, or a fresh pseudo-terminal.
#pragma once

#include <cstddef>
#include <cstdint>
#include <optional>

#include "hal/linux/serial_termios.h"
#include "hal/serial_port.h"

namespace boticelli::hal_linux {

enum class ConsoleMode : std::uint8_t {
  kStdio,   // stdin/stdout of the process (raw mode only when stdin is a tty)
  kPty,     // a new pseudo-terminal pair; the slave's path is printed on stderr
  kDevice,  // a tty device (a UART, a USB serial adapter, an existing pty)
};

// Forwards to the termios or stdio port. For kPty it opens /dev/ptmx through the termios
// port, unlocks the pair, prints the slave's path and holds the slave open itself, so the
// console survives a terminal program closing and reopening it.
class ConsolePort final : public hal::SerialPort {
 public:
  // `default_device` is used for kDevice when select() is given no path.
  ConsolePort(const char* default_device, std::uint32_t baud);
  ~ConsolePort() override;

  // At board init (before open()): which line open() will use. Builds the termios port in
  // place (no heap).
  void select(ConsoleMode mode, const char* device_path);
  // Before select(): the baud rate of a kDevice line (the board's configured one).
  void set_baud(std::uint32_t baud) { baud_ = baud; }
  bool open() override;
  std::ptrdiff_t read(std::uint8_t* buffer, std::size_t max) override;
  std::ptrdiff_t write(const std::uint8_t* data, std::size_t size) override;
  const char* error() const override;

 private:
  const char* default_device_;
  std::uint32_t baud_;
  std::optional<SerialTermios> tty_;
  SerialStdio stdio_;
  hal::SerialPort* active_ = &stdio_;
  ConsoleMode mode_ = ConsoleMode::kStdio;
  int pty_slave_fd_ = -1;
  char error_[160] = "";
};

}  // namespace boticelli::hal_linux
