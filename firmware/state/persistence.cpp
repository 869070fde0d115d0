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
#include <type_traits>

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

// A float (or, for the wheel counters, a double written by "%.17g"): the whole text, plain
// decimal or exponent notation, finite. Overflow gives ±inf (refused). Underflow (ERANGE with
// a subnormal result) is accepted: the writer prints every value, subnormals included, so that
// it reads back exactly.
template <typename Real>
bool parse_real(std::string_view text, Real& out) {
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
  Real v{};
  if constexpr (std::is_same_v<Real, float>) {
    v = std::strtof(copy, &end);
  } else {
    v = std::strtod(copy, &end);
  }
  if (end != copy + text.size() || !std::isfinite(v)) return false;
  out = v;
  return true;
}

bool parse_float(std::string_view text, float& out) {
  return parse_real(text, out);
}

bool parse_double(std::string_view text, double& out) {
  return parse_real(text, out);
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

int hex_digit(char c) {
  if (c >= '0' && c <= '9') return c - '0';
  if (c >= 'a' && c <= 'f') return c - 'a' + 10;
  return -1;
}

// "grid CELL_M N" and N tiles "TX TY HEX" (version 5).
bool read_grid(Reader& r, MissionState& s) {
  std::string_view v;
  if (!r.keyed("grid", v)) return r.fail("bad grid");
  float cell_m = 0.0F;
  std::uint64_t n = 0;
  if (!parse_float(next_word(v), cell_m) || !(cell_m >= 0.0F) || !parse_u64(next_word(v), n) ||
      !v.empty()) {
    return r.fail("bad grid");
  }
  if (n > worldmap::kMaxTiles) return r.fail("more grid tiles than the capacity");
  s.grid_cell_m = cell_m;
  s.grid.clear();
  constexpr std::size_t kCells = worldmap::kTileCells * worldmap::kTileCells;
  for (std::uint64_t i = 0; i < n; ++i) {
    std::string_view l;
    if (!r.line(l)) return false;
    std::uint64_t tx = 0;
    std::uint64_t ty = 0;
    if (!parse_u64(next_word(l), tx) || !parse_u64(next_word(l), ty) ||
        tx >= worldmap::kDirectoryTiles || ty >= worldmap::kDirectoryTiles ||
        l.size() != 2 * kCells) {
      return r.fail("bad grid tile");
    }
    worldmap::SavedTile t;
    t.tx = static_cast<std::int16_t>(tx);
    t.ty = static_cast<std::int16_t>(ty);
    for (std::size_t k = 0; k < kCells; ++k) {
      const int hi = hex_digit(l[2 * k]);
      const int lo = hex_digit(l[2 * k + 1]);
      if (hi < 0 || lo < 0) return r.fail("bad grid tile");
      const auto byte = static_cast<std::uint8_t>(hi * 16 + lo);
      t.cells[k] = static_cast<std::int8_t>(byte);
      if (t.cells[k] > worldmap::kMaxLogOdds || t.cells[k] < -worldmap::kMaxLogOdds) {
        return r.fail("bad grid tile");
      }
    }
    (void)s.grid.push_back(t);
  }
  return true;
}

// The first line (and from version 3 the second): version and sequence number.
bool decode_header(Reader& r, std::uint64_t& version, std::uint64_t& sequence) {
  std::string_view l;
  if (!r.line(l)) return false;
  if (l.substr(0, 16) != "BOTICELLI-STATE ") return r.fail("not a state file");
  // Version 1 (a goal without its height) is still read: its goal stands on the floor.
  // Version 2 has no sequence number (0) and no result (running).
  if (!parse_u64(l.substr(16), version) || version < 1 || version > kStateFormatVersion) {
    return r.fail("unsupported state file version");
  }
  sequence = 0;
  if (version >= 3) {
    std::string_view v;
    if (!r.keyed("sequence", v) || !parse_u64(v, sequence)) return r.fail("bad sequence");
  }
  return true;
}

bool decode_result(std::string_view v, MissionState& s) {
  const std::string_view name = next_word(v);
  for (const MissionEnd end :
       {MissionEnd::kRunning, MissionEnd::kFound, MissionEnd::kNotFound, MissionEnd::kAborted}) {
    if (name != mission_end_name(end)) continue;
    if (end == MissionEnd::kRunning && !v.empty()) return false;
    if (v.size() > MissionLogEntry::kMaxTextBytes) return false;
    for (const char c : v) {
      if (c < 0x20 || c > 0x7E) return false;
    }
    s.set_end(end, v);
    return true;
  }
  return false;
}

bool decode_body(Reader& r, MissionState& s, std::uint64_t& sequence) {
  std::string_view v;
  std::string_view l;
  std::uint64_t version = 0;
  if (!decode_header(r, version, sequence)) return false;
  if (!r.keyed("cycle", v) || !parse_u64(v, s.cycle)) return r.fail("bad cycle");
  if (!r.keyed("seed", v) || !parse_u64(v, s.seed)) return r.fail("bad seed");
  if (version >= 3 && (!r.keyed("result", v) || !decode_result(v, s))) {
    return r.fail("bad result");
  }
  float pose[3];
  if (!r.keyed("pose", v) || !parse_floats(v, pose, 3)) return r.fail("bad pose");
  s.pose = {pose[0], pose[1], pose[2]};
  if (version >= 4) {
    std::uint64_t ms = 0;
    if (!r.keyed("pose_time_ms", v) || !parse_u64(v, ms) || ms > INT64_MAX) {
      return r.fail("bad pose time");
    }
    s.pose_time_ms = static_cast<std::int64_t>(ms);
  }
  if (version >= 5) {
    if (!r.keyed("wheels", v)) return r.fail("bad wheels");
    if (v == "none") {
      s.wheels_known = false;
    } else {
      s.wheels_known = true;
      if (!parse_double(next_word(v), s.wheel_left_m) ||
          !parse_double(next_word(v), s.wheel_right_m) || !v.empty()) {
        return r.fail("bad wheels");
      }
    }
  }
  if (version >= 6) {
    float bias = 0.0F;
    if (!r.keyed("stereo_bias", v) || !parse_floats(v, &bias, 1) || std::fabs(bias) > 1.0F) {
      return r.fail("bad stereo bias");
    }
    s.stereo_bias_per_m = bias;
  }
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
  if (version >= 5 && !read_grid(r, s)) return false;
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

std::size_t encode_state(const MissionState& s, char* out, std::size_t capacity,
                         std::uint64_t sequence) {
  Writer w{out, capacity};
  w.printf("BOTICELLI-STATE %u\nsequence %llu\n", kStateFormatVersion,
           static_cast<unsigned long long>(sequence));
  w.printf("cycle %llu\nseed %llu\n", static_cast<unsigned long long>(s.cycle),
           static_cast<unsigned long long>(s.seed));
  if (s.finished()) {
    w.printf("result %s%s%s\n", mission_end_name(s.end), s.end_reason[0] != '\0' ? " " : "",
             s.end_reason.data());
  } else {
    w.printf("result running\n");
  }
  w.printf("pose %.9g %.9g %.9g\npose_time_ms %lld\n", static_cast<double>(s.pose.x_m),
           static_cast<double>(s.pose.y_m), static_cast<double>(s.pose.yaw_rad),
           static_cast<long long>(s.pose_time_ms < 0 ? 0 : s.pose_time_ms));
  if (s.wheels_known) {
    w.printf("wheels %.17g %.17g\n", s.wheel_left_m, s.wheel_right_m);
  } else {
    w.printf("wheels none\n");
  }
  w.printf("stereo_bias %.9g\n", static_cast<double>(s.stereo_bias_per_m));
  if (s.has_goal) {
    w.printf("goal %.9g %.9g %.9g\n", static_cast<double>(s.goal.x_m),
             static_cast<double>(s.goal.y_m), static_cast<double>(s.goal_height_m));
  } else {
    w.printf("goal none\n");
  }
  write_points(w, "obstacles", s.obstacles);
  write_points(w, "exploration", s.exploration);
  w.printf("grid %.9g %zu\n", static_cast<double>(s.grid_cell_m), s.grid.size());
  for (const worldmap::SavedTile& t : s.grid) {
    char line[16 + 2 * worldmap::kTileCells * worldmap::kTileCells + 2];
    int n = std::snprintf(line, sizeof line, "%d %d ", t.tx, t.ty);
    static constexpr char kHex[] = "0123456789abcdef";
    for (const std::int8_t c : t.cells) {
      const auto byte = static_cast<std::uint8_t>(c);
      line[n++] = kHex[byte >> 4U];
      line[n++] = kHex[byte & 0x0FU];
    }
    line[n++] = '\n';
    w.bytes({line, static_cast<std::size_t>(n)});
  }
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

namespace {
// The body of `file` (everything before its checksum line) when the checksum matches.
bool checked_body(std::string_view file, std::string_view& body, const char** error) {
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
  body = file.substr(0, file.size() - kCrcLine);
  if (crc32(body.data(), body.size()) != stored) {
    *error = "checksum mismatch (corrupt file)";
    return false;
  }
  return true;
}
}  // namespace

bool decode_state(std::string_view file, MissionState& out, const char** error,
                  std::uint64_t* sequence) {
  out.clear();
  std::string_view body;
  if (!checked_body(file, body, error)) return false;
  Reader r{body};
  std::uint64_t seq = 0;
  if (!decode_body(r, out, seq) || !r.rest.empty()) {
    *error = r.error != nullptr ? r.error : "trailing data";
    out.clear();
    return false;
  }
  if (sequence != nullptr) *sequence = seq;
  return true;
}

bool peek_state(std::string_view file, std::uint64_t& sequence, const char** error) {
  std::string_view body;
  if (!checked_body(file, body, error)) return false;
  Reader r{body};
  std::uint64_t version = 0;
  if (!decode_header(r, version, sequence)) {
    *error = r.error;
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
  surveyed_ = false;
  newest_ = -1;
  next_sequence_ = 1;
  copies_written_ = 0;
  loaded_path_[0] = '\0';
  warning_[0] = '\0';
  const int n1 = std::snprintf(dir_.data(), dir_.size(), "%s", dir);
  const char* names[kCandidates] = {kCopyNames[0], kCopyNames[1], kSingleFileName};
  bool too_long = n1 < 0;
  for (int i = 0; i < kCandidates; ++i) {
    auto& path = paths_[static_cast<std::size_t>(i)];
    const int n = std::snprintf(path.data(), path.size(), "%s/%s", dir, names[i]);
    // write_file_atomically() appends ".tmp"; keep_previous() ".N".
    too_long = too_long || n < 0 || static_cast<std::size_t>(n) + 4 >= path.size();
  }
  const int n3 = std::snprintf(parameters_path_.data(), parameters_path_.size(), "%s/%s", dir,
                               kParametersFileName);
  // The longest name, with write_file_atomically()'s ".tmp", must fit its 512-byte paths.
  if (too_long || n3 < 0 || static_cast<std::size_t>(n3) + 4 >= parameters_path_.size()) {
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

LoadResult StateStore::read_candidate(int i, std::size_t& size, char* why, std::size_t why_size) {
  const char* path = paths_[static_cast<std::size_t>(i)].data();
  size = 0;
  const int fd = ::open(path, O_RDONLY | O_CLOEXEC);
  if (fd < 0) {
    if (errno == ENOENT) return LoadResult::kMissing;
    std::snprintf(why, why_size, "cannot open: %s", std::strerror(errno));
    return LoadResult::kIoError;
  }
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
      std::snprintf(why, why_size, "cannot read: %s", std::strerror(errno));
      ::close(fd);
      return LoadResult::kIoError;
    }
    if (n == 0) break;
    size += static_cast<std::size_t>(n);
  }
  ::close(fd);
  if (too_big) {
    std::snprintf(why, why_size, "file larger than any valid state");
    return LoadResult::kCorrupt;
  }
  return LoadResult::kLoaded;
}

void StateStore::survey() {
  for (int i = 0; i < kCandidates; ++i) {
    Copy& c = copies_[static_cast<std::size_t>(i)];
    c = Copy{};
    std::size_t size = 0;
    const LoadResult read = read_candidate(i, size, c.why.data(), c.why.size());
    if (read == LoadResult::kMissing) continue;
    c.exists = true;
    c.io_error = read == LoadResult::kIoError;
    if (read != LoadResult::kLoaded) continue;
    const char* why = "";
    c.valid = peek_state({buffer_.data(), size}, c.sequence, &why);
    if (!c.valid) std::snprintf(c.why.data(), c.why.size(), "%s", why);
  }
  surveyed_ = true;
  newest_ = -1;
  std::uint64_t newest_sequence = 0;
  bool any = false;
  for (int i = 0; i < kCandidates; ++i) {
    const Copy& c = copies_[static_cast<std::size_t>(i)];
    if (!c.valid) continue;
    if (!any || c.sequence > newest_sequence) newest_sequence = c.sequence;
    any = true;
  }
  next_sequence_ = any ? newest_sequence + 1 : 1;
  const int best = newest_valid(0);
  newest_ = best == 0 || best == 1 ? best : -1;
}

// The first of the highest sequence number wins: the two copies win a tie against the single file.
int StateStore::newest_valid(int skip_mask) const {
  int best = -1;
  for (int i = 0; i < kCandidates; ++i) {
    const Copy& c = copies_[static_cast<std::size_t>(i)];
    if (!c.valid || (skip_mask & (1 << i)) != 0) continue;
    if (best < 0 || c.sequence > copies_[static_cast<std::size_t>(best)].sequence) best = i;
  }
  return best;
}

bool StateStore::sync_dir(char* error, std::size_t error_size) {
  const int dfd = ::open(dir_.data(), O_RDONLY | O_DIRECTORY | O_CLOEXEC);
  if (dfd < 0 || ::fsync(dfd) != 0) {
    set_error(error, error_size, "cannot sync", dir_.data());
    if (dfd >= 0) ::close(dfd);
    return false;
  }
  ::close(dfd);
  return true;
}

LoadResult StateStore::keep_previous(char* kept, std::size_t kept_size, char* error,
                                     std::size_t error_size) {
  survey();
  int keep = newest_valid(0);
  for (int i = 0; i < kCandidates && keep < 0; ++i) {
    if (copies_[static_cast<std::size_t>(i)].exists) keep = i;  // none valid: keep one anyway
  }
  if (keep < 0) return LoadResult::kMissing;
  const char* base = paths_[2].data();  // DIR/mission.state
  // Oldest first: .2 -> .3, .1 -> .2 (a missing one is skipped), then the copy -> .1.
  std::array<char, 520> from{};
  std::array<char, 520> to{};
  for (int i = kKeptStates - 1; i >= 0; --i) {
    if (i == 0) {
      std::snprintf(from.data(), from.size(), "%s", paths_[static_cast<std::size_t>(keep)].data());
    } else {
      std::snprintf(from.data(), from.size(), "%s.%d", base, i);
    }
    std::snprintf(to.data(), to.size(), "%s.%d", base, i + 1);
    if (::rename(from.data(), to.data()) != 0 && !(errno == ENOENT && i > 0)) {
      set_error(error, error_size, "cannot keep", from.data());
      return LoadResult::kIoError;
    }
  }
  // The other copies are older states of the same mission: the kept one supersedes them.
  for (int i = 0; i < kCandidates; ++i) {
    if (i == keep || !copies_[static_cast<std::size_t>(i)].exists) continue;
    if (::unlink(paths_[static_cast<std::size_t>(i)].data()) != 0 && errno != ENOENT) {
      set_error(error, error_size, "cannot remove", paths_[static_cast<std::size_t>(i)].data());
      return LoadResult::kIoError;
    }
  }
  if (!sync_dir(error, error_size)) return LoadResult::kIoError;
  copies_ = {};
  surveyed_ = true;
  newest_ = -1;
  next_sequence_ = 1;
  std::snprintf(kept, kept_size, "%s", to.data());
  return LoadResult::kLoaded;
}

bool StateStore::save(const MissionState& state, char* error, std::size_t error_size) {
  if (!is_open()) {
    std::snprintf(error, error_size, "no state directory");
    return false;
  }
  if (!surveyed_) survey();
  const std::size_t size = encode_state(state, buffer_.data(), buffer_.size(), next_sequence_);
  if (size == 0) {
    std::snprintf(error, error_size, "state does not fit the file buffer");
    return false;
  }
  // The copy that does not hold the newest valid state: the older one, or a damaged one.
  const int target = newest_ == 0 ? 1 : 0;
  if (!write_file_atomically(dir_.data(), kCopyNames[target], {buffer_.data(), size}, error,
                             error_size, crash_hook_, crash_context_)) {
    return false;
  }
  Copy& c = copies_[static_cast<std::size_t>(target)];
  c.exists = true;
  c.valid = true;
  c.sequence = next_sequence_;
  newest_ = target;
  ++next_sequence_;
  ++saves_;
  ++copies_written_;
  // A single-file state is a fallback until both copies hold newer states; then it goes.
  Copy& single = copies_[2];
  if (single.exists && copies_written_ >= 2) {
    if (::unlink(paths_[2].data()) == 0 || errno == ENOENT) single = Copy{};
  }
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
  loaded_path_[0] = '\0';
  warning_[0] = '\0';
  survey();
  bool any = false;
  bool any_corrupt = false;
  for (const Copy& c : copies_) {
    any = any || c.exists;
    any_corrupt = any_corrupt || (c.exists && !c.valid && !c.io_error);
  }
  if (!any) {
    std::snprintf(error, error_size, "no saved state in %s", dir_.data());
    return LoadResult::kMissing;
  }
  // Newest first; a copy whose body does not parse (checksum good) is passed over too.
  int skip = 0;
  for (int best = newest_valid(0); best >= 0; best = newest_valid(skip)) {
    Copy& c = copies_[static_cast<std::size_t>(best)];
    std::size_t size = 0;
    const char* why = "";
    std::uint64_t sequence = 0;
    if (read_candidate(best, size, c.why.data(), c.why.size()) == LoadResult::kLoaded &&
        decode_state({buffer_.data(), size}, out, &why, &sequence)) {
      std::snprintf(loaded_path_.data(), loaded_path_.size(), "%s",
                    paths_[static_cast<std::size_t>(best)].data());
      // Name every other copy that exists but could not be used.
      Writer w{warning_.data(), warning_.size()};
      for (int i = 0; i < kCandidates; ++i) {
        const Copy& o = copies_[static_cast<std::size_t>(i)];
        if (i == best || !o.exists || o.valid) continue;
        w.printf("%s%s: %s", w.size > 0 ? "; " : "", paths_[static_cast<std::size_t>(i)].data(),
                 o.why.data());
      }
      if (w.size > 0) {
        w.printf("; loaded %s (sequence %llu) instead", loaded_path_.data(),
                 static_cast<unsigned long long>(sequence));
      }
      newest_ = best == 0 || best == 1 ? best : -1;
      next_sequence_ = sequence + 1;
      for (const Copy& o : copies_) {
        if (o.valid && o.sequence >= next_sequence_) next_sequence_ = o.sequence + 1;
      }
      return LoadResult::kLoaded;
    }
    if (why[0] != '\0') std::snprintf(c.why.data(), c.why.size(), "%s", why);
    c.valid = false;
    any_corrupt = true;
    skip |= 1 << best;
  }
  // No copy loads: say why for each.
  Writer w{error, error_size};
  for (int i = 0; i < kCandidates; ++i) {
    const Copy& c = copies_[static_cast<std::size_t>(i)];
    if (!c.exists) continue;
    w.printf("%s%s: %s", w.size > 0 ? "; " : "", paths_[static_cast<std::size_t>(i)].data(),
             c.why.data());
  }
  newest_ = -1;
  return any_corrupt ? LoadResult::kCorrupt : LoadResult::kIoError;
}

}  // namespace boticelli::firmware
