// Console line assembly (see console_line.h).
#include "firmware/console/console_line.h"

namespace boticelli::firmware {

void LineAssembler::reset() {
  size_ = 0;
  overflow_ = false;
  bad_ = false;
  line_ready_ = false;
  escape_ = 0;
}

std::string_view LineAssembler::typed() const {
  if (line_ready_) return {};
  return {buffer_.data(), size_};
}

void LineAssembler::replace(std::string_view text) {
  size_ = text.size() < kMaxLineBytes ? text.size() : kMaxLineBytes;
  for (std::size_t i = 0; i < size_; ++i) buffer_[i] = text[i];
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
  if (escape_ != 0) {
    // ESC [ A / ESC O A (up), ... B (down); ESC [ 1 ; 5 C and the like end at a byte in
    // 0x40..0x7E. A sequence longer than a terminal sends spoils the line.
    if (escape_ == 1) {
      escape_ = byte == '[' || byte == 'O' ? 2 : 0;
      if (escape_ == 2) return LineEvent::kNone;
    } else if (byte >= 0x40 && byte <= 0x7E) {
      escape_ = 0;
      if (byte == 'A') return LineEvent::kOlder;
      if (byte == 'B') return LineEvent::kNewer;
      return LineEvent::kNone;
    } else if (byte >= 0x20 && byte <= 0x3F && escape_ < 10) {
      ++escape_;
      return LineEvent::kNone;
    } else {
      escape_ = 0;
      bad_ = true;
      return LineEvent::kNone;
    }
  }
  if (byte == 0x1B && recall_) {
    escape_ = 1;
    return LineEvent::kNone;
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

void CommandHistory::add(std::string_view line) {
  cursor_ = 0;
  if (line.empty() || (count_ > 0 && entry(1) == line)) return;
  const std::size_t n =
      line.size() < LineAssembler::kMaxLineBytes ? line.size() : LineAssembler::kMaxLineBytes;
  for (std::size_t i = 0; i < n; ++i) lines_[next_][i] = line[i];
  sizes_[next_] = n;
  next_ = (next_ + 1) % kEntries;
  if (count_ < kEntries) ++count_;
}

std::string_view CommandHistory::entry(std::size_t age) const {
  const std::size_t slot = (next_ + kEntries - age) % kEntries;
  return {lines_[slot].data(), sizes_[slot]};
}

bool CommandHistory::older(std::string_view& out) {
  if (cursor_ >= count_) return false;
  out = entry(++cursor_);
  return true;
}

bool CommandHistory::newer(std::string_view& out) {
  if (cursor_ == 0) return false;
  --cursor_;
  out = cursor_ == 0 ? std::string_view{} : entry(cursor_);
  return true;
}

}  // namespace boticelli::firmware
