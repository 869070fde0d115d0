// Logging: levels, the ring of recent log lines the console shows, and stderr lines that
// journald files under their level.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <string_view>

#include "hal/clock.h"

namespace boticelli::firmware {

enum class LogLevel : std::uint8_t { kError, kWarn, kInfo, kDebug };
const char* log_level_name(LogLevel level);
bool parse_log_level(std::string_view text, LogLevel& out);
// The sd-daemon(3) priority of a level: error 3, warn 4, info 6, debug 7.
int log_priority(LogLevel level);

// The last kLines log lines, oldest first, each cut to kTextBytes; fixed storage, never
// allocates. Every line gets a sequence number (0, 1, 2, ... since construction), so a reader
// that walks the ring while lines are added can tell which ones were overwritten.
class LogRing {
 public:
  static constexpr std::size_t kLines = 64;
  static constexpr std::size_t kTextBytes = 120;

  struct Entry {
    std::uint64_t t_us = 0;  // board clock when logged [us]
    LogLevel level = LogLevel::kInfo;
    std::uint8_t size = 0;
    std::array<char, kTextBytes> text{};
    std::string_view view() const { return {text.data(), size}; }
  };

  void add(std::uint64_t t_us, LogLevel level, std::string_view text);
  void clear() { total_ = 0; }
  std::size_t size() const { return total_ < kLines ? static_cast<std::size_t>(total_) : kLines; }
  // Sequence number of the next line to be added; the oldest kept is end_sequence() - size().
  std::uint64_t end_sequence() const { return total_; }
  // The line with that sequence number, or nullptr when it is not (or no longer) kept.
  const Entry* find(std::uint64_t sequence) const;

 private:
  std::array<Entry, kLines> entries_{};
  std::uint64_t total_ = 0;
};

// Start-up and shutdown messages on stderr. When stderr is the journal (systemd sets
// $JOURNAL_STREAM to the device:inode of the stream it connected), each line is
// "<N>text" with N the sd-daemon priority, and journald adds the "boticelli:" identifier
// itself; anywhere else (a terminal, a pipe, a test) "boticelli: text" as before. Every
// line also goes to the ring, when one is attached. Not for the cyclic path (stderr writes
// can block).
class ServiceLog {
 public:
  // Reads $JOURNAL_STREAM and compares it with stderr (fstat); call again after a redirect.
  void open();
  void attach(LogRing* ring, hal::Clock* clock) {
    ring_ = ring;
    clock_ = clock;
  }
  bool to_journal() const { return journal_; }
  void log(LogLevel level, const char* format, ...) __attribute__((format(printf, 3, 4)));

 private:
  bool journal_ = false;
  LogRing* ring_ = nullptr;
  hal::Clock* clock_ = nullptr;
};

// The process's one stderr log (stderr is one per process); firmware_main opens it.
ServiceLog& service_log();

}  // namespace boticelli::firmware
