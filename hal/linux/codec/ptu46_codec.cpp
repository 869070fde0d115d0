// PTU-D46 ASCII protocol codec (pure).
#include "hal/codec/ptu46_codec.h"

#include <cmath>
#include <cstring>
#include <numbers>

namespace boticelli::codec::ptu46 {

namespace {

char axis_letter(Axis axis) {
  return axis == Axis::kPan ? 'P' : 'T';
}

// Writes prefix, optional signed number and the space delimiter.
std::size_t write_command(const char* prefix, bool with_number, std::int64_t number, char* out,
                          std::size_t capacity) {
  char digits[24];
  std::size_t nd = 0;
  bool negative = false;
  if (with_number) {
    negative = number < 0;
    std::uint64_t magnitude = negative ? static_cast<std::uint64_t>(-(number + 1)) + 1U
                                       : static_cast<std::uint64_t>(number);
    do {
      digits[nd++] = static_cast<char>('0' + static_cast<int>(magnitude % 10U));
      magnitude /= 10U;
    } while (magnitude != 0U);
  }
  const std::size_t prefix_length = std::strlen(prefix);
  const std::size_t length = prefix_length + (negative ? 1U : 0U) + nd + 1U;
  if (length > capacity) return 0;
  std::size_t pos = 0;
  for (std::size_t i = 0; i < prefix_length; ++i) out[pos++] = prefix[i];
  if (negative) out[pos++] = '-';
  while (nd > 0) out[pos++] = digits[--nd];
  out[pos++] = ' ';
  return pos;
}

bool contains(std::string_view haystack, std::string_view needle) {
  // Case-insensitive search (the unit's messages vary in case between firmware versions).
  if (needle.size() > haystack.size()) return false;
  for (std::size_t i = 0; i + needle.size() <= haystack.size(); ++i) {
    bool match = true;
    for (std::size_t j = 0; j < needle.size(); ++j) {
      char a = haystack[i + j];
      char b = needle[j];
      if (a >= 'A' && a <= 'Z') a = static_cast<char>(a - 'A' + 'a');
      if (b >= 'A' && b <= 'Z') b = static_cast<char>(b - 'A' + 'a');
      if (a != b) {
        match = false;
        break;
      }
    }
    if (match) return true;
  }
  return false;
}

std::string_view trim(std::string_view s) {
  while (!s.empty() && (s.front() == ' ' || s.front() == '\t')) s.remove_prefix(1);
  while (!s.empty() && (s.back() == ' ' || s.back() == '\t')) s.remove_suffix(1);
  return s;
}

}  // namespace

std::size_t encode_query(Axis axis, Query query, char* out, std::size_t capacity) {
  char prefix[3] = {axis_letter(axis), '?', '\0'};
  switch (query) {
    case Query::kPosition:
      prefix[1] = 'P';
      break;
    case Query::kResolution:
      prefix[1] = 'R';
      break;
    case Query::kMinPosition:
      prefix[1] = 'N';
      break;
    case Query::kMaxPosition:
      prefix[1] = 'X';
      break;
    case Query::kSpeed:
      prefix[1] = 'S';
      break;
    case Query::kMaxSpeed:
      prefix[1] = 'U';
      break;
  }
  return write_command(prefix, false, 0, out, capacity);
}

std::size_t encode_setting(Setting setting, char* out, std::size_t capacity) {
  const char* text = "";
  switch (setting) {
    case Setting::kTerse:
      text = "FT";
      break;
    case Setting::kEchoOff:
      text = "ED";
      break;
    case Setting::kIndependentMode:
      text = "CI";
      break;
    case Setting::kAwait:
      text = "A";
      break;
    case Setting::kHalt:
      text = "H";
      break;
    case Setting::kReset:
      text = "R";
      break;
  }
  return write_command(text, false, 0, out, capacity);
}

std::size_t encode_position(Axis axis, std::int32_t counts, char* out, std::size_t capacity) {
  const char prefix[3] = {axis_letter(axis), 'P', '\0'};
  return write_command(prefix, true, counts, out, capacity);
}

std::size_t encode_speed(Axis axis, std::int32_t counts_s, char* out, std::size_t capacity) {
  const char prefix[3] = {axis_letter(axis), 'S', '\0'};
  return write_command(prefix, true, counts_s, out, capacity);
}

bool parse_number(std::string_view text, double& value) {
  std::size_t i = 0;
  bool negative = false;
  if (i < text.size() && (text[i] == '-' || text[i] == '+')) {
    negative = text[i] == '-';
    ++i;
  }
  double result = 0.0;
  std::size_t digits = 0;
  while (i < text.size() && text[i] >= '0' && text[i] <= '9') {
    result = result * 10.0 + static_cast<double>(text[i] - '0');
    ++digits;
    ++i;
  }
  if (i < text.size() && text[i] == '.') {
    ++i;
    double scale = 0.1;
    while (i < text.size() && text[i] >= '0' && text[i] <= '9') {
      result += scale * static_cast<double>(text[i] - '0');
      scale *= 0.1;
      ++digits;
      ++i;
    }
  }
  if (digits == 0 || digits > 15 || i != text.size()) return false;
  value = negative ? -result : result;
  return true;
}

Reply parse_reply(std::string_view line) {
  Reply r;
  std::size_t start = 0;
  while (start < line.size() && line[start] != '*' && line[start] != '!') ++start;
  r.skipped = start;
  if (start == line.size()) {
    r.kind = ReplyKind::kGarbage;
    r.text = line;
    return r;
  }
  r.text = line.substr(start);
  const std::string_view rest = trim(line.substr(start + 1));
  if (line[start] == '*') {
    r.kind = ReplyKind::kOk;
    double v = 0.0;
    if (!rest.empty() && parse_number(rest, v)) {
      r.has_value = true;
      r.value = v;
    }
    return r;
  }
  // '!' replies.
  if (rest == "P") {
    r.kind = ReplyKind::kLimitPan;
    r.error = ErrorKind::kLimit;
    return r;
  }
  if (rest == "T") {
    r.kind = ReplyKind::kLimitTilt;
    r.error = ErrorKind::kLimit;
    return r;
  }
  r.kind = ReplyKind::kError;
  if (contains(rest, "argument") || contains(rest, "out of range")) {
    r.error = ErrorKind::kIllegalArgument;
  } else if (contains(rest, "limit") || contains(rest, "allowable")) {
    r.error = ErrorKind::kLimit;
  } else if (contains(rest, "illegal") || contains(rest, "unknown") ||
             contains(rest, "unrecognized")) {
    r.error = ErrorKind::kIllegalCommand;
  } else {
    r.error = ErrorKind::kOther;
  }
  return r;
}

void LineAssembler::reset() {
  length_ = 0;
  ready_length_ = 0;
  corrupt_ = false;
  ready_corrupt_ = false;
  discarding_ = false;
}

bool LineAssembler::finish() {
  const bool have = length_ > 0 && !discarding_;
  if (have) {
    std::memcpy(ready_, buffer_, length_);
    ready_length_ = length_;
    ready_corrupt_ = corrupt_;
  }
  length_ = 0;
  corrupt_ = false;
  discarding_ = false;
  return have;
}

bool LineAssembler::push(char c) {
  if (c == '\r' || c == '\n') return finish();
  // "!P" / "!T" followed at once by the next reply (the reset answer "!T!T!P!P*").
  bool emitted = false;
  if ((c == '!' || c == '*') && length_ == 2 && buffer_[0] == '!' &&
      (buffer_[1] == 'P' || buffer_[1] == 'T') && !discarding_) {
    emitted = finish();
  }
  if (discarding_) return emitted;
  if (length_ == kMaxLineLength) {
    discarding_ = true;
    length_ = 0;
    ++overflows_;
    return emitted;
  }
  const auto u = static_cast<unsigned char>(c);
  if (u < 0x20 || u > 0x7E) corrupt_ = true;
  buffer_[length_++] = c;
  return emitted;
}

double counts_to_rad(double counts, double arcsec_per_count) {
  return counts * arcsec_per_count / 3600.0 * std::numbers::pi / 180.0;
}

bool rad_to_counts(double rad, double arcsec_per_count, std::int32_t& counts) {
  if (!(arcsec_per_count > 0.0) || !std::isfinite(rad)) return false;
  const double c = std::round(rad * 180.0 / std::numbers::pi * 3600.0 / arcsec_per_count);
  if (c < -2147483648.0 || c > 2147483647.0) return false;
  counts = static_cast<std::int32_t>(c);
  return true;
}

}  // namespace boticelli::codec::ptu46
