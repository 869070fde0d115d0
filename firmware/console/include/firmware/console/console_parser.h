// Console command-line parsing: split a line into words and read numbers strictly (hostile input).
#pragma once

#include <array>
#include <cstddef>
#include <string_view>

namespace boticelli::firmware {

// Up to kMaxWords words separated by spaces; more words make split() fail.
struct Words {
  static constexpr std::size_t kMaxWords = 4;
  std::array<std::string_view, kMaxWords> word{};
  std::size_t count = 0;
};

// False when the line has more than Words::kMaxWords words.
bool split_words(std::string_view line, Words& out);

// A decimal number ("-1.5", "2e-3", "10"); no hex, inf, nan, spaces or trailing text.
bool parse_number(std::string_view text, float& out);

}  // namespace boticelli::firmware
