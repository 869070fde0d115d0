// Console command-line parsing (see console_parser.h).
#include "firmware/console/console_parser.h"

#include <cerrno>
#include <cmath>
#include <cstdlib>
#include <cstring>

namespace boticelli::firmware {

bool split_words(std::string_view line, Words& out) {
  out.count = 0;
  std::size_t i = 0;
  while (i < line.size()) {
    while (i < line.size() && line[i] == ' ') ++i;
    if (i == line.size()) break;
    const std::size_t start = i;
    while (i < line.size() && line[i] != ' ') ++i;
    if (out.count == Words::kMaxWords) return false;
    out.word[out.count++] = line.substr(start, i - start);
  }
  return true;
}

bool parse_number(std::string_view text, float& out) {
  constexpr std::size_t kMaxChars = 32;
  if (text.empty() || text.size() > kMaxChars) return false;
  bool digit = false;
  for (const char c : text) {
    if (c >= '0' && c <= '9') {
      digit = true;
    } else if (c != '+' && c != '-' && c != '.' && c != 'e' && c != 'E') {
      return false;
    }
  }
  if (!digit) return false;
  char copy[kMaxChars + 1];
  std::memcpy(copy, text.data(), text.size());
  copy[text.size()] = '\0';
  errno = 0;
  char* end = nullptr;
  const float v = std::strtof(copy, &end);
  if (end != copy + text.size() || errno == ERANGE || !std::isfinite(v)) return false;
  out = v;
  return true;
}

}  // namespace boticelli::firmware
