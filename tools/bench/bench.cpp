// Benchmark registry and JSON-lines output (see bench.h).
#include "bench.h"

#include <cmath>
#include <cstdarg>
#include <cstring>

namespace boticelli::bench {
namespace {
bool g_json = false;
}  // namespace

void set_json(bool on) {
  g_json = on;
}
bool json() {
  return g_json;
}

JsonLine::JsonLine(const char* suite, const char* name) {
  if (g_json) {
    append("{\"suite\":\"%s\",\"case\":\"%s\"", suite, name);
  } else {
    append("%-12s %-28s", suite, name);
  }
}

void JsonLine::append(const char* fmt, ...) {
  if (overflow_) {
    return;
  }
  va_list args;
  va_start(args, fmt);
  const int n = std::vsnprintf(buffer_ + used_, sizeof buffer_ - used_, fmt, args);
  va_end(args);
  if (n < 0 || static_cast<std::size_t>(n) >= sizeof buffer_ - used_) {
    overflow_ = true;
    return;
  }
  used_ += static_cast<std::size_t>(n);
}

JsonLine& JsonLine::num(const char* key, double value) {
  if (!std::isfinite(value)) {
    append(g_json ? ",\"%s\":null" : " %s=nan", key);
  } else {
    append(g_json ? ",\"%s\":%.6g" : " %s=%.6g", key, value);
  }
  return *this;
}
JsonLine& JsonLine::integer(const char* key, std::int64_t value) {
  append(g_json ? ",\"%s\":%lld" : " %s=%lld", key, static_cast<long long>(value));
  return *this;
}
JsonLine& JsonLine::text(const char* key, const char* value) {
  append(g_json ? ",\"%s\":\"%s\"" : " %s=%s", key, value);
  return *this;
}
JsonLine& JsonLine::flag(const char* key, bool value) {
  append(g_json ? ",\"%s\":%s" : " %s=%s", key, value ? "true" : "false");
  return *this;
}
void JsonLine::emit() {
  if (overflow_) {
    std::fprintf(stderr, "boticelli-bench: a result line was too long and was dropped\n");
    return;
  }
  std::printf("%s%s\n", buffer_, g_json ? "}" : "");
  std::fflush(stdout);
}

}  // namespace boticelli::bench
