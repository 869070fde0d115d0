// Logging: level names, the log ring and the journald-aware stderr lines (see log.h).
#include "firmware/common/log.h"

#include <sys/stat.h>

#include <cinttypes>
#include <cstdarg>
#include <cstdio>
#include <cstdlib>

#include "firmware/common/text_buffer.h"

namespace boticelli::firmware {

const char* log_level_name(LogLevel level) {
  switch (level) {
    case LogLevel::kError:
      return "error";
    case LogLevel::kWarn:
      return "warn";
    case LogLevel::kInfo:
      return "info";
    case LogLevel::kDebug:
      return "debug";
  }
  return "?";
}

bool parse_log_level(std::string_view text, LogLevel& out) {
  for (const LogLevel l : {LogLevel::kError, LogLevel::kWarn, LogLevel::kInfo, LogLevel::kDebug}) {
    if (text == log_level_name(l)) {
      out = l;
      return true;
    }
  }
  return false;
}

int log_priority(LogLevel level) {
  switch (level) {
    case LogLevel::kError:
      return 3;  // LOG_ERR
    case LogLevel::kWarn:
      return 4;  // LOG_WARNING
    case LogLevel::kInfo:
      return 6;  // LOG_INFO
    case LogLevel::kDebug:
      return 7;  // LOG_DEBUG
  }
  return 6;
}

void LogRing::add(std::uint64_t t_us, LogLevel level, std::string_view text) {
  Entry& e = entries_[static_cast<std::size_t>(total_ % kLines)];
  e.t_us = t_us;
  e.level = level;
  const std::size_t n = text.size() < kTextBytes ? text.size() : kTextBytes;
  for (std::size_t i = 0; i < n; ++i) {
    const char c = text[i];
    e.text[i] = c >= 0x20 && c <= 0x7E ? c : '?';  // one printable line
  }
  e.size = static_cast<std::uint8_t>(n);
  ++total_;
}

const LogRing::Entry* LogRing::find(std::uint64_t sequence) const {
  if (sequence >= total_ || total_ - sequence > kLines) return nullptr;
  return &entries_[static_cast<std::size_t>(sequence % kLines)];
}

ServiceLog& service_log() {
  static ServiceLog log;
  return log;
}

void ServiceLog::open() {
  // sd_journal_stream_fd's contract (systemd.exec(5), $JOURNAL_STREAM): "DEV:INODE" of the
  // stream systemd connected; only when it is still our stderr do we speak to journald.
  journal_ = false;
  const char* stream = std::getenv("JOURNAL_STREAM");
  struct stat st {};
  if (stream == nullptr || ::fstat(2, &st) != 0) return;
  std::uintmax_t dev = 0;
  std::uintmax_t ino = 0;
  if (std::sscanf(stream, "%ju:%ju", &dev, &ino) != 2) return;
  journal_ = dev == static_cast<std::uintmax_t>(st.st_dev) &&
             ino == static_cast<std::uintmax_t>(st.st_ino);
}

void ServiceLog::log(LogLevel level, const char* format, ...) {
  TextBuffer<512> text;
  std::va_list args;
  va_start(args, format);
  text.vappendf(format, args);
  va_end(args);
  if (journal_) {
    std::fprintf(stderr, "<%d>%s\n", log_priority(level), text.c_str());
  } else {
    std::fprintf(stderr, "boticelli: %s\n", text.c_str());
  }
  std::fflush(stderr);
  if (ring_ != nullptr) ring_->add(clock_ != nullptr ? clock_->now_us() : 0U, level, text.view());
}

}  // namespace boticelli::firmware
