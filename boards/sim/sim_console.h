// SimConsole: the sim board's console — stdio on the host, a fresh pty for --console pty, or a tty
// path.
#pragma once

#include <cstddef>
#include <cstdint>
#include <optional>

#include "firmware/options.h"
#include "hal/linux/serial_termios.h"
#include "hal/serial_port.h"

namespace boticelli::boards::sim {

// Forwards to the Linux HAL's stdio or termios port. For `--console pty` it opens /dev/ptmx,
// unlocks the pair, prints the slave's path on stderr and holds the slave open.
class SimConsole final : public hal::SerialPort {
 public:
  explicit SimConsole(std::uint32_t baud) : baud_(baud) {}
  ~SimConsole() override;
  void select(firmware::ConsoleKind kind, const char* path);
  bool open() override;
  std::ptrdiff_t read(std::uint8_t* buffer, std::size_t max) override;
  std::ptrdiff_t write(const std::uint8_t* data, std::size_t size) override;
  const char* error() const override;

 private:
  std::uint32_t baud_;
  std::optional<hal_linux::SerialTermios> tty_;
  hal_linux::SerialStdio stdio_;
  hal::SerialPort* active_ = &stdio_;
  firmware::ConsoleKind kind_ = firmware::ConsoleKind::kStdio;
  int pty_slave_fd_ = -1;
  char error_[160] = "";
};

}  // namespace boticelli::boards::sim
