// Persistence: state file encoding, strict decoding, atomic save and load (see persistence.h).
#include "firmware/state/persistence.h"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <array>
#include <cstdarg>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>

namespace boticelli::firmware {
namespace {

constexpr std::array<std::uint32_t, 256> make_crc_table() {
  std::array<std::uint32_t, 256> table{};
  for (std::uint32_t n = 0; n < 256; ++n) {
    std::uint32_t c = n;
    for (int k = 0; k < 8; ++k) c = (c & 1U) != 0 ? 0xEDB88320U ^ (c >> 1) : c >> 1;
    table[n] = c;
  }
  return table;
}
constexpr std::array<std::uint32_t, 256> kCrcTable = make_crc_table();

// Appends to a fixed output buffer; remembers overflow.
struct Writer {
  char* out;
  std::size_t capacity;
  std::size_t size = 0;
  bool overflow = false;

  void printf(const char* format, ...) __attribute__((format(printf, 2, 3))) {
    if (overflow) return;
    std::va_list args;
    va_start(args, format);
    const int n = std::vsnprintf(out + size, capacity - size, format, args);
    va_end(args);
    if (n < 0 || static_cast<std::size_t>(n) >= capacity - size) {
      overflow = true;
      return;
    }
    size += static_cast<std::size_t>(n);
  }
  void bytes(std::string_view b) {
    if (overflow || b.size() >= capacity - size) {
      overflow = true;
      return;
    }
    std::memcpy(out + size, b.data(), b.size());
    size += b.size();
  }
};

void write_points(Writer& w, const char* name, const core::FixedVectorBase<core::Point2>& points) {
  w.printf("%s %zu\n", name, points.size());
  for (const core::Point2& p : points) {
    w.printf("%.9g %.9g\n", static_cast<double>(p.x_m), static_cast<double>(p.y_m));
  }
}

// Reads the file line by line with strict checks; the first problem is kept in `error`.
struct Reader {
  std::string_view rest;
  const char* error = nullptr;

  bool fail(const char* why) {
    if (error == nullptr) error = why;
    return false;
  }
  // The next line without its '\n'; a missing '\n' is a truncated file.
  bool line(std::string_view& out) {
    const std::size_t nl = rest.find('\n');
    if (nl == std::string_view::npos) return fail("truncated file");
    out = rest.substr(0, nl);
    rest.remove_prefix(nl + 1);
    return true;
  }
  // "<key>" followed by the rest of the line (after one space), or just "<key>".
  bool keyed(std::string_view key, std::string_view& value) {
    std::string_view l;
    if (!line(l)) return false;
    if (l.substr(0, key.size()) != key) return fail("unexpected line");
    l.remove_prefix(key.size());
    if (!l.empty()) {
      if (l[0] != ' ') return fail("unexpected line");
      l.remove_prefix(1);
    }
    value = l;
    return true;
  }
};

// Splits off the first space-separated word of `text`.
std::string_view next_word(std::string_view& text) {
  const std::size_t sp = text.find(' ');
  const std::string_view word = text.substr(0, sp);
  text.remove_prefix(sp == std::string_view::npos ? text.size() : sp + 1);
  return word;
}

bool parse_u64(std::string_view text, std::uint64_t& out) {
  if (text.empty() || text.size() > 20) return false;
  std::uint64_t v = 0;
  for (const char c : text) {
    if (c < '0' || c > '9') return false;
    const auto d = static_cast<std::uint64_t>(c - '0');
    if (v > (UINT64_MAX - d) / 10U) return false;
    v = v * 10U + d;
  }
  out = v;
  return true;
}

bool parse_float(std::string_view text, float& out) {
  constexpr std::size_t kMax = 40;
  if (text.empty() || text.size() > kMax) return false;
  for (const char c : text) {
    if (!((c >= '0' && c <= '9') || c == '-' || c == '+' || c == '.' || c == 'e' || c == 'E')) {
      return false;
    }
  }
  char copy[kMax + 1];
  std::memcpy(copy, text.data(), text.size());
  copy[text.size()] = '\0';
  char* end = nullptr;
  const float v = std::strtof(copy, &end);
  // Overflow gives ±inf (refused). Underflow (ERANGE with a subnormal result) is accepted:
  // the writer prints every float, subnormals included, so that it reads back exactly.
  if (end != copy + text.size() || !std::isfinite(v)) return false;
  out = v;
  return true;
}

// Exactly `n` floats separated by single spaces, nothing else.
bool parse_floats(std::string_view text, float* out, std::size_t n) {
  for (std::size_t i = 0; i < n; ++i) {
    if (!parse_float(next_word(text), out[i])) return false;
  }
  return text.empty();
}

bool read_points(Reader& r, const char* name, std::size_t capacity,
                 core::FixedVectorBase<core::Point2>& out) {
  std::string_view v;
  std::uint64_t n = 0;
  if (!r.keyed(name, v)) return false;
  if (!parse_u64(v, n)) return r.fail("bad point count");
  if (n > capacity) return r.fail("more points than the capacity");
  for (std::uint64_t i = 0; i < n; ++i) {
    std::string_view l;
    float xy[2];
    if (!r.line(l)) return false;
    if (!parse_floats(l, xy, 2)) return r.fail("bad point");
    (void)out.push_back({xy[0], xy[1]});
  }
  return true;
}

bool decode_body(Reader& r, MissionState& s) {
  std::string_view v;
  std::string_view l;
  if (!r.line(l)) return false;
  if (l.substr(0, 16) != "BOTICELLI-STATE ") return r.fail("not a state file");
  // Version 1 (a goal without its height) is still read: its goal stands on the floor.
  std::uint64_t version = 0;
  if (!parse_u64(l.substr(16), version) || version < 1 || version > kStateFormatVersion) {
    return r.fail("unsupported state file version");
  }
  if (!r.keyed("cycle", v) || !parse_u64(v, s.cycle)) return r.fail("bad cycle");
  if (!r.keyed("seed", v) || !parse_u64(v, s.seed)) return r.fail("bad seed");
  float pose[3];
  if (!r.keyed("pose", v) || !parse_floats(v, pose, 3)) return r.fail("bad pose");
  s.pose = {pose[0], pose[1], pose[2]};
  if (!r.keyed("goal", v)) return false;
  if (v == "none") {
    s.has_goal = false;
  } else {
    float goal[3] = {0.0F, 0.0F, 0.0F};
    if (!parse_floats(v, goal, version == 1 ? 2 : 3)) return r.fail("bad goal");
    s.has_goal = true;
    s.goal = {goal[0], goal[1]};
    s.goal_height_m = goal[2];
  }
  if (!read_points(r, "obstacles", MissionState::kMaxObstaclePoints, s.obstacles)) return false;
  if (!read_points(r, "exploration", MissionState::kMaxExplorationPoints, s.exploration)) {
    return false;
  }
  std::uint64_t model_bytes = 0;
  if (!r.keyed("model", v) || !parse_u64(v, model_bytes)) return r.fail("bad model size");
  if (model_bytes > MissionState::kMaxModelBytes) return r.fail("model larger than the capacity");
  // Bounded by the capacity above, so it fits a size_t on 32-bit boards too.
  const auto model_size = static_cast<std::size_t>(model_bytes);
  if (r.rest.size() < model_size + 1) return r.fail("truncated file");
  if (r.rest[model_size] != '\n') return r.fail("model size does not match");
  if (!s.set_model(r.rest.substr(0, model_size))) return r.fail("bad model text");
  r.rest.remove_prefix(model_size + 1);
  std::uint64_t entries = 0;
  if (!r.keyed("log", v) || !parse_u64(v, entries)) return r.fail("bad log size");
  if (entries > MissionState::kMaxLogEntries) return r.fail("more log lines than the capacity");
  for (std::uint64_t i = 0; i < entries; ++i) {
    if (!r.line(l)) return false;
    std::uint64_t at = 0;
    if (!parse_u64(next_word(l), at)) return r.fail("bad log line");
    if (l.size() > MissionLogEntry::kMaxTextBytes) return r.fail("log line too long");
    for (const char c : l) {
      if (c < 0x20 || c > 0x7E) return r.fail("bad log line");
    }
    s.add_log(at, l);
  }
  if (!r.line(l) || l != "end") return r.fail("missing end");
  return true;
}

}  // namespace

std::uint32_t crc32(const void* data, std::size_t size, std::uint32_t crc) {
  const auto* p = static_cast<const unsigned char*>(data);
  crc = ~crc;
  for (std::size_t i = 0; i < size; ++i) crc = kCrcTable[(crc ^ p[i]) & 0xFFU] ^ (crc >> 8);
  return ~crc;
}

std::size_t encode_state(const MissionState& s, char* out, std::size_t capacity) {
  Writer w{out, capacity};
  w.printf("BOTICELLI-STATE %u\n", kStateFormatVersion);
  w.printf("cycle %llu\nseed %llu\n", static_cast<unsigned long long>(s.cycle),
           static_cast<unsigned long long>(s.seed));
  w.printf("pose %.9g %.9g %.9g\n", static_cast<double>(s.pose.x_m),
           static_cast<double>(s.pose.y_m), static_cast<double>(s.pose.yaw_rad));
  if (s.has_goal) {
    w.printf("goal %.9g %.9g %.9g\n", static_cast<double>(s.goal.x_m),
             static_cast<double>(s.goal.y_m), static_cast<double>(s.goal_height_m));
  } else {
    w.printf("goal none\n");
  }
  write_points(w, "obstacles", s.obstacles);
  write_points(w, "exploration", s.exploration);
  w.printf("model %zu\n", s.model_bytes);
  w.bytes(s.model_text());
  w.bytes("\n");
  w.printf("log %zu\n", s.log.size());
  for (const MissionLogEntry& e : s.log) {
    w.printf("%llu %s\n", static_cast<unsigned long long>(e.cycle), e.text.data());
  }
  w.printf("end\n");
  if (w.overflow) return 0;
  const std::uint32_t crc = crc32(out, w.size);
  w.printf("crc32 %08x\n", crc);
  return w.overflow ? 0 : w.size;
}

bool decode_state(std::string_view file, MissionState& out, const char** error) {
  out.clear();
  // The checksum line is the file's last line; check it before reading anything else.
  constexpr std::size_t kCrcLine = 15;  // "crc32 XXXXXXXX\n"
  if (file.size() < kCrcLine || file.back() != '\n') {
    *error = "truncated file";
    return false;
  }
  const std::string_view crc_line = file.substr(file.size() - kCrcLine);
  if (crc_line.substr(0, 6) != "crc32 ") {
    *error = "missing checksum (truncated file?)";
    return false;
  }
  std::uint32_t stored = 0;
  for (const char c : crc_line.substr(6, 8)) {
    std::uint32_t d = 0;
    if (c >= '0' && c <= '9') {
      d = static_cast<std::uint32_t>(c - '0');
    } else if (c >= 'a' && c <= 'f') {
      d = static_cast<std::uint32_t>(c - 'a' + 10);
    } else {
      *error = "bad checksum line";
      return false;
    }
    stored = (stored << 4) | d;
  }
  const std::string_view body = file.substr(0, file.size() - kCrcLine);
  if (crc32(body.data(), body.size()) != stored) {
    *error = "checksum mismatch (corrupt file)";
    return false;
  }
  Reader r{body};
  if (!decode_body(r, out) || !r.rest.empty()) {
    *error = r.error != nullptr ? r.error : "trailing data";
    out.clear();
    return false;
  }
  return true;
}

namespace {
void set_error(char* error, std::size_t size, const char* what, const char* path) {
  std::snprintf(error, size, "%s %s: %s", what, path, std::strerror(errno));
}
}  // namespace

bool state_dir_mode_is_safe(unsigned mode) {
  return (mode & (S_IWGRP | S_IWOTH)) == 0;
}

bool StateStore::open(const char* dir, char* error, std::size_t error_size) {
  refused_ = false;
  const int n1 = std::snprintf(dir_.data(), dir_.size(), "%s", dir);
  const int n2 = std::snprintf(path_.data(), path_.size(), "%s/%s", dir, kFileName);
  const int n3 = std::snprintf(parameters_path_.data(), parameters_path_.size(), "%s/%s", dir,
                               kParametersFileName);
  // The longest name, with write_file_atomically()'s ".tmp", must fit its 512-byte paths.
  if (n1 < 0 || n2 < 0 || n3 < 0 || static_cast<std::size_t>(n3) + 4 >= parameters_path_.size()) {
    dir_[0] = '\0';
    std::snprintf(error, error_size, "state directory path too long");
    return false;
  }
  if (::mkdir(dir, 0750) != 0 && errno != EEXIST) {
    set_error(error, error_size, "cannot create state directory", dir);
    dir_[0] = '\0';
    return false;
  }
  struct stat st {};
  if (::stat(dir, &st) != 0 || !S_ISDIR(st.st_mode)) {
    std::snprintf(error, error_size, "state path %s is not a directory", dir);
    dir_[0] = '\0';
    refused_ = true;
    return false;
  }
  // Anyone else who can write in the directory can put a file or a symlink where the state
  // goes, or swap the saved mission: refuse it (the operator fixes the directory).
  const uid_t user = ::geteuid();
  if (st.st_uid != user) {
    std::snprintf(error, error_size,
                  "state directory %s refused: owned by uid %u, not by this user (uid %u)", dir,
                  static_cast<unsigned>(st.st_uid), static_cast<unsigned>(user));
    dir_[0] = '\0';
    refused_ = true;
    return false;
  }
  if (!state_dir_mode_is_safe(static_cast<unsigned>(st.st_mode))) {
    std::snprintf(error, error_size,
                  "state directory %s refused: writable by %s (mode %04o; chmod go-w %s)", dir,
                  (st.st_mode & S_IWGRP) != 0 && (st.st_mode & S_IWOTH) != 0 ? "group and others"
                  : (st.st_mode & S_IWGRP) != 0                              ? "its group"
                                                                             : "others",
                  static_cast<unsigned>(st.st_mode & 07777), dir);
    dir_[0] = '\0';
    refused_ = true;
    return false;
  }
  return true;
}

LoadResult StateStore::keep_previous(char* kept, std::size_t kept_size, char* error,
                                     std::size_t error_size) {
  struct stat st {};
  if (::stat(path_.data(), &st) != 0) {
    if (errno == ENOENT) return LoadResult::kMissing;
    set_error(error, error_size, "cannot stat", path_.data());
    return LoadResult::kIoError;
  }
  // Oldest first: .2 -> .3, .1 -> .2, then the file itself -> .1 (a missing copy is skipped).
  std::array<char, 520> from{};
  std::array<char, 520> to{};
  for (int i = kKeptStates - 1; i >= 0; --i) {
    if (i == 0) {
      std::snprintf(from.data(), from.size(), "%s", path_.data());
    } else {
      std::snprintf(from.data(), from.size(), "%s.%d", path_.data(), i);
    }
    std::snprintf(to.data(), to.size(), "%s.%d", path_.data(), i + 1);
    if (::rename(from.data(), to.data()) != 0 && !(errno == ENOENT && i > 0)) {
      set_error(error, error_size, "cannot keep", from.data());
      return LoadResult::kIoError;
    }
  }
  const int dfd = ::open(dir_.data(), O_RDONLY | O_DIRECTORY | O_CLOEXEC);
  if (dfd < 0 || ::fsync(dfd) != 0) {
    set_error(error, error_size, "cannot sync", dir_.data());
    if (dfd >= 0) ::close(dfd);
    return LoadResult::kIoError;
  }
  ::close(dfd);
  std::snprintf(kept, kept_size, "%s", to.data());
  return LoadResult::kLoaded;
}

bool StateStore::save(const MissionState& state, char* error, std::size_t error_size) {
  const std::size_t size = encode_state(state, buffer_.data(), buffer_.size());
  if (size == 0) {
    std::snprintf(error, error_size, "state does not fit the file buffer");
    return false;
  }
  if (!write_file_atomically(dir_.data(), kFileName, {buffer_.data(), size}, error, error_size,
                             crash_hook_, crash_context_)) {
    return false;
  }
  ++saves_;
  return true;
}

bool StateStore::save_parameters(std::string_view text, char* error, std::size_t error_size) {
  if (!is_open()) {
    std::snprintf(error, error_size, "no state directory");
    return false;
  }
  return write_file_atomically(dir_.data(), kParametersFileName, text, error, error_size,
                               crash_hook_, crash_context_);
}

LoadResult StateStore::load(MissionState& out, char* error, std::size_t error_size) {
  out.clear();
  const int fd = ::open(path_.data(), O_RDONLY | O_CLOEXEC);
  if (fd < 0) {
    if (errno == ENOENT) {
      std::snprintf(error, error_size, "no saved state in %s", dir_.data());
      return LoadResult::kMissing;
    }
    set_error(error, error_size, "cannot open", path_.data());
    return LoadResult::kIoError;
  }
  std::size_t size = 0;
  bool too_big = false;
  for (;;) {
    if (size == buffer_.size()) {
      char extra = 0;
      const ssize_t n = ::read(fd, &extra, 1);
      too_big = n > 0;
      break;
    }
    const ssize_t n = ::read(fd, buffer_.data() + size, buffer_.size() - size);
    if (n < 0) {
      if (errno == EINTR) continue;
      set_error(error, error_size, "cannot read", path_.data());
      ::close(fd);
      return LoadResult::kIoError;
    }
    if (n == 0) break;
    size += static_cast<std::size_t>(n);
  }
  ::close(fd);
  if (too_big) {
    std::snprintf(error, error_size, "%s: file larger than any valid state", path_.data());
    return LoadResult::kCorrupt;
  }
  const char* why = "";
  if (!decode_state({buffer_.data(), size}, out, &why)) {
    std::snprintf(error, error_size, "%s: %s", path_.data(), why);
    return LoadResult::kCorrupt;
  }
  return LoadResult::kLoaded;
}

}  // namespace boticelli::firmware
