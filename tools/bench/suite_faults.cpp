// Benchmark suite "faults": every (device, fault type) pair on the sim board, first around a
// stand-in mission (boards/sim/harness/fault_scenario.h: stop latency, console, recovery), then in
// a whole mission (the firmware binary with --faults, the MISSION line's result and reason). With
// RELIABILITY_DOC=FILE it writes the table between the file's table markers (docs/reliability.md is
// made this way, never by hand).
#include <sys/stat.h>
#include <unistd.h>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <vector>

#include "bench.h"
#include "bench_process.h"
#include "bench_worlds.h"
#include "fault_scenario.h"
#include "firmware/state/mission_state.h"
#include "firmware/state/persistence.h"
#include "hal/sim/fault_plan.h"
#include "sim_board.h"

namespace boticelli::bench {
namespace {

using boards::sim::FaultExpectation;
using boards::sim::FaultScenarioResult;
using hal::sim::FaultDevice;
using hal::sim::FaultType;

constexpr const char* kSuite = "faults";
constexpr const char* kBegin = "<!-- faults table: begin (written by boticelli-bench faults) -->";
constexpr const char* kEnd = "<!-- faults table: end -->";

boards::sim::SimBoard g_board;
FaultScenarioResult g_result;
firmware::StateStore g_store;
firmware::MissionState g_state;

struct MissionOutcome {
  bool ran = false;
  std::string result = "none";
  std::string reason;
  long long collisions = -1;
  bool state_loadable = false;
  double cpu_s = 0.0;
  // With an operator reset: the telemetry lines `clear-estop` and `resume` were typed after
  // (empty when not typed), and whether they showed the mission still held.
  std::string reset_seen;
  std::string resume_seen;
  bool held_until_reset = false;
  bool held_until_resume = false;
  // The mission log's hold for a device and its end (Mission::hold_for_device), if any.
  std::string held;
  std::string back;
  // A fault from the start: the firmware's start-up warning about it (stderr), if any.
  std::string start_warning;
};

// The MISSION line's fields: result=WORD ... reason="TEXT".
void parse_mission(const std::string& out, MissionOutcome& m) {
  const std::size_t at = out.rfind("MISSION ");
  if (at == std::string::npos) return;
  const std::string line = out.substr(at, out.find('\n', at) - at);
  m.ran = true;
  const std::size_t r = line.find("result=");
  if (r != std::string::npos) m.result = line.substr(r + 7, line.find(' ', r) - r - 7);
  const std::size_t c = line.find("collisions=");
  if (c != std::string::npos) m.collisions = std::atoll(line.c_str() + c + 11);
  const std::size_t q = line.find("reason=\"");
  if (q != std::string::npos) m.reason = line.substr(q + 8, line.rfind('"') - q - 8);
}

MissionOutcome run_mission(const std::string& firmware, const std::string& world,
                           FaultDevice device, FaultType type, bool operator_reset, bool at_start) {
  MissionOutcome m;
  char dir_template[] = "/tmp/boticelli-faults-XXXXXX";
  const char* dir = ::mkdtemp(dir_template);
  if (dir == nullptr) return m;
  const std::string plan = std::string(dir) + "/plan.txt";
  if (std::FILE* f = std::fopen(plan.c_str(), "w"); f != nullptr) {
    std::fprintf(f, "# one fault in the first look\n%.1f %s %s %.1f\n",
                 at_start ? 0.0 : boards::sim::kMissionFaultStartS,
                 hal::sim::fault_device_name(device), hal::sim::fault_type_name(type),
                 boards::sim::kMissionFaultS);
    std::fclose(f);
  }
  const std::string out = std::string(dir) + "/out.txt";
  const std::string err = std::string(dir) + "/err.txt";
  bool timed_out = false;
  // The operator: `clear-estop` kMissionResetAfterS after the fault's end, `resume` once the
  // telemetry says the mission waits for it (a telemetry line a second).
  const double reset_s = boards::sim::kMissionFaultStartS + boards::sim::kMissionFaultS +
                         boards::sim::kMissionResetAfterS;
  std::vector<ConsoleInput> input = {{reset_s, "", "clear-estop\r", ""},
                                     {reset_s, "waits_for=resume", "resume\r", ""}};
  (void)run_firmware({firmware, "--world", world, "--seed", "1", "--max-cycles", "1", "--faults",
                      plan, "--state", dir, "--console", "stdio"},
                     out, err, 600.0, timed_out, m.cpu_s, operator_reset ? &input : nullptr);
  parse_mission(read_file(out), m);
  if (at_start) {
    const std::string text = read_file(err);
    const std::size_t w = text.find("watchdog not armed");
    if (w != std::string::npos) m.start_warning = text.substr(w, text.find('\n', w) - w);
  }
  if (operator_reset) {
    m.reset_seen = input[0].seen;
    m.resume_seen = input[1].seen;
    const auto held = [](const std::string& line, const char* waits_for) {
      return line.find("state=hold ") != std::string::npos &&
             line.find(waits_for) != std::string::npos;
    };
    m.held_until_reset = held(m.reset_seen, "waits_for=clear-estop ");
    m.held_until_resume = held(m.resume_seen, "waits_for=resume ");
  }
  char error[256] = "";
  m.state_loadable = g_store.open(dir, error, sizeof error) &&
                     g_store.load(g_state, error, sizeof error) == firmware::LoadResult::kLoaded;
  if (m.state_loadable) {
    for (const firmware::MissionLogEntry& e : g_state.log) {
      const std::string text(e.view());
      if (m.held.empty() && text.rfind("held: ", 0) == 0) m.held = text;
      if (m.back.empty() && text.rfind("devices back after ", 0) == 0) m.back = text;
    }
  }
  for (const char* name : {"plan.txt", "out.txt", "err.txt", "mission.state.a", "mission.state.b",
                           "sim-world.truth"}) {
    ::unlink((std::string(dir) + "/" + name).c_str());
  }
  ::rmdir(dir);
  return m;
}

// A table cell: no pipes, no line breaks.
std::string cell(std::string text) {
  for (char& c : text) {
    if (c == '|') c = '/';
    if (c == '\n' || c == '\r') c = ' ';
  }
  return text;
}

std::string expected_text(const FaultExpectation& e) {
  std::string s = e.at_start      ? "from the board's start (the fault a start meets), for 3 s: "
                                    "base keeps moving; "
                  : !e.stops_base ? "base keeps moving; "
                  : e.detect_us > 0
                      ? "base stops commanding within a frame of the driver's 1 s check of the "
                        "wheels against their setpoints, "
                      : "base stops commanding within a frame, ";
  if (e.stops_base) {
    s += e.coasts ? "the axes idled (the wheels coast), at rest within the coasting distance, "
                  : "braked to rest within the braking distance, ";
    s += e.restarts_into_it ? "restarted into the fault by the base task's retry every second "
                              "and each time stopped again by the check; "
                            : "stays stopped while it fails; ";
  }
  s += "console: `" + std::string(e.console_says) + "`; ";
  if (e.operator_reset) {
    char buf[200];
    std::snprintf(buf, sizeof buf,
                  "after it still stopped until `clear-estop` (typed %.1f s later) and after "
                  "that until `resume` (%.1f s later); then ",
                  boards::sim::FaultScenarioConfig{}.after_s,
                  static_cast<double>(boards::sim::kResetToResumeUs) * 1e-6);
    s += buf;
  }
  if (e.recovers && e.stops_base && !e.operator_reset) s += "restarted by the base task's retry: ";
  s += e.recovers ? "healthy and moving again" : "stays stopped (no restart by itself)";
  if (e.recovers && !e.operator_reset) s += " after it";
  return s;
}

// The telemetry line's `t_s=`, `state=` and `waits_for=` fields.
std::string telemetry_fields(const std::string& line) {
  std::string s;
  for (const char* key : {"t_s=", "state=", "waits_for="}) {
    const std::size_t at = line.find(key);
    if (at == std::string::npos) continue;
    s += (s.empty() ? "" : " ") + line.substr(at, line.find(' ', at) - at);
  }
  return s;
}

std::string seen_text(const FaultExpectation& e, const FaultScenarioResult& r) {
  char buf[512];
  std::string s;
  if (r.stop_latency_ms >= 0.0) {
    std::snprintf(buf, sizeof buf, "base stopped commanding after %.0f ms%s; ", r.stop_latency_ms,
                  e.restarts_into_it
                      ? (r.stayed_stopped ? ", stopped again after each restart"
                                          : ", drove on after a restart")
                      : (r.stayed_stopped ? ", stayed stopped" : ", moved again during it"));
  } else {
    std::snprintf(buf, sizeof buf, "base %s; ",
                  e.at_start        ? "moved through it (from the start)"
                  : r.moving_before ? "kept moving"
                                    : "was not moving");
  }
  s += buf;
  s += r.says_expected ? "console said it; " : "console did NOT say it; ";
  if (e.operator_reset) {
    s += r.held_until_reset ? "at rest until clear-estop" : "MOVED before clear-estop";
    s += r.held_until_resume ? " and until resume; " : ", MOVED before resume; ";
  }
  s += r.healthy_after ? "healthy after" : "unhealthy after";
  s += r.moving_after ? ", moving" : ", at rest";
  if (e.stops_base || r.watchdog_expirations > 0) {
    std::snprintf(buf, sizeof buf, "; watchdog expirations %u", r.watchdog_expirations);
    s += buf;
  }
  if (r.save_failures > 0) {
    std::snprintf(buf, sizeof buf, "; saves %llu ok, %llu failed, file %s",
                  static_cast<unsigned long long>(r.saves),
                  static_cast<unsigned long long>(r.save_failures),
                  !r.state_loadable ? "DOES NOT LOAD"
                  : r.state_current ? "loads with the last submitted state"
                                    : "loads but LOST the last submitted state");
    s += buf;
  }
  if (r.frame_overruns > 0) {
    std::snprintf(buf, sizeof buf, "; frame overruns %llu",
                  static_cast<unsigned long long>(r.frame_overruns));
    s += buf;
  }
  return s;
}

// The stopping distance (with its bound) and time cells: where the base must stop.
std::string stopping_cells(const FaultExpectation& e, const FaultScenarioResult& r) {
  if (!e.stops_base) return "— | —";
  char buf[160];
  if (r.stop_time_ms < 0.0) {
    std::snprintf(buf, sizeof buf, "NOT at rest (bound %.4f) | —", r.stop_distance_bound_m);
  } else {
    std::snprintf(buf, sizeof buf, "%.4f (%.4f, %s) | %.0f", r.stop_distance_m,
                  r.stop_distance_bound_m, e.coasts ? "coasting" : "braked", r.stop_time_ms);
  }
  return buf;
}

// Replaces the text between the markers of `path` with `table`.
bool write_table(const char* path, const std::string& table) {
  std::string doc = read_file(path);
  const std::size_t b = doc.find(kBegin);
  const std::size_t e = doc.find(kEnd);
  if (b == std::string::npos || e == std::string::npos || e < b) {
    std::fprintf(stderr, "faults: %s has no table markers\n", path);
    return false;
  }
  doc = doc.substr(0, b + std::string(kBegin).size()) + "\n" + table + doc.substr(e);
  const std::string tmp = std::string(path) + ".tmp";
  std::FILE* f = std::fopen(tmp.c_str(), "w");
  if (f == nullptr) return false;
  const bool ok = std::fwrite(doc.data(), 1, doc.size(), f) == doc.size();
  if (std::fclose(f) != 0 || !ok) return false;
  return std::rename(tmp.c_str(), path) == 0;
}

}  // namespace

BOTICELLI_BENCH_SUITE(faults, "every injected (device, fault type) pair: firmware and mission") {
  const std::string world = std::string(BOTICELLI_WORLDS_DIR) + "/thesis_room.sdf";
  const std::string firmware = own_directory() + "/boticelli";
  struct stat st {};
  if (::stat(firmware.c_str(), &st) != 0) {
    std::fprintf(stderr, "faults: no firmware binary at %s\n", firmware.c_str());
    return 1;
  }
  std::string table =
      "| device | fault | expected of the firmware | seen (sim board, fault from 1 s for 3 s) | "
      "stopping distance [m] (bound) | stopping time [ms] | "
      "mission expected | mission seen (fault from 5 s for 5 s, 1 cycle) | verdict |\n"
      "|---|---|---|---|---|---|---|---|---|\n";
  int passed = 0;
  int pairs = 0;
  for (std::size_t d = 0; d < hal::sim::kFaultDeviceCount; ++d) {
    for (std::size_t t = 0; t < hal::sim::kFaultTypeCount; ++t) {
      const auto device = static_cast<FaultDevice>(d);
      const auto type = static_cast<FaultType>(t);
      if (!hal::sim::fault_applies(device, type)) continue;
      ++pairs;
      const FaultExpectation& e = boards::sim::expectation(device, type);
      char dir_template[] = "/tmp/boticelli-scenario-XXXXXX";
      const char* dir = ::mkdtemp(dir_template);
      boards::sim::FaultScenarioConfig config;
      config.world_file = world.c_str();
      config.state_dir = dir;
      const bool ran = boards::sim::run_fault_scenario(g_board, device, type, config, g_result);
      if (dir != nullptr) {
        for (const char* name : firmware::StateStore::kCopyNames) {
          ::unlink((std::string(dir) + "/" + name).c_str());
        }
        ::rmdir(dir);
      }
      const MissionOutcome m =
          run_mission(firmware, world, device, type, e.operator_reset, e.at_start);
      // The MISSION line counts bumper contacts: a faulted bumper line's are not the world's
      // (the stand-in's run checks the simulator's own count, which stays 0).
      const bool contacts_ok = m.collisions == 0 || device == FaultDevice::kBumper;
      const bool reset_ok = !e.operator_reset || (m.held_until_reset && m.held_until_resume);
      const bool holds_ok = !e.mission_holds || (!m.held.empty() && !m.back.empty());
      const bool start_ok = !e.at_start || !m.start_warning.empty();
      const bool mission_ok = m.ran && contacts_ok && m.state_loadable && reset_ok && holds_ok &&
                              start_ok && (m.result == "aborted") == e.mission_aborts;
      const bool ok = ran && g_result.passed && mission_ok;
      passed += ok ? 1 : 0;
      JsonLine(kSuite, "pair")
          .text("device", hal::sim::fault_device_name(device))
          .text("fault", hal::sim::fault_type_name(type))
          .flag("scenario_passed", ran && g_result.passed)
          .num("stop_latency_ms", g_result.stop_latency_ms)
          .num("stop_distance_m", g_result.stop_distance_m)
          .num("stop_distance_bound_m", g_result.stop_distance_bound_m)
          .num("stop_time_ms", g_result.stop_time_ms)
          .flag("stayed_stopped", g_result.stayed_stopped)
          .flag("console_said", g_result.says_expected)
          .flag("healthy_after", g_result.healthy_after)
          .flag("moving_after", g_result.moving_after)
          .integer("watchdog_expirations", g_result.watchdog_expirations)
          .integer("save_failures", static_cast<std::int64_t>(g_result.save_failures))
          .flag("state_current", g_result.state_current)
          .text("mission_result", m.result.c_str())
          .text("mission_reason", m.reason.c_str())
          .integer("mission_collisions", m.collisions)
          .flag("mission_state_loadable", m.state_loadable)
          .text("mission_clear_estop_after", m.reset_seen.c_str())
          .text("mission_resume_after", m.resume_seen.c_str())
          .text("mission_held", m.held.c_str())
          .text("mission_back", m.back.c_str())
          .num("mission_cpu_s", m.cpu_s)
          .flag("passed", ok)
          .emit();
      table +=
          "| " + std::string(hal::sim::fault_device_name(device)) + " | " +
          hal::sim::fault_type_name(type) + " | " + cell(expected_text(e)) + " | " +
          cell(ran ? seen_text(e, g_result) : std::string("did not run: ") + g_result.error) +
          " | " + stopping_cells(e, g_result) + " | " + cell(e.mission) + " | " +
          cell("result=" + m.result + " reason=\"" + m.reason + "\"" +
               (m.collisions == 0                ? ""
                : device == FaultDevice::kBumper ? " (collisions=" + std::to_string(m.collisions) +
                                                       ": the faulted bumper's contacts)"
                                                 : ", COLLISIONS=" + std::to_string(m.collisions)) +
               (m.state_loadable ? "" : ", state file NOT loadable") +
               (m.held.empty() ? "" : "; mission log: `" + m.held + "`, `" + m.back + "`") +
               (!e.at_start               ? ""
                : m.start_warning.empty() ? "; NO start-up warning"
                                          : "; at start: `" + m.start_warning + "`") +
               (!e.operator_reset ? ""
                : m.reset_seen.empty()
                    ? "; clear-estop NOT typed (no telemetry line for it)"
                    : "; clear-estop typed after `" + telemetry_fields(m.reset_seen) + "`" +
                          (m.resume_seen.empty()
                               ? ", resume NOT typed (the mission never waited for it)"
                               : ", resume after `" + telemetry_fields(m.resume_seen) + "`"))) +
          " | " + (ok ? "ok" : "**FAILED**") + " |\n";
    }
  }
  char summary[128];
  std::snprintf(summary, sizeof summary, "\n%d of %d pairs as expected.\n", passed, pairs);
  table += summary;
  JsonLine(kSuite, "summary").integer("pairs", pairs).integer("passed", passed).emit();
  if (const char* doc = std::getenv("RELIABILITY_DOC"); doc != nullptr) {
    if (!write_table(doc, table)) return 1;
  }
  return passed == pairs ? 0 : 1;
}

}  // namespace boticelli::bench
