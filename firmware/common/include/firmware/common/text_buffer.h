// TextBuffer: a fixed-capacity text builder (printf-style appends, truncation reported, no heap).
#pragma once

#include <array>
#include <cstdarg>
#include <cstddef>
#include <string_view>

namespace boticelli::firmware {

class TextBufferBase {
 public:
  TextBufferBase(const TextBufferBase&) = delete;
  TextBufferBase& operator=(const TextBufferBase&) = delete;

  // Appends formatted text; on overflow keeps what fits, sets truncated() and returns false.
  bool appendf(const char* format, ...) __attribute__((format(printf, 2, 3)));
  bool vappendf(const char* format, std::va_list args) __attribute__((format(printf, 2, 0)));
  bool append(std::string_view text);
  void clear() {
    size_ = 0;
    data_[0] = '\0';
    truncated_ = false;
  }
  std::string_view view() const { return {data_, size_}; }
  const char* c_str() const { return data_; }
  std::size_t size() const { return size_; }
  bool truncated() const { return truncated_; }

 protected:
  TextBufferBase(char* data, std::size_t capacity) : data_(data), capacity_(capacity) {
    data_[0] = '\0';
  }
  ~TextBufferBase() = default;

 private:
  char* data_;
  std::size_t capacity_;  // including the terminating NUL
  std::size_t size_ = 0;
  bool truncated_ = false;
};

namespace detail {
// Listed before TextBufferBase so the storage exists when the base is built.
template <std::size_t N>
struct TextStorage {
  std::array<char, N> storage_{};
};
}  // namespace detail

template <std::size_t N>
class TextBuffer final : private detail::TextStorage<N>, public TextBufferBase {
  static_assert(N > 1);

 public:
  TextBuffer() : TextBufferBase(this->storage_.data(), N) {}
};

}  // namespace boticelli::firmware
