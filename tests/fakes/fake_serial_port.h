// FakeSerialPort: an in-memory hal::SerialPort (bytes the test feeds in, bytes the code wrote).
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>
#include <string_view>

#include "hal/serial_port.h"

namespace boticelli::fakes {

// Reserve capacity before a no-allocation check: feed() and write() append to strings.
class FakeSerialPort final : public hal::SerialPort {
 public:
  FakeSerialPort() {
    input_.reserve(4096);
    output_.reserve(4096);
  }
  bool open() override {
    opened_ = !fail_open_;
    return opened_;
  }
  std::ptrdiff_t read(std::uint8_t* buffer, std::size_t max) override {
    if (fault_) return -1;
    std::size_t n = input_.size() - read_pos_;
    if (n > max) n = max;
    for (std::size_t i = 0; i < n; ++i)
      buffer[i] = static_cast<std::uint8_t>(input_[read_pos_ + i]);
    read_pos_ += n;
    if (read_pos_ == input_.size()) {
      input_.clear();
      read_pos_ = 0;
    }
    return static_cast<std::ptrdiff_t>(n);
  }
  std::ptrdiff_t write(const std::uint8_t* data, std::size_t size) override {
    if (fault_) return -1;
    std::size_t n = size < write_limit_ ? size : write_limit_;
    output_.append(reinterpret_cast<const char*>(data), n);
    return static_cast<std::ptrdiff_t>(n);
  }
  const char* error() const override { return fault_ ? "fake serial fault" : ""; }

  // Test side.
  void feed(std::string_view bytes) { input_.append(bytes); }
  const std::string& written() const { return output_; }
  void clear_written() { output_.clear(); }
  void reserve_written(std::size_t bytes) { output_.reserve(bytes); }  // for allocation checks
  void set_fault(bool fault) { fault_ = fault; }
  void set_fail_open(bool fail) { fail_open_ = fail; }
  // At most this many bytes are accepted per write() call (to test partial writes).
  void set_write_limit(std::size_t n) { write_limit_ = n; }
  bool opened() const { return opened_; }

 private:
  std::string input_;
  std::size_t read_pos_ = 0;
  std::string output_;
  bool fault_ = false;
  bool fail_open_ = false;
  bool opened_ = false;
  std::size_t write_limit_ = static_cast<std::size_t>(-1);
};

}  // namespace boticelli::fakes
