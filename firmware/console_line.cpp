// Console line assembly (see console_line.h).
#include "firmware/console_line.h"

namespace boticelli::firmware {

void LineAssembler::reset() {
  size_ = 0;
  overflow_ = false;
  bad_ = false;
  line_ready_ = false;
}

LineEvent LineAssembler::feed(std::uint8_t byte) {
  echo_ = {};
  if (line_ready_) {
    // The previous line was handed out; start a fresh one.
    size_ = 0;
    line_ready_ = false;
  }
  if (byte == '\r' || byte == '\n') {
    const bool empty = size_ == 0 && !overflow_ && !bad_;
    if (empty) return LineEvent::kNone;  // blank line, or the LF of a CRLF
    echo_ = "\r\n";
    const LineEvent event = overflow_ ? LineEvent::kTooLong
                            : bad_    ? LineEvent::kBadByte
                                      : LineEvent::kLine;
    overflow_ = false;
    bad_ = false;
    if (event != LineEvent::kLine) {
      size_ = 0;
      return event;
    }
    line_ready_ = true;
    return LineEvent::kLine;
  }
  if (byte == 0x08 || byte == 0x7F) {  // backspace / delete
    if (size_ > 0 && !overflow_) {
      --size_;
      echo_ = "\b \b";
    }
    return LineEvent::kNone;
  }
  if (byte == 0x03 || byte == 0x15) {  // Ctrl-C, Ctrl-U
    const bool had_text = size_ > 0 || overflow_ || bad_;
    size_ = 0;
    overflow_ = false;
    bad_ = false;
    if (!had_text) return LineEvent::kNone;
    echo_ = "^C\r\n";
    return LineEvent::kCancelled;
  }
  if (byte == '\t') byte = ' ';
  if (byte < 0x20 || byte > 0x7E) {
    bad_ = true;
    return LineEvent::kNone;
  }
  if (size_ == kMaxLineBytes) {
    overflow_ = true;
    return LineEvent::kNone;
  }
  buffer_[size_++] = static_cast<char>(byte);
  echo_char_[0] = static_cast<char>(byte);
  echo_ = {echo_char_.data(), 1};
  return LineEvent::kNone;
}

}  // namespace boticelli::firmware
