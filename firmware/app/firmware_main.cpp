// Firmware entry: options, board init, executive with the device tasks and the console, MISSION
// line.
#include "firmware/app/firmware_main.h"

#include <unistd.h>

#include <cerrno>
#include <csignal>
#include <cstdint>
#include <optional>
#include <cstdio>
#include <ctime>

#include "firmware/app/config_file.h"
#include "firmware/console/console.h"
#include "firmware/app/device_tasks.h"
#include "firmware/app/runtime.h"
#include "firmware/executive/executive.h"
#include "firmware/executive/host_timing_text.h"
#include "firmware/common/journal_forwarder.h"
#include "firmware/common/log.h"
#include "firmware/mission/mission.h"
#include "firmware/telemetry/map_export.h"
#include "firmware/telemetry/trace_writer.h"
#include "firmware/state/mission_state.h"
#include "firmware/app/options.h"
#include "firmware/common/parameters.h"
#include "firmware/state/persistence.h"
#include "firmware/executive/realtime.h"
#include "firmware/safety/safety.h"
#include "firmware/app/service_notify.h"
#include "firmware/telemetry/snapshot.h"
#include "firmware/state/state_saver.h"
#include "firmware/executive/task_table.h"
#include "firmware/app/last_gasp.h"
#include "firmware/common/text_buffer.h"

namespace boticelli::firmware {
namespace {

volatile std::sig_atomic_t g_signal = 0;

extern "C" void on_signal(int signal) {
  g_signal = signal;
}

const char* signal_name(int signal) {
  switch (signal) {
    case SIGINT:
      return "SIGINT";
    case SIGTERM:
      return "SIGTERM";
    case SIGHUP:
      return "SIGHUP";
    default:
      return "signal";
  }
}

double wall_seconds() {
  timespec ts{};
  ::clock_gettime(CLOCK_MONOTONIC, &ts);
  return static_cast<double>(ts.tv_sec) + static_cast<double>(ts.tv_nsec) * 1e-9;
}

// Static storage: nothing on the cyclic path allocates, and the large buffers (state, file
// image, console ring) stay off the stack.
MissionState g_state;
StateStore g_store;
ParameterTable g_parameters;
ConfigSchema g_config_keys;
mission::TraceWriter g_trace;
SnapshotWriter g_snapshots;
LogRing g_log_ring;
JournalForwarder g_journal;
// Stops the journal's thread on every way out of firmware_main (it writes what is queued).
struct JournalStop {
  ~JournalStop() { g_journal.stop(); }
};

// Everything that is bound to the board's devices, rebuilt in place for each run (static
// storage, no heap; firmware_main may be called again, e.g. by tests): the runtime, then the
// mission made on its safety latch, executive and saver.
std::optional<Runtime> g_runtime;
std::optional<mission::Mission> g_mission;
std::optional<mission::MissionTask> g_mission_task;

int fail(const char* what, const char* why) {
  service_log().log(LogLevel::kError, "%s%s%s", what, why[0] != '\0' ? ": " : "", why);
  return 1;
}

void warn_line(const char* message, void* /*context*/) {
  service_log().log(LogLevel::kWarn, "%s", message);
}

// The configuration file: --config FILE (must exist) or the board's default path (may be
// missing: the compiled-in defaults). False after logging the error.
bool apply_config(const Options& options, Board& board, char* error, std::size_t error_size) {
  ServiceLog& slog = service_log();
  g_config_keys.clear();
  if (!board.reset_config(g_config_keys)) {
    slog.log(LogLevel::kError, "configuration: key table full");
    return false;
  }
  const char* path =
      options.config_file != nullptr ? options.config_file : board.default_config_path();
  if (path == nullptr) return true;
  const ConfigLoad loaded = load_config_file(path, g_config_keys, error, error_size);
  if (loaded == ConfigLoad::kLoaded) {
    slog.log(LogLevel::kInfo, "configuration from %s", path);
    return true;
  }
  if (loaded == ConfigLoad::kMissing && options.config_file == nullptr) {
    slog.log(LogLevel::kInfo, "no %s: compiled-in defaults", path);
    return true;
  }
  slog.log(LogLevel::kError, "configuration: %s", error);
  return false;
}

// How old the resumed pose is: the robot is trusted to stand where it was saved (a hardware
// board cannot know it was moved), so say when that was.
void log_pose_age(const MissionState& state, std::int64_t now_ms) {
  ServiceLog& slog = service_log();
  const double x = static_cast<double>(state.pose.x_m);
  const double y = static_cast<double>(state.pose.y_m);
  const double yaw = static_cast<double>(state.pose.yaw_rad);
  if (state.pose_time_ms == 0 || now_ms == 0) {
    slog.log(LogLevel::kInfo, "resumed pose x=%.3f y=%.3f yaw=%.3f, its age unknown (%s)", x, y,
             yaw, now_ms == 0 ? "no wall clock on this board" : "saved without its time");
    return;
  }
  const double age_s = static_cast<double>(now_ms - state.pose_time_ms) * 1e-3;
  if (age_s < 0.0) {
    slog.log(LogLevel::kWarn,
             "resumed pose x=%.3f y=%.3f yaw=%.3f saved %.1f s in the future: the wall clock "
             "was set back since",
             x, y, yaw, -age_s);
    return;
  }
  // Older than a restart's few seconds: someone may have moved the robot meanwhile.
  constexpr double kFreshS = 60.0;
  slog.log(age_s <= kFreshS ? LogLevel::kInfo : LogLevel::kWarn,
           "resumed pose x=%.3f y=%.3f yaw=%.3f saved %.1f s ago%s", x, y, yaw, age_s,
           age_s <= kFreshS ? ""
                            : ": if the robot was moved since, its map is off (start a new "
                              "mission without --resume)");
}

}  // namespace

int firmware_main(int argc, const char* const* argv, Board& board, const MainHooks* hooks) {
  const double wall_start_s = wall_seconds();
  // Output to a closed pipe (`boticelli | head`, a log reader gone) must not kill the robot
  // with the base driving and no final save: with SIGPIPE ignored such a write fails with
  // EPIPE instead, which the stdio console (a port fault) and the printf()s here tolerate.
  std::signal(SIGPIPE, SIG_IGN);
  const BoardInfo& info = board.info();
  Options options;
  ServiceLog& slog = service_log();
  slog.open();
  g_log_ring.clear();
  slog.attach(&g_log_ring, nullptr);
  const ParseResult parsed = parse_options(argc, argv, info.simulated, options);
  if (!parsed.ok) {
    slog.log(LogLevel::kError, "%s", parsed.error);
    std::fputs(usage_text(), stderr);
    return 2;
  }
  if (options.show_help) {
    std::fputs(usage_text(), stdout);
    return 0;
  }
  std::printf("boticelli %s board=%s (%s)\n", BOTICELLI_VERSION, info.name, info.description);
  std::fflush(stdout);
  if (options.show_version) return 0;

  char error[384] = "";
  // A bad configuration is a usage error (2): the service is not restarted on it.
  if (!apply_config(options, board, error, sizeof error)) return 2;
  if (!board.init(options, error, sizeof error)) return fail(error, "");
  const BoardConfig& config = board.config();
  hal::Hal& hal = board.hal();
  slog.attach(&g_log_ring, &hal.clock);

  // Mission state: fresh, or resumed from --state DIR.
  StateStore* store = nullptr;
  if (options.state_dir != nullptr) {
    if (!g_store.open(options.state_dir, error, sizeof error)) {
      // A directory that must not be used (not a directory, another owner, writable by
      // others) is the operator's to fix: the usage code, which the unit does not restart on.
      const int code = fail(error, "");
      return g_store.refused() ? kExitUsage : code;
    }
    store = &g_store;
  }
  g_state.clear();
  g_state.seed = options.seed;
  if (options.resume) {
    // Nothing saved yet (first start of a service that always passes --resume): a new
    // mission. A file that is there but corrupt is never loaded and stops the start.
    const LoadResult loaded = g_store.load(g_state, error, sizeof error);
    if (loaded == LoadResult::kMissing) {
      g_state.clear();
      g_state.seed = options.seed;
      slog.log(LogLevel::kInfo, "%s: starting a new mission", error);
    } else if (loaded != LoadResult::kLoaded) {
      // No copy of the state loads. Restarting cannot mend the files: the usage code, which
      // the service unit does not restart on (RestartPreventExitStatus), so an operator
      // looks at them.
      (void)fail("cannot resume", error);
      return kExitUsage;
    } else {
      if (g_store.load_warning()[0] != '\0') {
        // A damaged copy (a bad card, a cut write): the other one costs a save at most.
        slog.log(LogLevel::kWarn, "state copy damaged: %s", g_store.load_warning());
      }
      if (!board.place_robot(g_state.pose, error, sizeof error))
        return fail("cannot resume", error);
      if (g_state.finished()) {
        slog.log(LogLevel::kWarn,
                 "the saved mission has ended (%s at cycle %llu: %s): not resumed, the robot "
                 "stays stopped; start without --resume for a new mission",
                 mission_end_name(g_state.end), static_cast<unsigned long long>(g_state.cycle),
                 g_state.end_reason.data());
      } else {
        slog.log(LogLevel::kInfo, "resumed from %s at cycle %llu", g_store.loaded_path(),
                 static_cast<unsigned long long>(g_state.cycle));
        log_pose_age(g_state, hal.clock.wall_time_ms());
      }
    }
  } else if (store != nullptr) {
    // A new mission never overwrites a saved one: it is kept as mission.state.1 (older ones
    // shift up), so a start without --resume by mistake loses nothing.
    char kept[520] = "";
    const LoadResult kept_result = g_store.keep_previous(kept, sizeof kept, error, sizeof error);
    if (kept_result == LoadResult::kIoError) return fail("state", error);
    if (kept_result == LoadResult::kLoaded) {
      slog.log(LogLevel::kWarn, "new mission: the saved one is kept as %s (--resume continues it)",
               kept);
    }
  }

  // Devices.
  if (!hal.console.open()) return fail("console", hal.console.error());
  if (!hal.base.init()) return fail("base", hal.base.error());
  // From here a crash still brakes the wheels (a kill -9 cannot be caught: the ODrives'
  // watchdog stops them then).
  LastGasp last_gasp;
  if (!last_gasp.arm(hal.base)) slog.log(LogLevel::kWarn, "no last-gasp stop on a crash");
  if (!hal.pan_tilt.init()) return fail("pan-tilt unit", hal.pan_tilt.error());
  if (!hal.camera.init()) return fail("camera", hal.camera.error());
  bool watchdog_armed = false;
  if (!config.watchdog_enabled) {
    // Only an explicit key switches it off, and every start says so.
    slog.log(LogLevel::kWarn,
             "hardware watchdog disabled by the configuration ([watchdog] enabled = false): a "
             "hang that systemd cannot end is not reset");
  } else {
    watchdog_armed = hal.watchdog.start(config.watchdog_timeout_ms);
    if (!watchdog_armed) {
      slog.log(LogLevel::kWarn, "watchdog not armed (%s)", hal.watchdog.error());
    }
  }
  if (options.trace_file != nullptr && !g_trace.open(options.trace_file, error, sizeof error)) {
    return fail(error, "");
  }
  if (options.snapshots_dir != nullptr &&
      !g_snapshots.open(options.snapshots_dir, error, sizeof error)) {
    return fail(error, "");
  }
  g_parameters = ParameterTable{};
  g_mission_task.reset();  // made on the last run's runtime: gone before it
  g_mission.reset();
  g_runtime.emplace(hal, hal.console, g_store, g_parameters, board.host_clock());
  Runtime& rt = *g_runtime;
  g_mission.emplace(mission::MissionContext{
      hal, config, rt.safety, rt.executive, g_state, store != nullptr ? &rt.saver : nullptr,
      board.truth(), options.trace_file != nullptr ? &g_trace : nullptr,
      options.snapshots_dir != nullptr ? &g_snapshots : nullptr, &rt.watchdog_task});
  mission::Mission& mission = *g_mission;
  g_mission_task.emplace(mission);
  const char* why = "";
  if (!rt.attach({*g_mission_task, mission, mission, mission}, &why)) {
    return fail("executive", why);
  }
  // On a real-time board the state is written by a thread of its own (fsync can take tens
  // of milliseconds on an SD card); on the simulation it is written in the background slot.
  if (store != nullptr && config.realtime) rt.saver.start();
  ServiceNotifier& notifier = rt.notifier;
  if (!notifier.open()) slog.log(LogLevel::kWarn, "%s", notifier.error());
  Executive& executive = rt.executive;
  Safety& safety = rt.safety;
  Console& console = *rt.console;
  console.set_log_ring(&g_log_ring, &hal.clock);
  // With stderr the journal, the console's log lines go there too (a thread writes them).
  JournalStop journal_stop;
  if (slog.to_journal() && g_journal.start(STDERR_FILENO)) console.set_journal(&g_journal);
  console.set_board_name(info.name);
  console.set_watchdog_state(watchdog_armed             ? Console::WatchdogState::kArmed
                             : !config.watchdog_enabled ? Console::WatchdogState::kDisabled
                                                        : Console::WatchdogState::kUnavailable);
  console.set_fault_injection(board.fault_injection());
  console.set_telemetry_ms(static_cast<float>(config.telemetry_period_ms));
  float background_slice_us = 0.0F;
  if (!console.register_parameters() ||
      !g_parameters.add({"bg_slice_us", &background_slice_us, 0.0F,
                         static_cast<float>(config.minor_frame_us), true,
                         "longest background slice [us], 0 = rest of the frame"})) {
    return fail("console parameters", "table full");
  }
  if (store != nullptr) {
    // The values `param save` kept: a file that is not TOML stops the start (2); a name the
    // table no longer has, or a value it refuses, is skipped with a warning.
    const ConfigLoad loaded = load_parameters_file(g_store.parameters_path(), g_parameters, error,
                                                   sizeof error, warn_line, nullptr);
    if (loaded == ConfigLoad::kInvalid) {
      slog.log(LogLevel::kError, "saved parameters: %s", error);
      return 2;
    }
    if (loaded == ConfigLoad::kLoaded) {
      slog.log(LogLevel::kInfo, "parameters from %s: %zu changed", g_store.parameters_path(),
               g_parameters.changed_count());
    }
    console.set_parameter_saver(&rt.saver);
  }

  if (config.realtime || options.realtime) {
    RealtimeConfig realtime;
    realtime.fifo_priority = config.fifo_priority;
    const RealtimeReport report = prepare_realtime(realtime);
    slog.log(report.fifo && report.memory_locked ? LogLevel::kInfo : LogLevel::kWarn, "%s",
             report.message);
  }

  struct sigaction action {};
  action.sa_handler = on_signal;
  sigemptyset(&action.sa_mask);
  sigaction(SIGINT, &action, nullptr);
  sigaction(SIGTERM, &action, nullptr);
  // A hang-up (the controlling terminal or the console's session gone) stops in the same
  // orderly way: base stopped, MISSION line; the default action would kill the process with
  // the base still driving.
  sigaction(SIGHUP, &action, nullptr);

  ExecutiveConfig exec_config;
  exec_config.frame_us = config.minor_frame_us;
  exec_config.background_units_per_slice = config.background_units_per_slice;
  if (options.host_slices) {
    // As on the robot: each slice ends by the clock (the host's), not after a count of units.
    exec_config.slices_on_host_clock = true;
    exec_config.background_units_per_slice = 0;
  }
  if (!executive.start(exec_config, &why)) return fail("executive", why);
  const std::uint64_t start_us = hal.clock.now_us();
  mission.start(start_us);
  console.log(LogLevel::kInfo, "boticelli %s on %s: ready", BOTICELLI_VERSION, info.name);
  if (options.state_dir != nullptr) {
    // A package upgrade restarted the firmware (postinst leaves DIR/start-held): held, as by
    // `pause`, until the operator's `resume`, once. A file that cannot be removed still holds.
    char held_path[520];
    std::snprintf(held_path, sizeof held_path, "%s/start-held", options.state_dir);
    if (::unlink(held_path) == 0 || errno != ENOENT) {
      executive.set_background_paused(true);
      slog.log(LogLevel::kWarn, "started held (%s, left by a package upgrade): type resume",
               held_path);
      console.log(LogLevel::kWarn, "started held (%s, left by a package upgrade): type resume",
                  held_path);
    }
  }
  // A mission that ended before this start is not carried on: the firmware stays up with the
  // robot stopped (console, status, LED) until it is stopped; with --max-cycles there is
  // nothing to run, so it ends at once.
  const bool ended_before = mission.ended_before_start();
  // The fault policy's give-up (a device unhealthy past its retry time) is for a running
  // mission: an ended one has nothing a restart would carry on.
  rt.watchdog_task.set_retry_us(
      ended_before ? UINT64_MAX
                   : static_cast<std::uint64_t>(static_cast<double>(config.device_retry_s) * 1e6));
  if (ended_before) {
    console.log(LogLevel::kWarn, "mission already ended (%s: %s): not resumed, robot stopped",
                mission::result_name(mission.result()), mission.end_reason());
  }
  notifier.ready();
  if (hooks != nullptr && hooks->loop_started != nullptr) hooks->loop_started(hooks->context);

  const char* stop_reason = "";
  TextBuffer<224> gave_up_reason;
  bool calibration_said = false;
  for (;;) {
    executive.set_background_max_slice_us(static_cast<std::uint32_t>(background_slice_us));
    executive.run_frame();
    if (hooks != nullptr && hooks->after_frame != nullptr) hooks->after_frame(hooks->context);
    if (!calibration_said && mission.calibration_suspect()) {
      // The calibration self-check's finding, on the console and in the journal, once.
      console.log(LogLevel::kWarn, "%s", mission.calibration_warning());
      calibration_said = true;
    }
    if (g_signal != 0) {
      stop_reason = signal_name(g_signal);
      break;
    }
    if (console.shutdown_requested()) {
      stop_reason = "console shutdown";
      break;
    }
    if (rt.watchdog_task.gave_up()) {
      // A device unhealthy for longer than its retry time: a restart re-opens everything.
      gave_up_reason.clear();
      gave_up_reason.appendf("gave up: %s", rt.watchdog_task.give_up_reason());
      stop_reason = gave_up_reason.c_str();
      break;
    }
    if (ended_before) {
      if (options.max_cycles != 0) {
        stop_reason = "mission already ended";
        break;
      }
      continue;
    }
    if (options.max_cycles != 0 && mission.cycles_this_run() >= options.max_cycles) {
      stop_reason = "max cycles";
      break;
    }
    if (mission.finished()) {
      stop_reason = mission.end_reason();
      break;
    }
  }
  if (hooks != nullptr && hooks->loop_ended != nullptr) {
    hooks->loop_ended(hooks->context, executive);
  }
  if (!mission.finished()) {
    // Stopped from outside: --max-cycles is the end of the search, anything else an abort.
    if (options.max_cycles != 0 && mission.cycles_this_run() >= options.max_cycles) {
      mission.finish_not_found("max cycles");
    } else {
      mission.abort(stop_reason);
    }
  }

  // Orderly stop: base and PTU halted, watchdog disarmed, console drained (bounded).
  notifier.stopping();
  hal.base.stop();
  hal.pan_tilt.halt();
  if (watchdog_armed) hal.watchdog.stop();
  hal.status_led.write(false);  // off: the firmware is not running
  console.send_final_telemetry(hal.clock.now_us());
  console.log(LogLevel::kInfo, "stopping: %s", stop_reason);
  console.log(LogLevel::kInfo,
              "mission cpu look_s=%.2f think_s=%.2f plan_s=%.2f register_s=%.3f registered=%u",
              mission.look_cpu_s(), mission.think_cpu_s(), mission.plan_cpu_s(),
              mission.register_cpu_s(), static_cast<unsigned>(mission.registered_looks()));
  {
    // The world memory: what it holds and costs, and how the frontier search went.
    const MapCounts m = mission.map_counts();
    console.log(LogLevel::kInfo,
                "mission map planner=%s grid_tiles=%u grid_bytes=%u free_m2=%.2f occupied_m2=%.2f "
                "grid_dropped=%u blacklisted=%u",
                mission.planner_name(), m.grid_tiles, m.grid_bytes, static_cast<double>(m.free_m2),
                static_cast<double>(m.occupied_m2), m.grid_dropped, m.blacklisted);
  }
  if (mission.calibration_bases() > 0) {
    console.log(LogLevel::kInfo,
                "mission calibration stereo_to_floor=%.3f bases=%u inverse_range_bias_per_m=%.4f",
                static_cast<double>(mission.calibration_ratio()),
                static_cast<unsigned>(mission.calibration_bases()),
                static_cast<double>(mission.stereo_inverse_range_bias()));
  }
  if (const OdometryCalibration c = mission.odometry_calibration(); c.intervals > 0) {
    // The base's odometry calibration the registrations show (`base-calibration`).
    console.log(LogLevel::kInfo,
                "mission base_calibration valid=%d intervals=%u turned_deg=%.0f driven_m=%.2f "
                "odometry_track_scale=%.4f sd=%.4f odometry_diameter_ratio=%.4f sd=%.4f",
                c.valid ? 1 : 0, c.intervals,
                static_cast<double>(c.turned_rad) * 180.0 / 3.14159265358979323846,
                static_cast<double>(c.driven_m), static_cast<double>(c.track_scale),
                static_cast<double>(c.track_scale_sd), static_cast<double>(c.diameter_ratio),
                static_cast<double>(c.diameter_ratio_sd));
  }
  if (mission.guard_truncated_looks() > 0) {
    console.log(LogLevel::kWarn, "mission guard_truncated_looks=%u (a full list dropped readings)",
                static_cast<unsigned>(mission.guard_truncated_looks()));
  }
  {
    // The longest unit of each kind [ms of host thread CPU]: what a slice or the mission
    // task's budget must hold on the robot.
    TextBuffer<256> line;
    line.append("mission longest_ms");
    for (std::size_t u = 0; u < static_cast<std::size_t>(mission::Unit::kCount); ++u) {
      const auto unit = static_cast<mission::Unit>(u);
      line.appendf(" %s=%.2f", mission::unit_name(unit), mission.longest_unit_s(unit) * 1e3);
    }
    console.log(LogLevel::kInfo, "%s", line.c_str());
  }
  {
    // The executive's figures on the host's clocks (docs/console.md, `stats`): what the
    // tasks, slices and frames took on this processor, whatever the board's clock says.
    for (std::size_t i = 0; i < host_timing_line_count(executive); ++i) {
      TextBuffer<256> line;
      append_host_timing_line(line, executive, i);
      console.log(LogLevel::kInfo, "%s", line.c_str());
    }
  }
  for (int i = 0; i < 50 && console.pending_output() > 0 && console.healthy(); ++i) {
    console.drain();
    hal.clock.sleep_until_us(hal.clock.now_us() + 2000U);
  }
  mission.finish_saving();
  if (options.map_prefix != nullptr &&
      !write_map_files(mission.grid(), options.map_prefix, error, sizeof error)) {
    slog.log(LogLevel::kError, "%s", error);
  }
  if (rt.saver.failures() > 0) {
    rt.saver.last_error(error, sizeof error);
    slog.log(LogLevel::kError, "%llu state saves failed, last: %s",
             static_cast<unsigned long long>(rt.saver.failures()), error);
  }
  if (g_trace.is_open() && !g_trace.close(error, sizeof error)) {
    slog.log(LogLevel::kError, "%s", error);
  }
  const double sim_time_s = static_cast<double>(hal.clock.now_us() - start_us) * 1e-6;
  const mission::Result result = mission.result();
  // A device given up on: the code the service unit restarts on (with --resume).
  const bool restart = rt.watchdog_task.gave_up() || mission.gave_up_on_device();
  if (restart) {
    slog.log(LogLevel::kError, "%s: exiting for a restart (--resume carries the mission on)",
             mission.end_reason());
  }
  // The reason last, quoted (it has spaces): why the mission ended, with the device's words
  // when a device ended it ("base stopped by itself: base: left axis: heartbeat lost ...").
  TextBuffer<160> reason;
  for (const char* c = mission.end_reason(); *c != '\0'; ++c) {
    reason.appendf("%c", *c == '"' ? '\'' : *c);
  }
  std::printf(
      "MISSION result=%s cycles=%llu collisions=%llu sim_time_s=%.3f wall_time_s=%.3f "
      "target_error_m=%.3f reason=\"%s\"\n",
      mission::result_name(result), static_cast<unsigned long long>(g_state.cycle),
      static_cast<unsigned long long>(safety.collisions()), sim_time_s,
      wall_seconds() - wall_start_s, static_cast<double>(mission.target_error_m()), reason.c_str());
  std::fflush(stdout);
  g_mission_task.reset();
  g_mission.reset();
  g_runtime.reset();
  g_signal = 0;
  if (restart) return kExitFailure;
  return result == mission::Result::kFound ? kExitFound : kExitNotFound;
}

}  // namespace boticelli::firmware
