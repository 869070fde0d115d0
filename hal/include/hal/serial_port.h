// SerialPort: non-blocking byte stream (UART via termios, stdio or a pty on the host).
#pragma once

#include <cstddef>
#include <cstdint>

#include "hal/noncopyable.h"

namespace boticelli::hal {

class SerialPort : private NonCopyable {
 public:
  virtual ~SerialPort() = default;
  // Opens and configures the line; false with error() set when it cannot.
  virtual bool open() = 0;
  // Copies up to `max` received bytes; returns how many (0 when none), −1 on a fault.
  virtual std::ptrdiff_t read(std::uint8_t* buffer, std::size_t max) = 0;
  // Queues up to `size` bytes; returns how many were accepted (may be fewer), −1 on a fault.
  virtual std::ptrdiff_t write(const std::uint8_t* data, std::size_t size) = 0;
  virtual const char* error() const { return ""; }
};

}  // namespace boticelli::hal
