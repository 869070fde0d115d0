// FaultPlan: names, the applicable pairs, the plan file's strict parser and the soak generator.
#include "hal/sim/fault_plan.h"

#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>

namespace boticelli::hal::sim {
namespace {

constexpr const char* const kDeviceNames[kFaultDeviceCount] = {
    "camera", "ptu",    "axis-left", "axis-right", "can",
    "estop",  "bumper", "storage",   "main-loop",  "watchdog"};
constexpr const char* const kTypeNames[kFaultTypeCount] = {
    "off", "stuck", "garbage", "wrong", "slow", "delayed", "intermittent"};

// Bit t set: type t means something for the device (docs/reliability.md).
constexpr std::uint8_t bit(FaultType t) {
  return static_cast<std::uint8_t>(1U << static_cast<unsigned>(t));
}
constexpr std::uint8_t kAll = 0x7F;
// An ODrive axis: heartbeat lost, frozen encoder estimates, axis error, a jammed wheel.
constexpr std::uint8_t kAxis = bit(FaultType::kOff) | bit(FaultType::kStuck) |
                               bit(FaultType::kWrong) | bit(FaultType::kSlow) |
                               bit(FaultType::kIntermittent);
constexpr std::array<std::uint8_t, kFaultDeviceCount> kApplies = {
    kAll,                                                                             // camera
    kAll,                                                                             // ptu
    kAxis,                                                                            // left
    kAxis,                                                                            // right
    bit(FaultType::kOff) | bit(FaultType::kDelayed) | bit(FaultType::kIntermittent),  // can
    bit(FaultType::kOff) | bit(FaultType::kStuck) | bit(FaultType::kIntermittent),    // estop
    bit(FaultType::kOff) | bit(FaultType::kStuck) | bit(FaultType::kIntermittent),    // bumper
    bit(FaultType::kOff) | bit(FaultType::kStuck) | bit(FaultType::kWrong) |
        bit(FaultType::kIntermittent),               // storage
    bit(FaultType::kStuck) | bit(FaultType::kSlow),  // main loop
    // The watchdog device: keep-alives refused (off, intermittent), busy when opened (stuck).
    bit(FaultType::kOff) | bit(FaultType::kStuck) | bit(FaultType::kIntermittent),
};

void say(char* error, std::size_t size, const char* name, std::size_t line, const char* why,
         std::string_view word = {}) {
  if (word.empty()) {
    std::snprintf(error, size, "%s:%zu: %s", name, line, why);
  } else {
    std::snprintf(error, size, "%s:%zu: %s '%.*s'", name, line, why,
                  static_cast<int>(word.size() > 40 ? 40 : word.size()), word.data());
  }
}

// A plain decimal number of seconds ("12", "0.25", "1e2"): no sign, hex, inf or nan.
bool parse_seconds(std::string_view word, double& out) {
  if (word.empty() || word.size() > 24) return false;
  char buf[32];
  for (std::size_t i = 0; i < word.size(); ++i) {
    const char c = word[i];
    if (!((c >= '0' && c <= '9') || c == '.' || c == 'e' || c == 'E' ||
          ((c == '-' || c == '+') && i > 0 && (word[i - 1] == 'e' || word[i - 1] == 'E')))) {
      return false;
    }
    buf[i] = c;
  }
  buf[word.size()] = '\0';
  if (buf[0] < '0' || buf[0] > '9') return false;
  char* end = nullptr;
  errno = 0;
  const double v = std::strtod(buf, &end);
  if (end != buf + word.size() || errno != 0 || !std::isfinite(v)) return false;
  out = v;
  return true;
}

std::uint64_t to_us(double s) {
  return static_cast<std::uint64_t>(std::llround(s * 1e6));
}

// splitmix64: the generator's only source of randomness.
std::uint64_t next_random(std::uint64_t& state) {
  std::uint64_t z = (state += 0x9E3779B97F4A7C15ULL);
  z = (z ^ (z >> 30U)) * 0xBF58476D1CE4E5B9ULL;
  z = (z ^ (z >> 27U)) * 0x94D049BB133111EBULL;
  return z ^ (z >> 31U);
}
double uniform(std::uint64_t& state) {
  return static_cast<double>(next_random(state) >> 11U) * (1.0 / 9007199254740992.0);
}

}  // namespace

const char* fault_device_name(FaultDevice device) {
  const auto i = static_cast<std::size_t>(device);
  if (i >= kFaultDeviceCount) return "?";
  return kDeviceNames[i];
}

const char* fault_type_name(FaultType type) {
  const auto i = static_cast<std::size_t>(type);
  if (i >= kFaultTypeCount) return "?";
  return kTypeNames[i];
}

bool parse_fault_device(std::string_view name, FaultDevice& out) {
  for (std::size_t i = 0; i < kFaultDeviceCount; ++i) {
    if (name == kDeviceNames[i]) {
      out = static_cast<FaultDevice>(i);
      return true;
    }
  }
  return false;
}

bool parse_fault_type(std::string_view name, FaultType& out) {
  for (std::size_t i = 0; i < kFaultTypeCount; ++i) {
    if (name == kTypeNames[i]) {
      out = static_cast<FaultType>(i);
      return true;
    }
  }
  return false;
}

bool fault_applies(FaultDevice device, FaultType type) {
  const auto d = static_cast<std::size_t>(device);
  const auto t = static_cast<std::size_t>(type);
  return d < kFaultDeviceCount && t < kFaultTypeCount && (kApplies[d] & (1U << t)) != 0;
}

bool FaultPlan::add(const Fault& fault) {
  if (count_ == kMaxFaults) return false;
  faults_[count_++] = fault;
  return true;
}

bool parse_fault_plan(std::string_view text, const char* name, FaultPlan& out, char* error,
                      std::size_t error_size) {
  out.clear();
  if (text.size() > FaultPlan::kMaxFileBytes) {
    std::snprintf(error, error_size, "%s: longer than %zu bytes", name, FaultPlan::kMaxFileBytes);
    return false;
  }
  std::size_t line_no = 0;
  std::size_t pos = 0;
  while (pos < text.size()) {
    ++line_no;
    std::size_t end = text.find('\n', pos);
    if (end == std::string_view::npos) end = text.size();
    std::string_view line = text.substr(pos, end - pos);
    pos = end + 1;
    if (!line.empty() && line.back() == '\r') line.remove_suffix(1);
    if (line.size() > FaultPlan::kMaxLineBytes) {
      say(error, error_size, name, line_no, "line longer than 160 bytes");
      out.clear();
      return false;
    }
    for (const char c : line) {
      const auto u = static_cast<unsigned char>(c);
      if ((u < 0x20 && c != '\t') || u >= 0x7F) {
        say(error, error_size, name, line_no, "control or non-ASCII byte");
        out.clear();
        return false;
      }
    }
    const std::size_t hash = line.find('#');
    if (hash != std::string_view::npos) line = line.substr(0, hash);
    // Words separated by spaces or tabs.
    std::array<std::string_view, 5> words{};
    std::size_t count = 0;
    std::size_t i = 0;
    while (i < line.size()) {
      while (i < line.size() && (line[i] == ' ' || line[i] == '\t')) ++i;
      if (i == line.size()) break;
      const std::size_t start = i;
      while (i < line.size() && line[i] != ' ' && line[i] != '\t') ++i;
      if (count == words.size()) {
        say(error, error_size, name, line_no, "too many words (AT_S DEVICE TYPE [DURATION_S])");
        out.clear();
        return false;
      }
      words[count++] = line.substr(start, i - start);
    }
    if (count == 0) continue;
    if (count < 3 || count > 4) {
      say(error, error_size, name, line_no, "expected AT_S DEVICE TYPE [DURATION_S]");
      out.clear();
      return false;
    }
    Fault f;
    double at_s = 0.0;
    if (!parse_seconds(words[0], at_s) || at_s > FaultPlan::kMaxTimeS) {
      say(error, error_size, name, line_no, "start time is not a number of seconds in [0, 1e6]",
          words[0]);
      out.clear();
      return false;
    }
    if (!parse_fault_device(words[1], f.device)) {
      say(error, error_size, name, line_no,
          "unknown device (camera, ptu, axis-left, axis-right, can, estop, bumper, storage, "
          "main-loop, watchdog)",
          words[1]);
      out.clear();
      return false;
    }
    if (!parse_fault_type(words[2], f.type)) {
      say(error, error_size, name, line_no,
          "unknown fault type (off, stuck, garbage, wrong, slow, delayed, intermittent)", words[2]);
      out.clear();
      return false;
    }
    if (!fault_applies(f.device, f.type)) {
      char why[96];
      std::snprintf(why, sizeof why, "%s cannot be %s", fault_device_name(f.device),
                    fault_type_name(f.type));
      say(error, error_size, name, line_no, why);
      out.clear();
      return false;
    }
    f.start_us = to_us(at_s);
    if (f.device == FaultDevice::kMainLoop && f.type == FaultType::kStuck && count == 3) {
      say(error, error_size, name, line_no, "a main-loop stall needs a duration");
      out.clear();
      return false;
    }
    if (count == 4) {
      double duration_s = 0.0;
      if (!parse_seconds(words[3], duration_s) || duration_s > FaultPlan::kMaxTimeS ||
          to_us(duration_s) == 0) {
        say(error, error_size, name, line_no, "duration is not a number of seconds in (0, 1e6]",
            words[3]);
        out.clear();
        return false;
      }
      f.duration_us = to_us(duration_s);
      if (f.device == FaultDevice::kMainLoop && f.type == FaultType::kStuck &&
          f.duration_us > kMaxStallUs) {
        say(error, error_size, name, line_no, "a main-loop stall is at most 60 s", words[3]);
        out.clear();
        return false;
      }
    }
    if (!out.add(f)) {
      say(error, error_size, name, line_no, "more than 256 faults");
      out.clear();
      return false;
    }
  }
  return true;
}

bool load_fault_plan(const char* path, FaultPlan& out, char* error, std::size_t error_size) {
  static std::array<char, FaultPlan::kMaxFileBytes + 1> buffer;  // init only, one caller
  out.clear();
  FILE* f = std::fopen(path, "rb");
  if (f == nullptr) {
    std::snprintf(error, error_size, "%s: %s", path, std::strerror(errno));
    return false;
  }
  const std::size_t n = std::fread(buffer.data(), 1, buffer.size(), f);
  const bool failed = std::ferror(f) != 0;
  std::fclose(f);
  if (failed) {
    std::snprintf(error, error_size, "%s: read error", path);
    return false;
  }
  if (n > FaultPlan::kMaxFileBytes) {
    std::snprintf(error, error_size, "%s: longer than %zu bytes", path, FaultPlan::kMaxFileBytes);
    return false;
  }
  return parse_fault_plan({buffer.data(), n}, path, out, error, error_size);
}

std::size_t format_fault_plan(const FaultPlan& plan, char* out, std::size_t capacity) {
  std::size_t used = 0;
  for (std::size_t i = 0; i < plan.size(); ++i) {
    const Fault& f = plan[i];
    const int n =
        f.duration_us == 0
            ? std::snprintf(out + used, capacity - used, "%.6f %s %s\n",
                            static_cast<double>(f.start_us) * 1e-6, fault_device_name(f.device),
                            fault_type_name(f.type))
            : std::snprintf(out + used, capacity - used, "%.6f %s %s %.6f\n",
                            static_cast<double>(f.start_us) * 1e-6, fault_device_name(f.device),
                            fault_type_name(f.type), static_cast<double>(f.duration_us) * 1e-6);
    if (n < 0 || static_cast<std::size_t>(n) >= capacity - used) return 0;
    used += static_cast<std::size_t>(n);
  }
  return used;
}

bool fault_rides_out(FaultDevice device, FaultType type) {
  // (Not the watchdog refusing keep-alives: on a robot that is a reset once it lasts.)
  return device == FaultDevice::kEstop || device == FaultDevice::kStorage ||
         (device == FaultDevice::kCamera &&
          (type == FaultType::kIntermittent || type == FaultType::kSlow ||
           type == FaultType::kDelayed)) ||
         (device == FaultDevice::kMainLoop && type == FaultType::kSlow) ||
         (device == FaultDevice::kCan && type == FaultType::kDelayed);
}

void generate_fault_plan(const PlanGeneratorConfig& config, FaultPlan& out) {
  out.clear();
  std::uint64_t state = config.seed * 0xD1B54A32D192ED03ULL + 0x8CB92BA72F3D8DD7ULL;
  // Pairs the mission is expected to ride out (a soak keeps running through them), or all.
  std::array<Fault, kFaultDeviceCount * kFaultTypeCount> pairs{};
  std::size_t pair_count = 0;
  for (std::size_t d = 0; d < kFaultDeviceCount; ++d) {
    for (std::size_t t = 0; t < kFaultTypeCount; ++t) {
      const auto device = static_cast<FaultDevice>(d);
      const auto type = static_cast<FaultType>(t);
      if (!fault_applies(device, type)) continue;
      if (!fault_rides_out(device, type) && !config.include_terminal) continue;
      pairs[pair_count].device = device;
      pairs[pair_count].type = type;
      ++pair_count;
    }
  }
  if (pair_count == 0 || config.run_s <= config.warmup_s) return;
  // One start per equal window of the run, in time order, so "one fault per device at a
  // time" only has to look back.
  std::array<std::uint64_t, kFaultDeviceCount> busy_until{};
  const double window_s =
      (config.run_s - config.warmup_s) / static_cast<double>(config.count == 0 ? 1 : config.count);
  for (std::size_t k = 0; k < config.count && out.size() < FaultPlan::kMaxFaults; ++k) {
    Fault f = pairs[static_cast<std::size_t>(next_random(state) % pair_count)];
    const double at_s = config.warmup_s + (static_cast<double>(k) + uniform(state)) * window_s;
    const double max_s = config.max_duration_s > 0.2 ? config.max_duration_s : 0.2;
    const double duration_s = 0.2 + uniform(state) * (max_s - 0.2);
    f.start_us = to_us(at_s);
    f.duration_us = to_us(duration_s);
    const auto d = static_cast<std::size_t>(f.device);
    if (f.start_us < busy_until[d]) continue;  // one fault per device at a time
    busy_until[d] = f.end_us();
    (void)out.add(f);
  }
}

}  // namespace boticelli::hal::sim
