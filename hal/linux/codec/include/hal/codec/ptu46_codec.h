// PTU-D46 ASCII protocol codec: command text and reply parsing, pure (no I/O, no OS headers).
#pragma once

#include <cstddef>
#include <cstdint>
#include <string_view>

namespace boticelli::codec::ptu46 {

// Facts (docs/protocols.md): commands are ASCII letters, an optional signed integer and a
// delimiter (space); in terse mode (FT) the unit answers each with one line "* [value]" or
// "! <message>" ended by CR LF. Positions are in counts; the resolution query (PR/TR)
// answers in arc-seconds per count. Unsolicited "!P" / "!T" report a pan / tilt limit hit;
// a reset (R) answers "!T!T!P!P*" as the axes run to their limits and back.

enum class Axis : std::uint8_t { kPan, kTilt };

enum class Query : std::uint8_t {
  kPosition,     // PP / TP
  kResolution,   // PR / TR  [arc-seconds per count]
  kMinPosition,  // PN / TN  [counts]
  kMaxPosition,  // PX / TX  [counts]
  kSpeed,        // PS / TS  [counts/s]
  kMaxSpeed,     // PU / TU  [counts/s]
};

enum class Setting : std::uint8_t {
  kTerse,            // FT
  kEchoOff,          // ED
  kIndependentMode,  // CI: independent (position) speed control mode
  kAwait,            // A: answers when the last position command has completed
  kHalt,             // H: stop both axes
  kReset,            // R: reset (home) both axes
};

// Longest command the encoders produce ("PP-2147483648 " is 14 characters).
inline constexpr std::size_t kMaxCommandLength = 16;
// Longest reply line accepted; longer lines are garbage (counted, discarded).
inline constexpr std::size_t kMaxLineLength = 80;

// Encoders: write the command into `out` and return its length, or 0 when `capacity` is
// too small. No terminating NUL is written.
std::size_t encode_query(Axis axis, Query query, char* out, std::size_t capacity);
std::size_t encode_setting(Setting setting, char* out, std::size_t capacity);
std::size_t encode_position(Axis axis, std::int32_t counts, char* out, std::size_t capacity);
std::size_t encode_speed(Axis axis, std::int32_t counts_s, char* out, std::size_t capacity);

enum class ReplyKind : std::uint8_t {
  kOk,         // "*" with or without a value
  kError,      // "!" with a message answering the current command
  kLimitPan,   // "!P": pan axis hit a limit (may arrive unsolicited)
  kLimitTilt,  // "!T": tilt axis hit a limit (may arrive unsolicited)
  kGarbage,    // nothing recognisable: neither '*' nor '!' in the line
};

enum class ErrorKind : std::uint8_t {
  kNone,
  kIllegalCommand,   // "! Illegal Command" / unknown command
  kIllegalArgument,  // "! Illegal ... Argument" / out of range
  kLimit,            // "! Maximum/Minimum allowable ... limit" messages
  kOther,
};

struct Reply {
  ReplyKind kind = ReplyKind::kGarbage;
  ErrorKind error = ErrorKind::kNone;
  bool has_value = false;
  double value = 0.0;       // the number after '*', when has_value
  std::size_t skipped = 0;  // bytes before the '*' or '!' (echo or line noise)
  std::string_view text;    // the reply from its marker on (points into the line)
};

// Parses one line (without CR/LF). Bytes before the first '*' or '!' are skipped (echo, line
// noise) and counted in `skipped`. A '*' followed by something that is not a number is an
// OK without value. Never reads outside `line`.
Reply parse_reply(std::string_view line);

// Parses a decimal number ("-1234", "+12", "185.1428"); false on anything else, including
// an empty string, a lone sign, more than 15 significant digits or trailing junk.
bool parse_number(std::string_view text, double& value);

// Splits the byte stream from the unit into lines. CR and LF end a line (CR LF gives one
// line); empty lines are dropped. A line that would exceed kMaxLineLength is discarded up
// to its end and counted as an overflow. Non-printable bytes mark the line as corrupt (it
// is still returned, flagged, so the caller can count it). A line "!P" or "!T" directly
// followed by '!' or '*' (the reset answer) is returned as its own line.
class LineAssembler {
 public:
  // Feeds one byte; returns true when a complete line is available in line().
  bool push(char c);
  std::string_view line() const { return {ready_, ready_length_}; }
  bool line_corrupt() const { return ready_corrupt_; }
  std::uint32_t overflows() const { return overflows_; }
  void reset();

 private:
  bool finish();
  char buffer_[kMaxLineLength] = {};
  char ready_[kMaxLineLength] = {};
  std::size_t length_ = 0;
  std::size_t ready_length_ = 0;
  bool corrupt_ = false;
  bool ready_corrupt_ = false;
  bool discarding_ = false;
  std::uint32_t overflows_ = 0;
};

// Conversions with the queried resolution [arc-seconds per count].
double counts_to_rad(double counts, double arcsec_per_count);
// Nearest count; false when the result does not fit an int32 or the resolution is not > 0.
bool rad_to_counts(double rad, double arcsec_per_count, std::int32_t& counts);

}  // namespace boticelli::codec::ptu46
