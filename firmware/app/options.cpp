// Command-line parsing for the firmware (see options.h).
#include "firmware/app/options.h"

#include <cerrno>
#include <cinttypes>
#include <cstdio>
#include <cstdlib>
#include <cstring>

namespace boticelli::firmware {
namespace {

char g_error[192];

// "<before>'<arg>'<after>", e.g. fail("option ", "--seed", " needs a whole number").
ParseResult fail(const char* before, const char* arg, const char* after) {
  std::snprintf(g_error, sizeof g_error, "%s'%s'%s", before, arg, after);
  return {false, g_error};
}

bool parse_u64(const char* text, std::uint64_t& out) {
  if (text == nullptr || *text == '\0' || *text == '-' || *text == '+') {
    return false;
  }
  errno = 0;
  char* end = nullptr;
  const unsigned long long v = std::strtoull(text, &end, 10);
  if (errno != 0 || end == text || *end != '\0') {
    return false;
  }
  out = static_cast<std::uint64_t>(v);
  return true;
}

// A plain non-negative decimal number (strtod's syntax without inf, nan or hex), at most
// `max`.
bool parse_speed(const char* text, double max, double& out) {
  if (text == nullptr || *text == '\0' || *text == '-' || *text == '+') return false;
  for (const char* c = text; *c != '\0'; ++c) {
    if ((*c < '0' || *c > '9') && *c != '.' && *c != 'e' && *c != 'E' && *c != '-' && *c != '+') {
      return false;
    }
  }
  errno = 0;
  char* end = nullptr;
  const double v = std::strtod(text, &end);
  if (errno != 0 || end == text || *end != '\0' || !(v >= 0.0) || v > max) return false;
  out = v;
  return true;
}

}  // namespace

const char* usage_text() {
  return "usage: boticelli [options]\n"
         "  --world FILE        world to simulate (SDF subset; sim board only)\n"
         "  --faults FILE       inject the faults planned in FILE (sim board only)\n"
         "  --speed X           simulated time per wall time: 1 = real time, 0 = as fast\n"
         "                      as possible (default; sim board only)\n"
         "  --host-slices       end background slices by the host's clock, as on the robot,\n"
         "                      not by a count of units (timing runs; sim board only)\n"
         "  --realtime          lock memory and run SCHED_FIFO where permitted, as on the\n"
         "                      robot (sim board only)\n"
         "  --seed N            random seed for the simulation and training (default 1)\n"
         "  --max-cycles N      stop after N Look-Think-Drive cycles (default: no limit)\n"
         "  --snapshots DIR     write a picture of the map after each cycle into DIR\n"
         "  --trace FILE        write the robot's path as CSV to FILE\n"
         "  --map PREFIX        at the end, write the world memory (grid) as PREFIX.pgm and\n"
         "                      PREFIX.yaml (ROS map_server's format)\n"
         "  --console KIND      stdio (default), pty, or the PATH of a serial device\n"
         "  --config FILE       read the configuration from FILE (default on the robot:\n"
         "                      /etc/boticelli/boticelli.conf, if it exists)\n"
         "  --state DIR         keep the mission state and saved parameters in DIR\n"
         "  --resume            continue the mission saved in --state DIR (new if none)\n"
         "  --version           print the version and board, then exit\n"
         "  --help              print this text, then exit\n";
}

ParseResult parse_options(int argc, const char* const* argv, bool simulated, Options& out) {
  out = Options{};
  for (int i = 1; i < argc; ++i) {
    const char* arg = argv[i];
    auto value = [&](const char*& dst) -> bool {
      if (i + 1 >= argc) {
        return false;
      }
      dst = argv[++i];
      return true;
    };
    const char* v = nullptr;
    if (std::strcmp(arg, "--help") == 0 || std::strcmp(arg, "-h") == 0) {
      out.show_help = true;
    } else if (std::strcmp(arg, "--version") == 0) {
      out.show_version = true;
    } else if (std::strcmp(arg, "--resume") == 0) {
      out.resume = true;
    } else if (std::strcmp(arg, "--world") == 0) {
      if (!value(out.world_file)) return fail("option ", arg, " needs a FILE");
      if (!simulated) return fail("option ", arg, " is only for the sim board");
    } else if (std::strcmp(arg, "--faults") == 0) {
      if (!value(out.faults_file) || *out.faults_file == '\0') {
        return fail("option ", arg, " needs a FILE");
      }
      if (!simulated) return fail("option ", arg, " is only for the sim board");
    } else if (std::strcmp(arg, "--speed") == 0) {
      if (!value(v) || !parse_speed(v, 1000.0, out.speed)) {
        return fail("option ", arg, " needs a number from 0 to 1000 (1 = real time)");
      }
      if (!simulated) return fail("option ", arg, " is only for the sim board");
    } else if (std::strcmp(arg, "--host-slices") == 0) {
      if (!simulated) return fail("option ", arg, " is only for the sim board");
      out.host_slices = true;
    } else if (std::strcmp(arg, "--realtime") == 0) {
      if (!simulated) return fail("option ", arg, " is only for the sim board");
      out.realtime = true;
    } else if (std::strcmp(arg, "--seed") == 0) {
      if (!value(v) || !parse_u64(v, out.seed))
        return fail("option ", arg, " needs a whole number");
    } else if (std::strcmp(arg, "--max-cycles") == 0) {
      if (!value(v) || !parse_u64(v, out.max_cycles)) {
        return fail("option ", arg, " needs a whole number");
      }
    } else if (std::strcmp(arg, "--snapshots") == 0) {
      if (!value(out.snapshots_dir)) return fail("option ", arg, " needs a DIR");
    } else if (std::strcmp(arg, "--trace") == 0) {
      if (!value(out.trace_file)) return fail("option ", arg, " needs a FILE");
    } else if (std::strcmp(arg, "--map") == 0) {
      if (!value(out.map_prefix) || *out.map_prefix == '\0') {
        return fail("option ", arg, " needs a PREFIX");
      }
    } else if (std::strcmp(arg, "--config") == 0) {
      if (!value(out.config_file) || *out.config_file == '\0') {
        return fail("option ", arg, " needs a FILE");
      }
    } else if (std::strcmp(arg, "--state") == 0) {
      if (!value(out.state_dir)) return fail("option ", arg, " needs a DIR");
    } else if (std::strcmp(arg, "--console") == 0) {
      if (!value(v)) return fail("option ", arg, " needs stdio, pty or a PATH");
      if (std::strcmp(v, "stdio") == 0) {
        out.console = ConsoleKind::kStdio;
      } else if (std::strcmp(v, "pty") == 0) {
        out.console = ConsoleKind::kPty;
      } else if (*v != '\0') {
        out.console = ConsoleKind::kPath;
        out.console_path = v;
      } else {
        return fail("option ", arg, " needs stdio, pty or a PATH");
      }
    } else {
      return fail("unknown option ", arg, "");
    }
  }
  if (out.resume && out.state_dir == nullptr) {
    return fail("option ", "--resume", " needs --state DIR");
  }
  return {true, ""};
}

}  // namespace boticelli::firmware
