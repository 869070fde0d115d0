// ConsolePort: the rpi4 board's console — the UART, any tty, stdio or a fresh pseudo-terminal,
// chosen by --console.
#pragma once

#include <cstddef>
#include <cstdint>
#include <optional>

#include "firmware/options.h"
#include "hal/linux/serial_termios.h"
#include "hal/serial_port.h"

namespace boticelli::boards::rpi4 {

// Forwards to the termios or stdio port of the Linux HAL. For `--console pty` it opens
// /dev/ptmx through the termios port, unlocks the pair, prints the slave's path and holds
// the slave open itself, so the console survives a terminal program closing it.
class ConsolePort final : public hal::SerialPort {
 public:
  ConsolePort(const char* uart_device, std::uint32_t baud);
  ~ConsolePort() override;

  // At board init: which port open() will use (kPath with nullptr: the board's UART).
  void select(firmware::ConsoleKind kind, const char* path);
  bool open() override;
  std::ptrdiff_t read(std::uint8_t* buffer, std::size_t max) override;
  std::ptrdiff_t write(const std::uint8_t* data, std::size_t size) override;
  const char* error() const override;

 private:
  const char* uart_device_;
  std::uint32_t baud_;
  std::optional<hal_linux::SerialTermios> tty_;  // built by select() (at init, no heap)
  hal_linux::SerialStdio stdio_;
  hal::SerialPort* active_ = &stdio_;
  firmware::ConsoleKind kind_ = firmware::ConsoleKind::kStdio;
  int pty_slave_fd_ = -1;
  char error_[160] = "";
};

}  // namespace boticelli::boards::rpi4
