// Tests of the rpi4 systemd unit against the firmware: which exit codes it restarts on, and that
// a hung firmware is restarted by systemd well before the hardware watchdog resets the board.
#include <cstdio>
#include <cstdlib>
#include <map>
#include <string>

#include "board_config.h"  // boards/rpi4: the hardware watchdog's timeout
#include "firmware/app/firmware_main.h"
#include "firmware/state/persistence.h"

#include "CppUTest/TestHarness.h"

namespace {

// The keys of one section of the shipped unit (the last value of a key repeated wins, as in
// systemd).
std::map<std::string, std::string> section_keys(const std::string& section) {
  std::map<std::string, std::string> keys;
  FILE* f = std::fopen(BOTICELLI_SOURCE_DIR "/boards/rpi4/packaging/boticelli.service", "r");
  if (f == nullptr) return keys;
  char line[512];
  bool in_service = false;
  while (std::fgets(line, sizeof line, f) != nullptr) {
    std::string s(line);
    while (!s.empty() && (s.back() == '\n' || s.back() == '\r')) s.pop_back();
    if (s.empty() || s[0] == '#') continue;
    if (s[0] == '[') {
      in_service = s == section;
      continue;
    }
    const std::size_t eq = s.find('=');
    if (in_service && eq != std::string::npos) keys[s.substr(0, eq)] = s.substr(eq + 1);
  }
  std::fclose(f);
  return keys;
}
std::map<std::string, std::string> service_keys() {
  return section_keys("[Service]");
}

// A systemd time span as the unit writes them: "2s", "500ms", "1.5s" or bare seconds [s].
double seconds(const std::string& span) {
  double value = 0.0;
  char unit[8] = "";
  if (std::sscanf(span.c_str(), "%lf%7s", &value, unit) < 1) return -1.0;
  const std::string u(unit);
  if (u.empty() || u == "s" || u == "sec") return value;
  if (u == "ms" || u == "msec") return value * 1e-3;
  if (u == "min") return value * 60.0;
  return -1.0;
}

bool has_word(const std::string& words, int code) {
  const std::string w = " " + words + " ";
  return w.find(" " + std::to_string(code) + " ") != std::string::npos;
}

}  // namespace

TEST_GROUP(ServiceUnit){};

TEST(ServiceUnit, DoesNotRestartOnTheExitCodesARestartCannotMendButDoesOnAFailure) {
  const auto keys = service_keys();
  CHECK_TEXT(keys.count("RestartPreventExitStatus") == 1, "no RestartPreventExitStatus");
  if (keys.count("RestartPreventExitStatus") == 0) return;
  const std::string& prevent = keys.at("RestartPreventExitStatus");
  // 2: usage, configuration or a saved state that cannot be loaded; 3: the mission ended.
  CHECK(has_word(prevent, boticelli::firmware::kExitUsage));
  CHECK(has_word(prevent, boticelli::firmware::kExitNotFound));
  CHECK_FALSE(has_word(prevent, boticelli::firmware::kExitFailure));
  STRCMP_EQUAL("on-failure", keys.at("Restart").c_str());
}

// A stop (systemd's SIGTERM, the console's shutdown) or a mission that ended without the target
// exits kExitNotFound: a clean end, so the unit is inactive afterwards, not "failed"; a usage
// or configuration error (kExitUsage) and a failure stay failures.
TEST(ServiceUnit, AStopOrAnEndedMissionLeavesTheUnitInactiveNotFailed) {
  const auto keys = service_keys();
  CHECK_TEXT(keys.count("SuccessExitStatus") == 1, "no SuccessExitStatus");
  if (keys.count("SuccessExitStatus") == 0) return;
  const std::string& success = keys.at("SuccessExitStatus");
  CHECK(has_word(success, boticelli::firmware::kExitNotFound));
  CHECK_FALSE(has_word(success, boticelli::firmware::kExitUsage));
  CHECK_FALSE(has_word(success, boticelli::firmware::kExitFailure));
}

// The fault policy's end (docs/reliability.md): a device given up on after its retry time
// exits kExitFailure, which the unit restarts; a fault that persists through restarts must end
// the service, so the start limit must be reachable by such restarts: StartLimitBurst of them
// (retry time + RestartSec + start-up each) fit in StartLimitIntervalSec.
TEST(ServiceUnit, ADeviceGivenUpOnIsRestartedAndOneThatPersistsThroughRestartsEndsTheService) {
  constexpr double kStartS = 3.0;
  const auto keys = service_keys();
  const auto unit = section_keys("[Unit]");
  CHECK_TEXT(unit.count("StartLimitIntervalSec") == 1 && unit.count("StartLimitBurst") == 1,
             "no StartLimitIntervalSec / StartLimitBurst in [Unit]");
  if (unit.count("StartLimitIntervalSec") == 0 || unit.count("StartLimitBurst") == 0) return;
  CHECK_FALSE(has_word(keys.at("RestartPreventExitStatus"), boticelli::firmware::kExitFailure));
  STRCMP_EQUAL("on-failure", keys.at("Restart").c_str());
  const double interval_s = seconds(unit.at("StartLimitIntervalSec"));
  const int burst = std::atoi(unit.at("StartLimitBurst").c_str());
  const double retry_s = static_cast<double>(boticelli::boards::rpi4::make_config().device_retry_s);
  const double one_s = retry_s + seconds(keys.at("RestartSec")) + kStartS;
  CHECK(burst >= 2);
  if (static_cast<double>(burst) * one_s > interval_s) {
    char why[200];
    std::snprintf(why, sizeof why,
                  "%d restarts of %.0f s each do not fit StartLimitIntervalSec %.0f s: a device "
                  "that never comes back is restarted for ever",
                  burst, one_s, interval_s);
    FAIL(why);
  }
}

// The chain after the firmware hangs (docs/flashing.md, "Watchdogs"): the last WATCHDOG=1 and
// the last /dev/watchdog kick are sent together; systemd notices after WatchdogSec, sends
// SIGABRT and SIGKILL after TimeoutAbortSec, waits RestartSec, and the new process must open
// /dev/watchdog (after its devices are up: at most kStartS) before the hardware timeout runs
// out, with kMarginS to spare. Otherwise the board resets instead of the service restarting.
TEST(ServiceUnit, AHungFirmwareIsRestartedWellInsideTheHardwareWatchdogTimeout) {
  constexpr double kStartS = 3.0;   // exec to /dev/watchdog opened (devices opened first)
  constexpr double kMarginS = 2.0;  // left over before the board would reset
  const auto keys = service_keys();
  CHECK(keys.count("WatchdogSec") == 1 && keys.count("RestartSec") == 1);
  if (keys.count("WatchdogSec") == 0 || keys.count("RestartSec") == 0) return;
  const double watchdog_s = seconds(keys.at("WatchdogSec"));
  // Without TimeoutAbortSec systemd waits TimeoutStopSec (default 90 s) before SIGKILL.
  const std::string abort_key = keys.count("TimeoutAbortSec") != 0  ? "TimeoutAbortSec"
                                : keys.count("TimeoutStopSec") != 0 ? "TimeoutStopSec"
                                                                    : "";
  const double abort_s = abort_key.empty() ? 90.0 : seconds(keys.at(abort_key));
  const double restart_s = seconds(keys.at("RestartSec"));
  CHECK(watchdog_s > 0.0 && abort_s > 0.0 && restart_s >= 0.0);
  const double hardware_s =
      static_cast<double>(boticelli::boards::rpi4::make_config().watchdog_timeout_ms) * 1e-3;
  // The BCM2711's watchdog cannot count beyond about 15 s.
  CHECK(hardware_s > 0.0 && hardware_s <= 15.0);
  const double chain_s = watchdog_s + abort_s + restart_s + kStartS;
  if (chain_s + kMarginS > hardware_s) {
    char why[200];
    std::snprintf(why, sizeof why,
                  "WatchdogSec %.1f + %s %.1f + RestartSec %.1f + start %.1f = %.1f s, hardware "
                  "watchdog %.1f s",
                  watchdog_s, abort_key.c_str(), abort_s, restart_s, kStartS, chain_s, hardware_s);
    FAIL(why);
  }
  // The firmware kicks every 100 ms: several kicks fit in systemd's interval.
  CHECK(watchdog_s >= 1.0);
}

// Not only the shipped timeout: every timeout the configuration file accepts
// ([watchdog] timeout_ms, BoardConfig::watchdog_min_timeout_ms and _max_) keeps the chain above
// with its margin, and none is beyond what the BCM2711 counts.
TEST(ServiceUnit, EveryWatchdogTimeoutTheConfigurationAcceptsLeavesTheRestartChainIntact) {
  constexpr double kStartS = 3.0;
  constexpr double kMarginS = 2.0;
  const auto keys = service_keys();
  CHECK(keys.count("WatchdogSec") == 1 && keys.count("RestartSec") == 1 &&
        keys.count("TimeoutAbortSec") == 1);
  if (keys.count("WatchdogSec") == 0 || keys.count("RestartSec") == 0 ||
      keys.count("TimeoutAbortSec") == 0) {
    return;
  }
  const double chain_s = seconds(keys.at("WatchdogSec")) + seconds(keys.at("TimeoutAbortSec")) +
                         seconds(keys.at("RestartSec")) + kStartS;
  const boticelli::firmware::BoardConfig c = boticelli::boards::rpi4::make_config();
  const double lowest_s = static_cast<double>(c.watchdog_min_timeout_ms) * 1e-3;
  if (chain_s + kMarginS > lowest_s) {
    char why[160];
    std::snprintf(why, sizeof why,
                  "the configuration accepts %.1f s, but the restart chain is %.1f s + %.1f s "
                  "to spare",
                  lowest_s, chain_s, kMarginS);
    FAIL(why);
  }
  CHECK(c.watchdog_max_timeout_ms <= 15000U);
  CHECK(c.watchdog_timeout_ms >= c.watchdog_min_timeout_ms &&
        c.watchdog_timeout_ms <= c.watchdog_max_timeout_ms);
}

// The firmware refuses a state directory its group or others may write in; the one systemd
// makes for the unit (StateDirectory=, owned by User=, StateDirectoryMode=, 0755 when not
// set) must pass, or the service would never start.
TEST(ServiceUnit, TheStateDirectorySystemdMakesIsOneTheFirmwareAccepts) {
  const auto keys = service_keys();
  CHECK_TEXT(keys.count("StateDirectory") == 1 && keys.count("ExecStart") == 1,
             "no StateDirectory or ExecStart");
  if (keys.count("StateDirectory") == 0 || keys.count("ExecStart") == 0) return;
  const std::string mode_text =
      keys.count("StateDirectoryMode") != 0 ? keys.at("StateDirectoryMode") : "0755";
  char* end = nullptr;
  const unsigned long mode = std::strtoul(mode_text.c_str(), &end, 8);
  CHECK_TEXT(end != mode_text.c_str() && *end == '\0' && mode <= 07777, mode_text.c_str());
  CHECK_TEXT(boticelli::firmware::state_dir_mode_is_safe(static_cast<unsigned>(mode)),
             mode_text.c_str());
  // The directory is the --state of ExecStart.
  STRCMP_CONTAINS(("--state /var/lib/" + keys.at("StateDirectory")).c_str(),
                  keys.at("ExecStart").c_str());
}
