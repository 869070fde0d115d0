// Options: the firmware's command line (`boticelli --help`, man page boticelli(8)), parsed without
// allocation or exceptions.
#pragma once

#include <cstdint>

namespace boticelli::firmware {

enum class ConsoleKind : std::uint8_t { kStdio, kPty, kPath };

struct Options {
  const char* world_file = nullptr;   // --world FILE (sim board only)
  const char* faults_file = nullptr;  // --faults FILE: a fault plan (sim board only)
  double speed = 0.0;  // --speed X (sim board only): simulated/wall time, 0 = as fast as possible
  bool host_slices = false;  // --host-slices (sim board only): slices end by the host's clock
  bool realtime = false;     // --realtime (sim board only): mlockall and SCHED_FIFO if permitted
  std::uint64_t seed = 1;    // --seed N
  std::uint64_t max_cycles = 0;               // --max-cycles N; 0 = no limit
  const char* snapshots_dir = nullptr;        // --snapshots DIR
  const char* trace_file = nullptr;           // --trace FILE
  const char* map_prefix = nullptr;           // --map PREFIX: PREFIX.pgm/.yaml at the end
  ConsoleKind console = ConsoleKind::kStdio;  // --console stdio|pty|PATH
  const char* console_path = nullptr;         // the PATH of --console PATH
  const char* state_dir = nullptr;            // --state DIR
  const char* config_file = nullptr;          // --config FILE (else the board's default path)
  bool resume = false;                        // --resume
  bool show_help = false;                     // --help
  bool show_version = false;                  // --version
};

struct ParseResult {
  bool ok = false;
  // When !ok: what was wrong, e.g. "unknown option '--foo'". Points into a static buffer
  // or a literal; valid until the next parse.
  const char* error = "";
};

// Parses argv[1..argc). `simulated` is false on hardware boards, where --world and --speed
// are refused.
ParseResult parse_options(int argc, const char* const* argv, bool simulated, Options& out);

// The usage text printed by --help and after a usage error.
const char* usage_text();

}  // namespace boticelli::firmware
