// MockSerialPort: CppUMock mock of hal::SerialPort ("SerialPort.read", "SerialPort.write").
#pragma once

#include "hal/serial_port.h"

#include "CppUTestExt/MockSupport.h"

namespace boticelli::mocks {

// read(): the expectation gives the bytes as output parameter "buffer"
// (withOutputParameterReturning("buffer", bytes, n)) and the count as its return value.
// write(): the bytes are checked as a memory buffer parameter "data"
// (withMemoryBufferParameter("data", bytes, n)); returns the int value or `size`.
class MockSerialPort final : public hal::SerialPort {
 public:
  bool open() override {
    return mock().actualCall("SerialPort.open").onObject(this).returnBoolValueOrDefault(true);
  }
  std::ptrdiff_t read(std::uint8_t* buffer, std::size_t max) override {
    return static_cast<std::ptrdiff_t>(mock()
                                           .actualCall("SerialPort.read")
                                           .onObject(this)
                                           .withOutputParameter("buffer", buffer)
                                           .withParameter("max", static_cast<unsigned long>(max))
                                           .returnLongIntValueOrDefault(0));
  }
  std::ptrdiff_t write(const std::uint8_t* data, std::size_t size) override {
    return static_cast<std::ptrdiff_t>(mock()
                                           .actualCall("SerialPort.write")
                                           .onObject(this)
                                           .withMemoryBufferParameter("data", data, size)
                                           .returnLongIntValueOrDefault(static_cast<long>(size)));
  }
  const char* error() const override {
    return mock().actualCall("SerialPort.error").onObject(this).returnStringValueOrDefault("");
  }
};

}  // namespace boticelli::mocks
