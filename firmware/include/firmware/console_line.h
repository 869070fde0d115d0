// Console line input: bounded line assembly from untrusted serial bytes (CR/LF, backspace, hostile
// bytes).
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <string_view>

namespace boticelli::firmware {

enum class LineEvent : std::uint8_t {
  kNone,       // byte absorbed, no complete line yet
  kLine,       // line() holds a complete line (without its end)
  kTooLong,    // a line longer than kMaxLineBytes ended; it was discarded
  kBadByte,    // a line with a control or non-ASCII byte ended; it was discarded
  kCancelled,  // Ctrl-C / Ctrl-U dropped the line typed so far
};

// Assembles lines the way a terminal user types them (picocom, screen): CR, LF or CRLF end a
// line (empty lines are ignored), backspace (BS or DEL) erases, Ctrl-C / Ctrl-U cancel, tab
// counts as a space. Anything else below 0x20 or above 0x7E spoils the line. Never stores
// more than kMaxLineBytes.
class LineAssembler {
 public:
  static constexpr std::size_t kMaxLineBytes = 120;

  LineEvent feed(std::uint8_t byte);
  // Valid after kLine until the next feed().
  std::string_view line() const { return {buffer_.data(), size_}; }
  // What an echoing terminal should show for the last byte fed ("" for none, "\b \b" for
  // an erase, "\r\n" for a line end).
  std::string_view echo() const { return echo_; }
  void reset();

 private:
  std::array<char, kMaxLineBytes> buffer_{};
  std::size_t size_ = 0;
  bool overflow_ = false;
  bool bad_ = false;
  bool line_ready_ = false;
  std::array<char, 1> echo_char_{};
  std::string_view echo_;
};

}  // namespace boticelli::firmware
