// TextBuffer appends (see text_buffer.h).
#include "firmware/common/text_buffer.h"

#include <cstdio>
#include <cstring>

namespace boticelli::firmware {

bool TextBufferBase::appendf(const char* format, ...) {
  std::va_list args;
  va_start(args, format);
  const bool ok = vappendf(format, args);
  va_end(args);
  return ok;
}

bool TextBufferBase::vappendf(const char* format, std::va_list args) {
  const std::size_t room = capacity_ - size_;
  const int n = std::vsnprintf(data_ + size_, room, format, args);
  if (n < 0) {
    data_[size_] = '\0';
    truncated_ = true;
    return false;
  }
  if (static_cast<std::size_t>(n) >= room) {
    size_ = capacity_ - 1;
    truncated_ = true;
    return false;
  }
  size_ += static_cast<std::size_t>(n);
  return true;
}

bool TextBufferBase::append(std::string_view text) {
  const std::size_t room = capacity_ - 1 - size_;
  const std::size_t n = text.size() < room ? text.size() : room;
  std::memcpy(data_ + size_, text.data(), n);
  size_ += n;
  data_[size_] = '\0';
  if (n < text.size()) {
    truncated_ = true;
    return false;
  }
  return true;
}

}  // namespace boticelli::firmware
