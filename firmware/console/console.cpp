// Console: command execution, telemetry and output buffering (see console.h, docs/console.md).
#include "firmware/console/console.h"

#include <cmath>
#include <cstdarg>
#include <cstring>

#include "firmware/executive/host_timing_text.h"

namespace boticelli::firmware {
namespace {

constexpr std::string_view kEol = "\r\n";
static_assert(LogRing::kLines == 64, "the `log show N` error message names the ring's size");

}  // namespace

const Console::Command Console::kCommands[] = {
    {"help", "", "list the commands", &Console::cmd_help},
    {"status", "", "state, e-stop, pause, what it waits for, health, cycles, uptime",
     &Console::cmd_status},
    {"stats", "[reset]", "executive timing per task, frame jitter, background use",
     &Console::cmd_stats},
    {"pose", "", "robot pose in the world frame", &Console::cmd_pose},
    {"model", "", "the occupancy ALN in the text format", &Console::cmd_model},
    {"map", "", "world memory (grid) summary, frontiers, goal, polygon, target", &Console::cmd_map},
    {"base-calibration", "",
     "the odometry's track scale and wheel diameter ratio the looks' registrations show",
     &Console::cmd_base_calibration},
    {"camera-calibration", "",
     "the camera rig's calibration as the floor shows it, and the stereo's correction",
     &Console::cmd_camera_calibration},
    {"pause", "", "pause the background work (mission)", &Console::cmd_pause},
    {"resume", "", "after pause or clear-estop: the background work and the base go on",
     &Console::cmd_resume},
    {"estop", "", "stop the base now and latch the e-stop", &Console::cmd_estop},
    {"clear-estop", "", "reset the e-stop latch when no input is active (then resume)",
     &Console::cmd_clear_estop},
    {"get", "[NAME]", "show one or every parameter", &Console::cmd_get},
    {"set", "NAME VALUE", "set a parameter (range checked)", &Console::cmd_set},
    {"log", "[LEVEL|show [N]]", "log level (error|warn|info|debug), or the last N log lines",
     &Console::cmd_log},
    {"log", "mission [N]", "the last N lines of the mission log (kept in the state file)",
     &Console::cmd_log},
    {"param", "show|save", "parameters changed from their defaults; save them for restarts",
     &Console::cmd_param},
    {"fault", "[DEVICE TYPE [SECONDS]]",
     "inject a device fault (sim board), or list the active ones", &Console::cmd_fault},
    {"ver", "", "firmware version and board", &Console::cmd_ver},
    {"shutdown", "", "stop the firmware in an orderly way", &Console::cmd_shutdown},
    {"quit", "", "same as shutdown", &Console::cmd_shutdown},
};

Console::Console(hal::SerialPort& port, Executive& executive, Safety& safety, MissionView& view,
                 ParameterTable& parameters)
    : port_(port), executive_(executive), safety_(safety), view_(view), parameters_(parameters) {}

bool Console::register_parameters() {
  return parameters_.add({"telemetry_ms", &telemetry_ms_, 0.0F, 60000.0F, true,
                          "telemetry period [ms], 0 = off"}) &&
         parameters_.add({"echo", &echo_, 0.0F, 1.0F, true, "echo typed characters (0/1)"});
}

void Console::set_parameter_saver(StateSaver* saver) {
  parameter_saver_ = saver;
  if (saver != nullptr) {
    seen_parameter_saves_ = saver->parameter_saves();
    seen_parameter_failures_ = saver->parameter_failures();
    seen_state_saves_ = saver->saved();
    seen_state_failures_ = saver->failures();
  }
}

bool Console::emit(std::string_view bytes) {
  if (bytes.size() > tx_free()) {
    dropped_bytes_ += bytes.size();
    return false;
  }
  std::size_t tail = (tx_head_ + tx_used_) % kTxBytes;
  for (const char c : bytes) {
    tx_[tail] = c;
    tail = tail + 1 == kTxBytes ? 0 : tail + 1;
  }
  tx_used_ += bytes.size();
  return true;
}

void Console::flush() {
  while (tx_used_ > 0 && !port_fault_) {
    const std::size_t chunk = tx_head_ + tx_used_ <= kTxBytes ? tx_used_ : kTxBytes - tx_head_;
    const std::ptrdiff_t n =
        port_.write(reinterpret_cast<const std::uint8_t*>(tx_.data() + tx_head_), chunk);
    if (n < 0) {
      port_fault_ = true;
      return;
    }
    if (n == 0) return;
    const std::size_t sent = static_cast<std::size_t>(n);
    tx_head_ = (tx_head_ + sent) % kTxBytes;
    tx_used_ -= sent;
    if (sent < chunk) return;
  }
}

void Console::reply_error(const char* reason) {
  ++errors_;
  reply_.clear();
  reply_.appendf("ERR %s", reason);
  reply_.append(kEol);
  emit(reply_.view());
}

bool Console::emit_unsolicited(std::string_view line) {
  if (streaming()) return false;  // never inside a reply
  const std::string_view typed = echo_ != 0.0F ? line_.typed() : std::string_view{};
  if (typed.empty()) return emit(line);
  // Carriage return and erase to the end of the line (VT100, what picocom's terminal
  // understands), the line, then the half-typed command again.
  constexpr std::string_view kClearLine = "\r\x1b[K";
  if (kClearLine.size() + line.size() + typed.size() > tx_free()) {
    dropped_bytes_ += line.size();
    return false;
  }
  emit(kClearLine);
  emit(line);
  emit(typed);
  return true;
}

void Console::log(LogLevel level, const char* format, ...) {
  // The ring keeps info and above whatever the console's level (debug only when shown).
  const bool keep = ring_ != nullptr && (level <= LogLevel::kInfo || level <= log_level_);
  if (level > log_level_ && !keep) return;
  TextBuffer<256> text;
  text.appendf("LOG %s ", log_level_name(level));
  const std::size_t prefix = text.size();
  std::va_list args;
  va_start(args, format);
  text.vappendf(format, args);
  va_end(args);
  if (keep) {
    ring_->add(clock_ != nullptr ? clock_->now_us() : now_us_, level, text.view().substr(prefix));
  }
  // Faults at run time reach the journal too, under their level (not only the console).
  if (journal_ != nullptr && level <= LogLevel::kInfo) {
    (void)journal_->push(level, text.view().substr(prefix));
  }
  if (level > log_level_) return;
  if (text.size() > 256 - 3) return;  // never cut a line in the middle of the protocol
  text.append(kEol);
  emit_unsolicited(text.view());
}

void Console::service(std::uint64_t now_us) {
  now_us_ = now_us;
  if (!started_) {
    started_ = true;
    start_us_ = now_us;
    next_telemetry_us_ = now_us;
    next_overrun_log_us_ = now_us;
  }
  flush();
  stream_model();
  stream_log();
  line_.set_recall(echo_ != 0.0F);
  // Input is taken only while a full reply fits, so replies are never cut (the serial
  // driver keeps the bytes meanwhile).
  while (!streaming() && tx_free() >= kReplyBytes + 8) {
    if (rx_pos_ == rx_len_) {
      if (port_fault_) break;
      const std::ptrdiff_t n = port_.read(rx_.data(), rx_.size());
      if (n < 0) {
        port_fault_ = true;
        break;
      }
      if (n == 0) break;
      rx_pos_ = 0;
      rx_len_ = static_cast<std::size_t>(n);
    }
    const LineEvent event = line_.feed(rx_[rx_pos_++]);
    if (echo_ != 0.0F && !line_.echo().empty()) emit(line_.echo());
    switch (event) {
      case LineEvent::kNone:
      case LineEvent::kCancelled:
        break;
      case LineEvent::kOlder:
      case LineEvent::kNewer:
        recall(event == LineEvent::kOlder);
        break;
      case LineEvent::kTooLong:
        reply_error("line too long");
        break;
      case LineEvent::kBadByte:
        reply_error("bad character in line");
        break;
      case LineEvent::kLine:
        history_.add(line_.line());
        execute(line_.line());
        stream_model();
        stream_log();
        break;
    }
  }
  check_executive(now_us);
  check_parameter_saves();
  check_state_saves();
  send_telemetry(now_us);
  flush();
}

void Console::recall(bool older) {
  std::string_view text;
  if (!(older ? history_.older(text) : history_.newer(text))) return;
  line_.replace(text);
  // Show the recalled line in place of the one typed (CR, erase to end of line, the text).
  constexpr std::string_view kClearLine = "\r\x1b[K";
  if (kClearLine.size() + text.size() <= tx_free()) {
    emit(kClearLine);
    emit(text);
  }
}

void Console::execute(std::string_view line) {
  ++lines_;
  Words words;
  if (!split_words(line, words)) {
    reply_error("too many arguments");
    return;
  }
  if (words.count == 0) return;
  for (const Command& c : kCommands) {
    if (words.word[0] == c.name) {
      reply_.clear();
      (this->*c.handler)(words);
      return;
    }
  }
  reply_error("unknown command (try help)");
}

// Each handler either fills reply_ and ends it with OK, or calls reply_error() alone.
namespace {
bool no_args(const Words& w) {
  return w.count == 1;
}
}  // namespace

void Console::cmd_help(const Words& w) {
  if (!no_args(w)) return reply_error("help takes no arguments");
  for (const Command& c : kCommands) {
    reply_.appendf("%-12s %-24s %s\r\n", c.name, c.args, c.help);
  }
  reply_.append("OK\r\n");
  emit(reply_.view());
}

namespace {

// " target=none", or " target=seen|confirmed target_x_m=… target_y_m=… target_z_m=… sightings=N".
void append_target(TextBufferBase& out, const TargetEstimate& t) {
  out.appendf(" target=%s", target_status_name(t.status));
  if (t.status == TargetStatus::kNone) return;
  out.appendf(" target_x_m=%.3f target_y_m=%.3f target_z_m=%.3f sightings=%u",
              static_cast<double>(t.x_m), static_cast<double>(t.y_m), static_cast<double>(t.z_m),
              t.sightings);
}

}  // namespace

const char* goal_kind_name(GoalKind kind) {
  switch (kind) {
    case GoalKind::kNone:
      return "none";
    case GoalKind::kFrontier:
      return "frontier";
    case GoalKind::kTarget:
      return "target";
  }
  return "unknown";
}

const char* target_status_name(TargetStatus status) {
  switch (status) {
    case TargetStatus::kNone:
      return "none";
    case TargetStatus::kSeen:
      return "seen";
    case TargetStatus::kConfirmed:
      return "confirmed";
  }
  return "unknown";
}

void Console::cmd_status(const Words& w) {
  if (!no_args(w)) return reply_error("status takes no arguments");
  const FrameStats& f = executive_.frame_stats();
  const MapCounts m = view_.map_counts();
  const bool paused = executive_.background_paused();
  reply_.appendf("status state=%s estop=%s paused=%d waits_for=%s healthy=%d", view_.state_name(),
                 stop_cause_name(safety_.cause()), paused ? 1 : 0, awaited_command(safety_, paused),
                 robot_healthy() ? 1 : 0);
  append_unhealthy(reply_);
  reply_.appendf(" watchdog=%s", watchdog_state_ == WatchdogState::kArmed      ? "armed"
                                 : watchdog_state_ == WatchdogState::kDisabled ? "disabled"
                                                                               : "unavailable");
  reply_.appendf(" cycles=%llu pieces=%u features=%u obstacle_points=%u exploration_points=%u",
                 static_cast<unsigned long long>(view_.cycles()), view_.pieces(), view_.features(),
                 m.obstacle_points, m.exploration_points);
  append_target(reply_, view_.target());
  reply_.appendf(" frames=%llu uptime_s=%.1f\r\nOK\r\n", static_cast<unsigned long long>(f.frames),
                 static_cast<double>(now_us_ - start_us_) * 1e-6);
  emit(reply_.view());
}

void Console::cmd_stats(const Words& w) {
  if (w.count == 2 && w.word[1] == "reset") {
    executive_.reset_stats();
    seen_frame_overruns_ = 0;
    seen_background_overruns_ = 0;
    reply_.append("OK\r\n");
    emit(reply_.view());
    return;
  }
  if (!no_args(w)) return reply_error("stats takes no argument or 'reset'");
  for (std::size_t i = 0; i < executive_.task_count(); ++i) {
    const TaskSpec& s = executive_.spec(i);
    const TaskStats& t = executive_.task_stats(i);
    const char* why = executive_.task_health(i);
    reply_.appendf(
        "task %-8s period_us=%u budget_us=%u runs=%llu avg_us=%llu worst_us=%u overruns=%llu "
        "healthy=%d",
        s.name, s.period_us, s.budget_us, static_cast<unsigned long long>(t.runs),
        static_cast<unsigned long long>(t.average_us()), t.worst_us,
        static_cast<unsigned long long>(t.overruns), why == nullptr ? 1 : 0);
    if (why != nullptr) reply_.appendf(" why=\"%s\"", why);
    reply_.append(kEol);
  }
  if (parameter_saver_ != nullptr) {
    reply_.appendf("storage saved=%llu failed=%llu healthy=%d\r\n",
                   static_cast<unsigned long long>(parameter_saver_->saved()),
                   static_cast<unsigned long long>(parameter_saver_->failures()),
                   storage_healthy_ ? 1 : 0);
  }
  const FrameStats& f = executive_.frame_stats();
  reply_.appendf(
      "frame frame_us=%u frames=%llu overruns=%llu missed=%llu jitter_avg_us=%llu "
      "jitter_worst_us=%u\r\n"
      "background util_pct=%.1f slices=%llu overruns=%llu done=%llu paused=%d\r\n",
      executive_.config().frame_us, static_cast<unsigned long long>(f.frames),
      static_cast<unsigned long long>(f.overruns), static_cast<unsigned long long>(f.missed_frames),
      static_cast<unsigned long long>(f.jitter_average_us()), f.jitter_worst_us,
      static_cast<double>(f.background_per_mille()) / 10.0,
      static_cast<unsigned long long>(f.background_slices),
      static_cast<unsigned long long>(f.background_overruns),
      static_cast<unsigned long long>(f.background_done), executive_.background_paused() ? 1 : 0);
  // The same work on the host's clocks, beside the board's (on the sim board the board's
  // time stands still while the host computes).
  for (std::size_t line = 0; line < host_timing_line_count(executive_); ++line) {
    append_host_timing_line(reply_, executive_, line);
    reply_.append(kEol);
  }
  reply_.append("OK\r\n");
  if (reply_.truncated()) return reply_error("stats reply too long");
  emit(reply_.view());
}

void Console::cmd_pose(const Words& w) {
  if (!no_args(w)) return reply_error("pose takes no arguments");
  const core::Pose2 p = view_.pose();
  reply_.appendf("pose x_m=%.3f y_m=%.3f yaw_rad=%.4f\r\nOK\r\n", static_cast<double>(p.x_m),
                 static_cast<double>(p.y_m), static_cast<double>(p.yaw_rad));
  emit(reply_.view());
}

void Console::cmd_model(const Words& w) {
  if (!no_args(w)) return reply_error("model takes no arguments");
  const std::string_view text = view_.model_text();
  if (text.empty()) {
    view_.release_model_text();
    return reply_error("no model yet");
  }
  model_pending_ = text;
}

void Console::stream_model() {
  if (model_pending_.empty()) return;
  // Queue the text in pieces as the ring drains; then end the reply. Each piece ends at a
  // newline at the latest, and a bare LF (the ALN writer's line end) goes out as CRLF like
  // every console line; a CR LF in the text is kept as it is (never split between pieces).
  while (!model_pending_.empty()) {
    const std::size_t room = tx_free();
    if (room < 64) return;
    std::size_t n = model_pending_.size() < room - 32 ? model_pending_.size() : room - 32;
    const std::size_t nl = model_pending_.substr(0, n).find('\n');
    if (nl != std::string_view::npos) {
      n = nl + 1;
      if (nl > 0 && model_pending_[nl - 1] == '\r') {
        emit(model_pending_.substr(0, n));
      } else {
        emit(model_pending_.substr(0, nl));
        emit(kEol);
      }
    } else {
      if (n < model_pending_.size() && model_pending_[n - 1] == '\r') --n;
      emit(model_pending_.substr(0, n));
    }
    model_pending_.remove_prefix(n);
    if (model_pending_.empty()) {
      // The text's last byte decides whether a line end is due.
      break;
    }
    flush();
  }
  // Close the reply. The provider's text normally ends with a newline; add CRLF if not.
  if (tx_used_ > 0) {
    const std::size_t last = (tx_head_ + tx_used_ + kTxBytes - 1) % kTxBytes;
    if (tx_[last] != '\n') emit(kEol);
  }
  emit("OK\r\n");
  view_.release_model_text();  // all of it is queued: a newer model may replace it now
}

void Console::cmd_map(const Words& w) {
  if (!no_args(w)) return reply_error("map takes no arguments");
  const MapCounts m = view_.map_counts();
  reply_.appendf("map polygon_vertices=%u obstacle_points=%u exploration_points=%u",
                 m.polygon_vertices, m.obstacle_points, m.exploration_points);
  reply_.appendf(" grid_tiles=%u grid_bytes=%u free_m2=%.2f occupied_m2=%.2f grid_dropped=%u",
                 m.grid_tiles, m.grid_bytes, static_cast<double>(m.free_m2),
                 static_cast<double>(m.occupied_m2), m.grid_dropped);
  reply_.appendf(" frontiers=%u blacklisted=%u goal=%s", m.frontiers, m.blacklisted,
                 goal_kind_name(m.goal));
  if (m.goal != GoalKind::kNone) {
    reply_.appendf(" goal_x_m=%.3f goal_y_m=%.3f goal_path_m=%.2f", static_cast<double>(m.goal_x_m),
                   static_cast<double>(m.goal_y_m), static_cast<double>(m.goal_path_m));
  }
  append_target(reply_, view_.target());
  reply_.append("\r\nOK\r\n");
  emit(reply_.view());
}

void Console::cmd_base_calibration(const Words& w) {
  if (!no_args(w)) return reply_error("base-calibration takes no arguments");
  const OdometryCalibration c = view_.odometry_calibration();
  reply_.appendf("base-calibration intervals=%u turned_deg=%.0f driven_m=%.2f", c.intervals,
                 static_cast<double>(c.turned_rad) * 180.0 / 3.14159265358979323846,
                 static_cast<double>(c.driven_m));
  if (c.valid) {
    reply_.appendf(" odometry_track_scale=%.4f sd=%.4f odometry_diameter_ratio=%.4f sd=%.4f",
                   static_cast<double>(c.track_scale), static_cast<double>(c.track_scale_sd),
                   static_cast<double>(c.diameter_ratio), static_cast<double>(c.diameter_ratio_sd));
  } else {
    reply_.append(
        " not enough yet (4 intervals, 360 deg turned and 2 m driven, with register_looks)");
  }
  reply_.append("\r\nOK\r\n");
  emit(reply_.view());
}

void Console::cmd_camera_calibration(const Words& w) {
  if (!no_args(w)) return reply_error("camera-calibration takes no arguments");
  const CameraCalibration c = view_.camera_calibration();
  reply_.appendf("camera-calibration bases=%u", c.bases);
  if (c.bases > 0) {
    reply_.appendf(" stereo_to_floor=%.3f", static_cast<double>(c.stereo_to_floor));
  } else {
    reply_.append(" no check yet (30 stereo points low on obstacles whose base the floor shows)");
  }
  reply_.appendf(
      " self_calibration=%s inverse_range_bias_per_m=%.4f focal_scale=%.4f "
      "tilt_step_error_deg=%.3f",
      c.self_calibrating ? "on" : "off", static_cast<double>(c.inverse_range_bias_per_m),
      static_cast<double>(c.focal_scale),
      static_cast<double>(c.tilt_step_error_rad) * 180.0 / 3.14159265358979323846);
  reply_.append("\r\nOK\r\n");
  emit(reply_.view());
}

void Console::cmd_pause(const Words& w) {
  if (!no_args(w)) return reply_error("pause takes no arguments");
  executive_.set_background_paused(true);
  emit("OK\r\n");
}

void Console::cmd_resume(const Words& w) {
  if (!no_args(w)) return reply_error("resume takes no arguments");
  // After an e-stop's reset the base goes on only now; refused while the latch is engaged.
  if (const char* why = safety_.resume(); why != nullptr) return reply_error(why);
  executive_.set_background_paused(false);
  emit("OK\r\n");
}

void Console::cmd_estop(const Words& w) {
  if (!no_args(w)) return reply_error("estop takes no arguments");
  safety_.engage(StopCause::kConsole);
  emit("OK\r\n");
}

void Console::cmd_clear_estop(const Words& w) {
  if (!no_args(w)) return reply_error("clear-estop takes no arguments");
  if (const char* why = safety_.clear(); why != nullptr) return reply_error(why);
  emit("OK\r\n");
}

void Console::append_parameter(const Parameter& p) {
  reply_.appendf("%s=%g range=[%g,%g] %s\r\n", p.name, static_cast<double>(*p.value),
                 static_cast<double>(p.min), static_cast<double>(p.max), p.help);
}

void Console::cmd_get(const Words& w) {
  if (w.count > 2) return reply_error("get takes at most one NAME");
  if (w.count == 2) {
    const Parameter* p = parameters_.find(w.word[1]);
    if (p == nullptr) return reply_error("unknown parameter");
    append_parameter(*p);
  } else {
    for (std::size_t i = 0; i < parameters_.size(); ++i) append_parameter(parameters_[i]);
  }
  if (reply_.truncated()) return reply_error("reply too long");
  reply_.append("OK\r\n");
  emit(reply_.view());
}

void Console::cmd_set(const Words& w) {
  if (w.count != 3) return reply_error("usage: set NAME VALUE");
  float value = 0.0F;
  if (parameters_.find(w.word[1]) == nullptr) return reply_error("unknown parameter");
  if (!parse_number(w.word[2], value)) return reply_error("value is not a number");
  if (const char* why = parameters_.set(w.word[1], value); why != nullptr) {
    return reply_error(why);
  }
  if (w.word[1] == "telemetry_ms") next_telemetry_us_ = now_us_;
  emit("OK\r\n");
}

void Console::cmd_ver(const Words& w) {
  if (!no_args(w)) return reply_error("ver takes no arguments");
  reply_.appendf("ver version=%s board=%s\r\nOK\r\n", BOTICELLI_VERSION, board_name_);
  emit(reply_.view());
}

void Console::stream_log() {
  if (!log_streaming_) return;
  // One whole line at a time as the output ring drains; lines overwritten (the log ring) or
  // dropped (the mission log) since the command are skipped.
  while (log_next_ < log_end_) {
    TextBuffer<LogRing::kTextBytes + MissionLogEntry::kMaxTextBytes + 48> line;
    if (log_mission_) {
      const MissionLogEntry* e = view_.mission_log_line(log_next_);
      if (e == nullptr) {
        ++log_next_;
        continue;
      }
      line.appendf("mission cycle=%llu ", static_cast<unsigned long long>(e->cycle));
      line.append(e->view());
    } else {
      const LogRing::Entry* e = ring_->find(log_next_);
      if (e == nullptr) {
        ++log_next_;
        continue;
      }
      const auto since_start_us =
          static_cast<double>(static_cast<std::int64_t>(e->t_us - start_us_));
      line.appendf("log t_s=%.3f %s ", since_start_us * 1e-6, log_level_name(e->level));
      line.append(e->view());
    }
    line.append(kEol);
    if (line.size() + 8 > tx_free()) return;
    emit(line.view());
    ++log_next_;
  }
  if (tx_free() < 8) return;
  emit("OK\r\n");
  log_streaming_ = false;
}

void Console::cmd_log(const Words& w) {
  if (w.count >= 2 && w.word[1] == "show") {
    if (ring_ == nullptr) return reply_error("no log ring");
    std::uint64_t n = LogRing::kLines;
    if (w.count > 3) return reply_error("usage: log show [N]");
    if (w.count == 3) {
      float value = 0.0F;
      if (!parse_number(w.word[2], value) || !(value >= 1.0F) ||
          value > static_cast<float>(LogRing::kLines) || std::nearbyint(value) != value) {
        return reply_error("N must be a whole number from 1 to 64");
      }
      n = static_cast<std::uint64_t>(value);
    }
    log_end_ = ring_->end_sequence();
    const std::uint64_t kept = ring_->size();
    log_next_ = log_end_ - (n < kept ? n : kept);
    log_mission_ = false;
    log_streaming_ = true;
    return;
  }
  if (w.count >= 2 && w.word[1] == "mission") {
    static_assert(MissionState::kMaxLogEntries == 128, "the error message names the capacity");
    std::uint64_t n = MissionState::kMaxLogEntries;
    if (w.count > 3) return reply_error("usage: log mission [N]");
    if (w.count == 3) {
      float value = 0.0F;
      if (!parse_number(w.word[2], value) || !(value >= 1.0F) ||
          value > static_cast<float>(MissionState::kMaxLogEntries) ||
          std::nearbyint(value) != value) {
        return reply_error("N must be a whole number from 1 to 128");
      }
      n = static_cast<std::uint64_t>(value);
    }
    log_end_ = view_.mission_log_end();
    const std::uint64_t kept = log_end_ - view_.mission_log_begin();
    log_next_ = log_end_ - (n < kept ? n : kept);
    log_mission_ = true;
    log_streaming_ = true;
    return;
  }
  if (w.count > 2) {
    return reply_error("usage: log [error|warn|info|debug], log show [N] or log mission [N]");
  }
  if (w.count == 2) {
    LogLevel level = LogLevel::kInfo;
    if (!parse_log_level(w.word[1], level)) return reply_error("unknown log level");
    log_level_ = level;
  }
  reply_.appendf("log level=%s\r\nOK\r\n", log_level_name(log_level_));
  emit(reply_.view());
}

void Console::cmd_param(const Words& w) {
  if (w.count == 2 && w.word[1] == "show") {
    // What differs from the defaults (the values at start, before any saved ones were
    // loaded): what `param save` would keep.
    for (std::size_t i = 0; i < parameters_.size(); ++i) {
      if (parameters_.is_default(i)) continue;
      const Parameter& p = parameters_[i];
      reply_.appendf("%s=%g default=%g\r\n", p.name, static_cast<double>(*p.value),
                     static_cast<double>(parameters_.default_value(i)));
    }
    if (reply_.truncated()) return reply_error("reply too long");
    reply_.append("OK\r\n");
    emit(reply_.view());
    return;
  }
  if (w.count == 2 && w.word[1] == "save") {
    if (parameter_saver_ == nullptr)
      return reply_error("no state directory (start with --state DIR)");
    const std::size_t bytes =
        parameters_.encode_changed(parameter_text_.data(), parameter_text_.size());
    if (bytes == 0) return reply_error("parameters do not fit the file buffer");
    switch (parameter_saver_->submit_parameters({parameter_text_.data(), bytes})) {
      case StateSaver::Submitted::kQueued:
        // The writer thread reports the result as a LOG line (check_parameter_saves).
        reply_.appendf("param save changed=%zu file=%s queued\r\nOK\r\n",
                       parameters_.changed_count(), parameter_saver_->parameters_path());
        break;
      case StateSaver::Submitted::kSaved:
        seen_parameter_saves_ = parameter_saver_->parameter_saves();
        reply_.appendf("param save changed=%zu file=%s\r\nOK\r\n", parameters_.changed_count(),
                       parameter_saver_->parameters_path());
        break;
      case StateSaver::Submitted::kFailed: {
        seen_parameter_failures_ = parameter_saver_->parameter_failures();
        char why[256] = "";
        (void)parameter_saver_->parameter_error(why, sizeof why);
        TextBuffer<300> text;
        text.appendf("cannot save: %s", why);
        return reply_error(text.c_str());
      }
      case StateSaver::Submitted::kBusy:
        return reply_error("still saving, try again");
      case StateSaver::Submitted::kTooLong:
        return reply_error("parameters do not fit the file buffer");
    }
    emit(reply_.view());
    return;
  }
  return reply_error("usage: param show or param save");
}

void Console::check_parameter_saves() {
  if (parameter_saver_ == nullptr) return;
  const std::uint64_t saves = parameter_saver_->parameter_saves();
  if (saves != seen_parameter_saves_) {
    seen_parameter_saves_ = saves;
    log(LogLevel::kInfo, "parameters saved to %s", parameter_saver_->parameters_path());
  }
  const std::uint64_t failures = parameter_saver_->parameter_failures();
  if (failures != seen_parameter_failures_) {
    char why[256] = "";
    if (!parameter_saver_->parameter_error(why, sizeof why)) return;  // next frame
    seen_parameter_failures_ = failures;
    log(LogLevel::kError, "parameters not saved: %s", why);
  }
}

void Console::cmd_fault(const Words& w) {
  if (faults_ == nullptr) return reply_error("no fault injection on this board (sim board only)");
  if (w.count == 1) {
    faults_->describe_active(reply_);
    reply_.append("OK\r\n");
    if (reply_.truncated()) return reply_error("fault reply too long");
    emit(reply_.view());
    return;
  }
  if (w.count < 3) return reply_error("usage: fault DEVICE TYPE [SECONDS]");
  float seconds = 0.0F;
  if (w.count == 4 &&
      (!parse_number(w.word[3], seconds) || !(seconds > 0.0F) || !(seconds <= 1e6F))) {
    return reply_error("SECONDS must be a number in (0, 1e6]");
  }
  TextBuffer<200> text;
  if (!faults_->inject(w.word[1], w.word[2], static_cast<double>(seconds), text)) {
    return reply_error(text.c_str());
  }
  reply_.append(text.view());
  reply_.append("\r\nOK\r\n");
  emit(reply_.view());
  log(LogLevel::kWarn, "%s injected", text.c_str());
}

void Console::cmd_shutdown(const Words& w) {
  if (!no_args(w)) return reply_error("shutdown takes no arguments");
  shutdown_requested_ = true;
  emit("OK shutting down\r\n");
}

void Console::check_executive(std::uint64_t now_us) {
  const FrameStats& f = executive_.frame_stats();
  if (now_us >= next_overrun_log_us_ &&
      (f.overruns != seen_frame_overruns_ || f.background_overruns != seen_background_overruns_)) {
    // At most one line per second, however many overruns there were.
    log(LogLevel::kWarn, "overruns frame=%llu background=%llu",
        static_cast<unsigned long long>(f.overruns),
        static_cast<unsigned long long>(f.background_overruns));
    seen_frame_overruns_ = f.overruns;
    seen_background_overruns_ = f.background_overruns;
    next_overrun_log_us_ = now_us + 1000000U;
  }
  // The e-stop latch: which input stopped the base (an e-stop is not a fault of a task), and
  // what the operator must type next.
  if (safety_.cause() != logged_cause_) {
    if (safety_.cause() == StopCause::kNone) {
      log(LogLevel::kInfo, "e-stop cleared (was %s), base stopped until resume",
          stop_cause_name(logged_cause_));
    } else {
      log(LogLevel::kWarn, "e-stop engaged: %s (base stopped), latched until clear-estop",
          stop_cause_name(safety_.cause()));
    }
    logged_cause_ = safety_.cause();
  }
  if (safety_.awaiting_resume() != logged_awaiting_resume_) {
    if (!safety_.awaiting_resume()) log(LogLevel::kInfo, "resumed after the e-stop: base released");
    logged_awaiting_resume_ = safety_.awaiting_resume();
  }
  // Each task's health on its own line, with the device's reason: which device failed and
  // why, not only that something did.
  for (std::size_t i = 0; i < executive_.task_count(); ++i) {
    const char* why = executive_.task_health(i);
    TextBufferBase& logged = logged_reason_[i];
    if (why == nullptr) {
      if (logged.size() == 0) continue;
      logged.clear();
      log(LogLevel::kInfo, "%s healthy again", executive_.spec(i).name);
      continue;
    }
    const bool first = logged.size() == 0;
    if (!first && (logged.view() == why || now_us < logged_at_us_[i] + 1000000U)) continue;
    logged.clear();
    logged.append(why);
    logged_at_us_[i] = now_us;
    // A hang (overrunning, starved) withholds the watchdog; a device fault is held and retried
    // (the fault policy) until the retry time runs out.
    log(LogLevel::kError, "%s unhealthy: %s (%s)", executive_.spec(i).name, why,
        executive_.running_health(i) != nullptr ? "watchdog not kicked" : "held and retried");
  }
}

void Console::check_state_saves() {
  if (parameter_saver_ == nullptr) return;
  const std::uint64_t failures = parameter_saver_->failures();
  if (failures != seen_state_failures_) {
    char why[256] = "";
    if (!parameter_saver_->try_last_error(why, sizeof why)) return;  // next frame
    seen_state_failures_ = failures;
    storage_healthy_ = false;
    log(LogLevel::kError, "storage unhealthy: state not saved (%llu failed): %s",
        static_cast<unsigned long long>(failures), why);
  }
  const std::uint64_t saves = parameter_saver_->saved();
  if (saves != seen_state_saves_) {
    seen_state_saves_ = saves;
    if (!storage_healthy_ && !parameter_saver_->failing()) {
      storage_healthy_ = true;
      log(LogLevel::kInfo, "storage healthy again: state saved");
    }
  }
}

void Console::append_unhealthy(TextBufferBase& out) const {
  out.append(" unhealthy=");
  bool any = false;
  for (std::size_t i = 0; i < executive_.task_count(); ++i) {
    if (executive_.task_health(i) == nullptr) continue;
    out.appendf("%s%s", any ? "," : "", executive_.spec(i).name);
    any = true;
  }
  if (!storage_healthy_) {
    out.appendf("%sstorage", any ? "," : "");
    any = true;
  }
  if (!any) out.append("none");
}

void Console::send_telemetry(std::uint64_t now_us) {
  if (telemetry_ms_ <= 0.0F || now_us < next_telemetry_us_) return;
  const auto period_us = static_cast<std::uint64_t>(telemetry_ms_) * 1000U;
  next_telemetry_us_ += period_us;
  if (next_telemetry_us_ <= now_us) next_telemetry_us_ = now_us + period_us;  // no bursts
  emit_telemetry(now_us);
}

void Console::send_final_telemetry(std::uint64_t now_us) {
  if (telemetry_ms_ > 0.0F) emit_telemetry(now_us);
}

void Console::emit_telemetry(std::uint64_t now_us) {
  const core::Pose2 p = view_.pose();
  TextBuffer<256> line;
  line.appendf(
      "TLM t_s=%.2f state=%s cycles=%llu pan_rad=%.3f features=%u pieces=%u x_m=%.3f y_m=%.3f "
      "yaw_rad=%.3f estop=%s waits_for=%s target=%s\r\n",
      static_cast<double>(now_us - start_us_) * 1e-6, view_.state_name(),
      static_cast<unsigned long long>(view_.cycles()), static_cast<double>(view_.pan_rad()),
      view_.features(), view_.pieces(), static_cast<double>(p.x_m), static_cast<double>(p.y_m),
      static_cast<double>(p.yaw_rad), stop_cause_name(safety_.cause()),
      awaited_command(safety_, executive_.background_paused()),
      target_status_name(view_.target().status));
  if (!line.truncated()) emit_unsolicited(line.view());
}

}  // namespace boticelli::firmware
