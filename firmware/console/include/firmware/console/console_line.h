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
  kOlder,      // up arrow (with recall on): the caller may replace() the line with an older one
  kNewer,      // down arrow (with recall on): a newer one
};

// Assembles lines the way a terminal user types them (picocom, screen): CR, LF or CRLF end a
// line (empty lines are ignored), backspace (BS or DEL) erases, Ctrl-C / Ctrl-U cancel, tab
// counts as a space. Anything else below 0x20 or above 0x7E spoils the line. Never stores
// more than kMaxLineBytes. With recall on (an echoing console), the terminal's escape
// sequences are read instead: up and down arrows become kOlder / kNewer, every other
// sequence (left, right, function keys) is ignored.
class LineAssembler {
 public:
  static constexpr std::size_t kMaxLineBytes = 120;

  LineEvent feed(std::uint8_t byte);
  // Valid after kLine until the next feed().
  std::string_view line() const { return {buffer_.data(), size_}; }
  // What an echoing terminal should show for the last byte fed ("" for none, "\b \b" for
  // an erase, "\r\n" for a line end).
  std::string_view echo() const { return echo_; }
  // The part of a line typed so far, as an echoing terminal shows it ("" after a kLine).
  std::string_view typed() const;
  // Replaces the line typed so far (a recalled command; cut to kMaxLineBytes).
  void replace(std::string_view text);
  void set_recall(bool on) { recall_ = on; }
  void reset();

 private:
  std::array<char, kMaxLineBytes> buffer_{};
  std::size_t size_ = 0;
  bool overflow_ = false;
  bool bad_ = false;
  bool line_ready_ = false;
  bool recall_ = false;
  std::uint8_t escape_ = 0;  // 0 none, 1 after ESC, 2 inside ESC [ / ESC O; then parameter bytes
  std::array<char, 1> echo_char_{};
  std::string_view echo_;
};

// The last kEntries command lines for up/down recall, newest first; fixed storage.
class CommandHistory {
 public:
  static constexpr std::size_t kEntries = 16;

  // Keeps a line (not an empty one, nor a repeat of the newest) and ends browsing.
  void add(std::string_view line);
  // One line older than the one shown; false (out unchanged) when there is none.
  bool older(std::string_view& out);
  // One line newer; the empty line after the newest. False when not browsing.
  bool newer(std::string_view& out);
  std::size_t size() const { return count_; }

 private:
  std::string_view entry(std::size_t age) const;  // 1 = newest

  std::array<std::array<char, LineAssembler::kMaxLineBytes>, kEntries> lines_{};
  std::array<std::size_t, kEntries> sizes_{};
  std::size_t next_ = 0;    // slot the next line goes to
  std::size_t count_ = 0;   // lines kept
  std::size_t cursor_ = 0;  // age of the line shown; 0 = not browsing
};

}  // namespace boticelli::firmware
