// Console: the serial monitor — line commands, periodic telemetry and log lines over a
// hal::SerialPort.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <string_view>

#include "firmware/console/console_line.h"
#include "firmware/console/console_parser.h"
#include "firmware/executive/executive.h"
#include "firmware/console/fault_injection.h"
#include "firmware/common/journal_forwarder.h"
#include "firmware/common/log.h"
#include "firmware/telemetry/mission_view.h"
#include "firmware/common/parameters.h"
#include "firmware/safety/safety.h"
#include "firmware/state/state_saver.h"
#include "firmware/common/text_buffer.h"
#include "hal/serial_port.h"

namespace boticelli::firmware {

// Protocol (docs/console.md): one command per line; every command answers with its data
// lines and then "OK", or with exactly one line "ERR <reason>" and no other effect.
// Unsolicited lines start with "TLM " (telemetry) or "LOG " (log). Output lines end in CRLF.
class Console {
 public:
  static constexpr std::size_t kTxBytes = 12288;      // output ring
  static constexpr std::size_t kReplyBytes = 4096;    // one command's reply
  static constexpr std::size_t kReadChunkBytes = 64;  // bytes read per service() call

  Console(hal::SerialPort& port, Executive& executive, Safety& safety, MissionView& view,
          ParameterTable& parameters);
  Console(const Console&) = delete;
  Console& operator=(const Console&) = delete;

  // Registers the console's own parameters (telemetry_ms, echo); call once at init.
  bool register_parameters();
  // The ring `log show` reads and every log line goes to (also while not shown), stamped
  // with `clock`; and the board name `ver` reports. Optional, at init.
  void set_log_ring(LogRing* ring, hal::Clock* clock) {
    ring_ = ring;
    clock_ = clock;
  }
  // Where the log lines of info and above go besides the ring: the journal (the firmware
  // sets one when stderr is the journal), or nullptr. At init.
  void set_journal(JournalForwarder* journal) { journal_ = journal; }
  void set_board_name(const char* name) { board_name_ = name; }
  // The hardware watchdog's state, which `status` shows (`watchdog=`). At init.
  enum class WatchdogState : std::uint8_t {
    kArmed,        // armed, kicked while every task is healthy
    kDisabled,     // switched off by the configuration ([watchdog] enabled = false)
    kUnavailable,  // enabled, but the device could not be armed (the start-up log says why)
  };
  void set_watchdog_state(WatchdogState state) { watchdog_state_ = state; }
  // Where `param save` hands the changed parameters (written into the state directory by
  // the saver's thread); without one (no --state DIR) `param save` is refused. The console
  // also watches the same saver's mission-state saves: a failed one is a LOG error line at
  // once and makes the storage unhealthy (status, stats) until a save succeeds. At init.
  void set_parameter_saver(StateSaver* saver);
  // The board's fault injection for the `fault` command (the sim board), or nullptr. At init.
  void set_fault_injection(FaultInjection* faults) { faults_ = faults; }
  // The console task's body: flushes output, reads and executes input, sends telemetry.
  void service(std::uint64_t now_us);
  // Sends queued output only (no input, telemetry or health lines): for the shutdown drain.
  void drain() { flush(); }
  // One TLM line now, whatever the period (unless telemetry is off): at the orderly stop, the
  // state the mission ended in (a target confirmed in the mission's last second is shown).
  void send_final_telemetry(std::uint64_t now_us);
  // A log line ("LOG <level> <text>") when `level` is within the console's log level.
  void log(LogLevel level, const char* format, ...) __attribute__((format(printf, 3, 4)));

  bool shutdown_requested() const { return shutdown_requested_; }
  bool healthy() const { return !port_fault_; }
  // False while the newest mission-state save failed (disk full, directory unwritable).
  bool storage_healthy() const { return storage_healthy_; }
  // Every task (Executive::all_healthy) and the storage.
  bool robot_healthy() const { return storage_healthy_ && executive_.all_healthy(); }
  LogLevel log_level() const { return log_level_; }
  void set_echo(bool on) { echo_ = on ? 1.0F : 0.0F; }
  void set_telemetry_ms(float ms) { telemetry_ms_ = ms; }
  std::uint64_t lines_executed() const { return lines_; }
  std::uint64_t errors() const { return errors_; }
  std::uint64_t dropped_bytes() const { return dropped_bytes_; }
  std::size_t pending_output() const { return tx_used_; }

 private:
  struct Command {
    const char* name;
    const char* args;
    const char* help;
    void (Console::*handler)(const Words&);
  };

  void execute(std::string_view line);
  void reply_error(const char* reason);
  bool emit(std::string_view bytes);  // all or nothing into the ring
  // A TLM or LOG line: never inside a reply being streamed; with echo on, a half-typed line
  // is cleared first and typed again after it.
  bool emit_unsolicited(std::string_view line);
  bool streaming() const { return !model_pending_.empty() || log_streaming_; }
  void stream_log();
  void recall(bool older);
  std::size_t tx_free() const { return kTxBytes - tx_used_; }
  void flush();
  void stream_model();
  void check_executive(std::uint64_t now_us);
  void check_state_saves();
  void append_unhealthy(TextBufferBase& out) const;
  void send_telemetry(std::uint64_t now_us);
  void emit_telemetry(std::uint64_t now_us);

  void cmd_help(const Words& w);
  void cmd_status(const Words& w);
  void cmd_stats(const Words& w);
  void cmd_pose(const Words& w);
  void cmd_model(const Words& w);
  void cmd_map(const Words& w);
  void cmd_base_calibration(const Words& w);
  void cmd_camera_calibration(const Words& w);
  void cmd_pause(const Words& w);
  void cmd_resume(const Words& w);
  void cmd_estop(const Words& w);
  void cmd_clear_estop(const Words& w);
  void cmd_get(const Words& w);
  void cmd_set(const Words& w);
  void cmd_log(const Words& w);
  void cmd_param(const Words& w);
  void check_parameter_saves();
  void cmd_ver(const Words& w);
  void cmd_shutdown(const Words& w);
  void cmd_fault(const Words& w);
  void append_parameter(const Parameter& p);

  static const Command kCommands[];

  hal::SerialPort& port_;
  Executive& executive_;
  Safety& safety_;
  MissionView& view_;
  ParameterTable& parameters_;

  LineAssembler line_;
  CommandHistory history_;
  std::array<std::uint8_t, kReadChunkBytes> rx_{};
  std::size_t rx_pos_ = 0;
  std::size_t rx_len_ = 0;

  std::array<char, kTxBytes> tx_{};
  std::size_t tx_head_ = 0;  // next byte to send
  std::size_t tx_used_ = 0;
  TextBuffer<kReplyBytes> reply_;

  std::string_view model_pending_;  // rest of a `model` reply still to be queued
  LogRing* ring_ = nullptr;
  JournalForwarder* journal_ = nullptr;
  hal::Clock* clock_ = nullptr;
  const char* board_name_ = "?";
  WatchdogState watchdog_state_ = WatchdogState::kUnavailable;
  bool log_streaming_ = false;  // a `log show` or `log mission` reply is being queued
  bool log_mission_ = false;    // ... and it is `log mission` (the mission log, by line number)
  std::uint64_t log_next_ = 0;  // its next line's sequence number in the ring
  std::uint64_t log_end_ = 0;   // one past its last

  StateSaver* parameter_saver_ = nullptr;
  FaultInjection* faults_ = nullptr;
  std::array<char, ParameterTable::kMaxFileBytes> parameter_text_{};  // `param save`'s file
  std::uint64_t seen_parameter_saves_ = 0;
  std::uint64_t seen_parameter_failures_ = 0;

  float telemetry_ms_ = 1000.0F;  // 0 = off
  float echo_ = 0.0F;             // 1 = echo typed characters (for terminals without local echo)
  std::uint64_t next_telemetry_us_ = 0;
  std::uint64_t now_us_ = 0;
  std::uint64_t start_us_ = 0;
  bool started_ = false;
  LogLevel log_level_ = LogLevel::kInfo;
  bool shutdown_requested_ = false;
  bool port_fault_ = false;
  std::uint64_t lines_ = 0;
  std::uint64_t errors_ = 0;
  std::uint64_t dropped_bytes_ = 0;
  std::uint64_t seen_frame_overruns_ = 0;
  std::uint64_t seen_background_overruns_ = 0;
  std::uint64_t next_overrun_log_us_ = 0;
  // Per task: the reason last logged while it was unhealthy (empty: logged healthy), and
  // when, so a reason that keeps changing is logged at most once a second.
  std::array<TextBuffer<96>, Executive::kMaxTasks> logged_reason_{};
  std::array<std::uint64_t, Executive::kMaxTasks> logged_at_us_{};
  std::uint64_t seen_state_saves_ = 0;
  std::uint64_t seen_state_failures_ = 0;
  bool storage_healthy_ = true;
  StopCause logged_cause_ = StopCause::kNone;
  bool logged_awaiting_resume_ = false;
};

}  // namespace boticelli::firmware
