// FaultPlan: which sim device fails how, when and for how long — the plan file's parser
// (untrusted input: bounded, validated, FILE:LINE: why) and a seeded generator for soaks.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <string_view>

namespace boticelli::hal::sim {

// The devices a fault can be injected into (the sim board's HAL boundary).
enum class FaultDevice : std::uint8_t {
  kCamera,
  kPtu,
  kAxisLeft,   // the left wheel's ODrive axis
  kAxisRight,  // the right wheel's ODrive axis
  kCan,        // the CAN bus to both axes
  kEstop,      // the e-stop button's line
  kBumper,     // the bumper ring's line
  kStorage,    // the state directory
  kMainLoop,   // the executive itself
  kWatchdog,   // the hardware watchdog device (/dev/watchdog)
  kCount
};

enum class FaultType : std::uint8_t {
  kOff,           // gone (no device, no answer, no heartbeat, line broken, unwritable)
  kStuck,         // frozen (the same frame, a move that never ends, a line held, a stall)
  kGarbage,       // corrupt data (error-flagged frames, garbled replies)
  kWrong,         // wrong but well-formed (wrong frame size, `!` errors, an axis error, full)
  kSlow,          // too slow (frame rate, axis speed, frames that take too long)
  kDelayed,       // late (frames delivered late, moves that start late)
  kIntermittent,  // on and off in 250 ms slots, a seeded coin per slot
  kCount
};

// Longest stall of the executive a plan may ask for [µs] (the simulation runs through it).
inline constexpr std::uint64_t kMaxStallUs = 60000000;

inline constexpr std::size_t kFaultDeviceCount = static_cast<std::size_t>(FaultDevice::kCount);
inline constexpr std::size_t kFaultTypeCount = static_cast<std::size_t>(FaultType::kCount);

// Names as in the plan file and the console: camera, ptu, axis-left, axis-right, can, estop,
// bumper, storage, main-loop, watchdog; off, stuck, garbage, wrong, slow, delayed, intermittent.
const char* fault_device_name(FaultDevice device);
const char* fault_type_name(FaultType type);
bool parse_fault_device(std::string_view name, FaultDevice& out);
bool parse_fault_type(std::string_view name, FaultType& out);
// Whether the type means something for the device (docs/reliability.md lists the pairs).
bool fault_applies(FaultDevice device, FaultType type);

struct Fault {
  FaultDevice device = FaultDevice::kCamera;
  FaultType type = FaultType::kOff;
  std::uint64_t start_us = 0;     // simulated time since the board started [µs]
  std::uint64_t duration_us = 0;  // 0 = until the end of the run
  std::uint64_t end_us() const { return duration_us == 0 ? UINT64_MAX : start_us + duration_us; }
};

// A fixed-capacity list of faults, in the order given (they may overlap; for one device
// the one started last wins while both are active).
class FaultPlan {
 public:
  static constexpr std::size_t kMaxFaults = 256;
  static constexpr std::size_t kMaxFileBytes = std::size_t{64} * 1024;
  static constexpr std::size_t kMaxLineBytes = 160;
  static constexpr double kMaxTimeS = 1e6;  // latest start and longest duration [s]

  bool add(const Fault& fault);  // false when full
  void clear() { count_ = 0; }
  std::size_t size() const { return count_; }
  bool empty() const { return count_ == 0; }
  const Fault& operator[](std::size_t i) const { return faults_[i]; }

 private:
  std::array<Fault, kMaxFaults> faults_{};
  std::size_t count_ = 0;
};

// Plan text, one fault a line: `AT_S DEVICE TYPE [DURATION_S]` (seconds of simulated time,
// plain decimals; no duration = until the end); `#` starts a comment, blank lines are
// skipped. Every line is checked (length, printable ASCII, names, the pair, numbers,
// ranges, capacity); on the first bad one `out` is cleared and `error` holds
// "NAME:LINE: why". Does not allocate.
bool parse_fault_plan(std::string_view text, const char* name, FaultPlan& out, char* error,
                      std::size_t error_size);
// Reads and parses a plan file (at most kMaxFileBytes). Allocates nothing; call at init.
bool load_fault_plan(const char* path, FaultPlan& out, char* error, std::size_t error_size);
// Writes `plan` in the file format (what parse_fault_plan reads back to the same plan);
// returns the bytes written, 0 when `capacity` is too small.
std::size_t format_fault_plan(const FaultPlan& plan, char* out, std::size_t capacity);

// Whether the mission rides the pair out without a device being held and retried (the e-stop
// latch and storage faults, a slow / late / intermittent camera, a slow main loop, a late
// CAN bus): the soak's default plan. The rest stop a device (held and retried), the base (a
// restart by the base task) or, for the watchdog refusing keep-alives, on a robot the board.
bool fault_rides_out(FaultDevice device, FaultType type);

// A random plan for a soak: `count` faults of applicable pairs (no main-loop stall longer
// than `max_duration_s`), starts uniform over [warmup_s, run_s), durations uniform over
// [0.2, max_duration_s] s, at most one fault per device at a time. The same seed gives the
// same plan.
struct PlanGeneratorConfig {
  std::uint64_t seed = 1;
  double run_s = 7200.0;
  double warmup_s = 60.0;
  double max_duration_s = 20.0;
  std::size_t count = 100;
  // Also the pairs that are not ridden out (fault_rides_out false): devices held and retried,
  // the base restarted, the bumper (latched until the operator's reset), the watchdog.
  bool include_terminal = false;
};
void generate_fault_plan(const PlanGeneratorConfig& config, FaultPlan& out);

}  // namespace boticelli::hal::sim
