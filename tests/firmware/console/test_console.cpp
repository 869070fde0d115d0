// Tests of the serial console: line assembly, parsing with hostile input, every command, telemetry,
// no allocation.
#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cstdint>
#include <cstdio>
#include <string>
#include <string_view>
#include <vector>

#include "fake_clock.h"
#include "fake_serial_port.h"
#include "firmware/common/journal_forwarder.h"
#include "firmware/console/console.h"
#include "firmware/console/console_line.h"
#include "firmware/console/console_parser.h"
#include "firmware/executive/executive.h"
#include "firmware/state/persistence.h"
#include "firmware/state/state_saver.h"
#include "firmware/telemetry/model_text.h"
#include "firmware_fakes.h"

#include "alloc_guard.h"
#include "CppUTest/TestHarness.h"

using boticelli::fakes::FakeClock;
using boticelli::fakes::FakeSerialPort;
using namespace boticelli::firmware;
using namespace boticelli::test;

namespace {

class FakeView final : public MissionView {
 public:
  const char* state_name() const override { return "look"; }
  boticelli::core::Pose2 pose() const override { return pose_value; }
  float pan_rad() const override { return 0.5F; }
  std::uint32_t features() const override { return 321; }
  std::uint32_t pieces() const override { return 17; }
  std::uint64_t cycles() const override { return 4; }
  // The text from `source` when set (the mission's double buffer), else `model`; `held` says
  // whether the console holds it.
  std::string_view model_text() override {
    held = true;
    return source != nullptr ? source->hold() : std::string_view(model);
  }
  void release_model_text() override {
    held = false;
    if (source != nullptr) source->release();
  }
  MapCounts map_counts() const override { return counts; }
  MapCounts counts{12, 34, 5};
  TargetEstimate target() const override { return target_value; }
  OdometryCalibration odometry_calibration() const override { return calibration; }
  OdometryCalibration calibration;
  CameraCalibration camera_calibration() const override { return camera; }
  CameraCalibration camera;
  std::uint64_t mission_log_begin() const override { return log_dropped; }
  std::uint64_t mission_log_end() const override { return log_dropped + log.size(); }
  const MissionLogEntry* mission_log_line(std::uint64_t n) const override {
    if (n < mission_log_begin() || n >= mission_log_end()) return nullptr;
    return &log[static_cast<std::size_t>(n - log_dropped)];
  }
  void add_log(std::uint64_t cycle, const std::string& text) {
    MissionLogEntry e;
    e.cycle = cycle;
    std::snprintf(e.text.data(), e.text.size(), "%s", text.c_str());
    log.push_back(e);
  }
  std::vector<MissionLogEntry> log;
  std::uint64_t log_dropped = 0;
  boticelli::core::Pose2 pose_value{1.25F, -0.5F, 0.75F};
  TargetEstimate target_value{};
  std::string model;
  ModelText* source = nullptr;
  bool held = false;
};

class IdleTask final : public Task {
 public:
  void run(std::uint64_t) override {}
};

std::vector<std::string> lines_of(const std::string& text) {
  std::vector<std::string> out;
  std::size_t start = 0;
  while (true) {
    const std::size_t end = text.find("\r\n", start);
    if (end == std::string::npos) break;
    out.push_back(text.substr(start, end - start));
    start = end + 2;
  }
  return out;
}

}  // namespace

TEST_GROUP(LineAssembler) {
  LineAssembler a;
  std::vector<std::string> lines;
  std::vector<LineEvent> events;
  void feed(std::string_view bytes) {
    for (const char c : bytes) {
      const LineEvent e = a.feed(static_cast<std::uint8_t>(c));
      if (e == LineEvent::kLine) lines.emplace_back(a.line());
      if (e != LineEvent::kNone) events.push_back(e);
    }
  }
};

TEST(LineAssembler, EndsLinesAtCrLfOrCrlfAndIgnoresEmptyLines) {
  feed("status\rstats\npose\r\n\r\n\nmap\r");
  CHECK_EQUAL(4U, lines.size());
  STRCMP_EQUAL("status", lines[0].c_str());
  STRCMP_EQUAL("stats", lines[1].c_str());
  STRCMP_EQUAL("pose", lines[2].c_str());
  STRCMP_EQUAL("map", lines[3].c_str());
}

TEST(LineAssembler, ErasesWithBackspaceOrDeleteAndCancelsWithCtrlC) {
  feed("stax\btz\x7f\x7fts\r");
  feed("garbage\x03help\r");
  CHECK_EQUAL(2U, lines.size());
  STRCMP_EQUAL("stats", lines[0].c_str());
  STRCMP_EQUAL("help", lines[1].c_str());
  CHECK(events[1] == LineEvent::kCancelled);
}

TEST(LineAssembler, DiscardsAnOverlongLineWholeAndRecovers) {
  feed(std::string(LineAssembler::kMaxLineBytes + 1, 'a') + "\r");
  CHECK_EQUAL(0U, lines.size());
  CHECK(events.back() == LineEvent::kTooLong);
  feed(std::string(LineAssembler::kMaxLineBytes, 'b') + "\r");
  CHECK_EQUAL(1U, lines.size());
  CHECK_EQUAL(LineAssembler::kMaxLineBytes, lines[0].size());
  // Backspace cannot rescue an overflowed line.
  feed(std::string(LineAssembler::kMaxLineBytes + 5, 'c') + "\b\b\b\b\b\b\r");
  CHECK(events.back() == LineEvent::kTooLong);
}

TEST(LineAssembler, SpoilsALineWithControlOrNonAsciiBytes) {
  feed("st\x1b[Aatus\r");
  CHECK(events.back() == LineEvent::kBadByte);
  feed("pose\xc3\xa9\r");
  CHECK(events.back() == LineEvent::kBadByte);
  feed(std::string("se\0t", 4) + "\r");
  CHECK(events.back() == LineEvent::kBadByte);
  CHECK_EQUAL(0U, lines.size());
  feed("\tpose\r");
  STRCMP_EQUAL(" pose", lines.at(0).c_str());
}

TEST_GROUP(ConsoleParser){};

TEST(ConsoleParser, SplitsWordsOnSpacesAndRefusesTooMany) {
  Words w;
  CHECK(split_words("  set   telemetry_ms  500 ", w));
  CHECK_EQUAL(3U, w.count);
  CHECK(w.word[1] == "telemetry_ms");
  CHECK(w.word[2] == "500");
  CHECK(split_words("", w));
  CHECK_EQUAL(0U, w.count);
  CHECK_FALSE(split_words("a b c d e", w));
}

TEST(LineAssembler, ReadsArrowKeysAsRecallWhenRecallIsOnAndIgnoresOtherSequences) {
  a.set_recall(true);
  feed("st\x1b[A\x1bOB\x1b[D\x1b[1;5Catus\r");
  CHECK_EQUAL(3U, events.size());
  CHECK(events[0] == LineEvent::kOlder);
  CHECK(events[1] == LineEvent::kNewer);
  CHECK(events[2] == LineEvent::kLine);
  STRCMP_EQUAL("status", lines.at(0).c_str());
  a.set_recall(false);
  events.clear();
  feed("st\x1b[Aatus\r");  // without recall an arrow key spoils the line, as before
  CHECK_EQUAL(1U, events.size());
  CHECK(events[0] == LineEvent::kBadByte);
}

TEST(LineAssembler, ShowsWhatIsTypedAndTakesAReplacement) {
  feed("sta");
  CHECK(a.typed() == "sta");
  a.replace("pose");
  CHECK(a.typed() == "pose");
  feed("\r");
  CHECK(a.typed().empty());
  STRCMP_EQUAL("pose", lines.at(0).c_str());
}

TEST_GROUP(CommandHistory){};

TEST(CommandHistory, RecallsOlderAndNewerLinesWithinItsCapacity) {
  CommandHistory h;
  std::string_view out = "unchanged";
  CHECK_FALSE(h.older(out));
  CHECK(out == "unchanged");
  for (int i = 0; i < 20; ++i) h.add("cmd " + std::to_string(i));
  h.add("cmd 19");  // a repeat of the newest is kept once
  h.add("");
  CHECK_EQUAL(CommandHistory::kEntries, h.size());
  CHECK(h.older(out));
  CHECK(out == "cmd 19");
  CHECK(h.older(out));
  CHECK(out == "cmd 18");
  CHECK(h.newer(out));
  CHECK(out == "cmd 19");
  CHECK(h.newer(out));
  CHECK(out.empty());
  CHECK_FALSE(h.newer(out));
  for (std::size_t i = 0; i < CommandHistory::kEntries; ++i) CHECK(h.older(out));
  CHECK(out == "cmd 4");
  CHECK_FALSE(h.older(out));
}

TEST_GROUP(LogRing) {
  LogRing ring;
};

TEST(LogRing, KeepsTheLastLinesAndForgetsOverwrittenOnes) {
  CHECK(ring.find(0) == nullptr);
  for (int i = 0; i < 70; ++i) {
    ring.add(static_cast<std::uint64_t>(i), LogLevel::kWarn, "line " + std::to_string(i));
  }
  CHECK_EQUAL(LogRing::kLines, ring.size());
  CHECK_EQUAL(70U, ring.end_sequence());
  CHECK(ring.find(5) == nullptr);
  CHECK(ring.find(70) == nullptr);
  const LogRing::Entry* e = ring.find(6);
  CHECK(e != nullptr);
  CHECK(e->view() == "line 6");
  CHECK_EQUAL(6U, e->t_us);
  ring.add(0, LogLevel::kInfo, std::string(300, 'x') + "\n");  // cut, one printable line
  CHECK_EQUAL(LogRing::kTextBytes, ring.find(70)->view().size());
}

TEST(ConsoleParser, ReadsOnlyPlainDecimalNumbers) {
  float v = 0.0F;
  CHECK(parse_number("-1.5", v));
  DOUBLES_EQUAL(-1.5, v, 0.0);
  CHECK(parse_number("2e-3", v));
  DOUBLES_EQUAL(0.002, v, 1e-9);
  // Trailing characters that can appear in a number but do not end one here: "1.5-", "1.2.3".
  for (const char* bad : {"", "-", ".", "e5", "0x10", "inf", "nan", "1.5x", "1 2", "1e99", "--1",
                          "1.5-", "1.2.3", "2e", "3e+", "123456789012345678901234567890123"}) {
    CHECK_FALSE_TEXT(parse_number(bad, v), bad);
  }
}

namespace {
// Everything a pipe's read end holds now (non-blocking).
std::string read_pipe(int fd) {
  std::string s;
  char buf[512];
  ssize_t n = 0;
  while ((n = ::read(fd, buf, sizeof buf)) > 0) s.append(buf, static_cast<std::size_t>(n));
  return s;
}
}  // namespace

TEST_GROUP(JournalForwarder) {
  int fds[2] = {-1, -1};
  void setup() override {
    CHECK(::pipe(fds) == 0);
    CHECK(::fcntl(fds[0], F_SETFL, O_NONBLOCK) == 0);
  }
  void teardown() override {
    ::close(fds[0]);
    ::close(fds[1]);
  }
};

// Each line once, with its sd-daemon priority (warn 4, error 3, info 6), one line per entry
// (the thread's work, done here by drain(): qemu-user cannot be trusted to start threads).
TEST(JournalForwarder, WritesEachLineOnceWithItsPriorityAndNoNewlineInside) {
  static JournalForwarder journal;
  journal.set_fd(fds[1]);
  CHECK(journal.push(LogLevel::kWarn, "camera: device gone (ENODEV), re-opening"));
  CHECK(journal.push(LogLevel::kError, "two\nlines"));
  CHECK(journal.push(LogLevel::kInfo, "back"));
  journal.drain();
  journal.drain();  // written once
  STRCMP_EQUAL("<4>camera: device gone (ENODEV), re-opening\n<3>two lines\n<6>back\n",
               read_pipe(fds[0]).c_str());
  CHECK_EQUAL(3U, journal.written());
}

// qemu-user (the cross presets' test runner) hangs in thread creation on some hosts: the
// thread is tested by the native builds (and the ThreadSanitizer program).
#ifndef BOTICELLI_TESTS_UNDER_EMULATOR
TEST(JournalForwarder, ItsThreadWritesWhatIsQueuedAndStopWritesTheRest) {
  static JournalForwarder journal;
  CHECK(journal.push(LogLevel::kWarn, "before the start"));
  CHECK(journal.start(fds[1]));
  CHECK(journal.running());
  CHECK(journal.push(LogLevel::kInfo, "while it runs"));
  journal.stop();
  CHECK_FALSE(journal.running());
  STRCMP_EQUAL("<4>before the start\n<6>while it runs\n", read_pipe(fds[0]).c_str());
}
#endif

// The executive's side never waits: a full queue drops the line and counts it, and pushing
// allocates nothing; what was queued is written in order.
TEST(JournalForwarder, AFullQueueDropsAndCountsWithoutBlockingOrAllocating) {
  static JournalForwarder journal;
  CHECK_NO_ALLOCATION(for (std::size_t i = 0; i < JournalForwarder::kSlots + 3; ++i) {
    (void)journal.push(LogLevel::kWarn, i < JournalForwarder::kSlots ? "queued" : "dropped");
  });
  CHECK_EQUAL(3U, journal.dropped());
  CHECK_FALSE(journal.push(LogLevel::kWarn, "still full"));
  journal.set_fd(fds[1]);
  journal.drain();
  const std::string out = read_pipe(fds[0]);
  CHECK_EQUAL(JournalForwarder::kSlots,
              static_cast<std::size_t>(std::count(out.begin(), out.end(), '\n')));
  CHECK(out.find("dropped") == std::string::npos);
  CHECK(journal.push(LogLevel::kWarn, "room again"));
}

TEST_GROUP(Console) {
  FakeClock clock{5000000};
  FakeSerialPort port;
  Executive exec{clock};
  FakeInput button, bumper;
  FakeBase base;
  Safety safety{button, bumper, base};
  FakeView view;
  ParameterTable parameters;
  Console console{port, exec, safety, view, parameters};
  IdleTask idle;
  float gain = 2.0F;
  std::uint64_t now_us = 5000000;
  const char* error = "";

  void setup() override {
    CHECK(exec.add_task({"estop", 10000, 200}, idle, &error));
    CHECK(exec.add_task({"camera", 20000, 2000}, idle, &error));
    CHECK(exec.start(ExecutiveConfig{}, &error));
    console.set_telemetry_ms(0.0F);  // before the registration: its default
    CHECK(console.register_parameters());
    CHECK(parameters.add({"gain", &gain, 0.0F, 10.0F, false, "a gain [1]"}));
  }
  void service(int times = 1) {
    for (int i = 0; i < times; ++i) {
      console.service(now_us);
      now_us += 10000;
    }
  }
  // Sends one line and returns the reply lines.
  std::vector<std::string> command(std::string_view line) {
    port.clear_written();
    port.feed(line);
    port.feed("\r");
    service(3);
    return lines_of(port.written());
  }
};

TEST(Console, AnswersHelpWithEveryCommand) {
  const auto reply = command("help");
  CHECK_EQUAL("OK", reply.back());
  for (const char* name : {"help",
                           "status",
                           "stats",
                           "pose",
                           "model",
                           "map",
                           "base-calibration",
                           "camera-calibration",
                           "pause",
                           "resume",
                           "estop",
                           "clear-estop",
                           "get",
                           "set",
                           "log",
                           "param",
                           "fault",
                           "ver",
                           "shutdown",
                           "quit"}) {
    bool found = false;
    for (const auto& l : reply) found = found || l.rfind(std::string(name) + " ", 0) == 0;
    CHECK_TEXT(found, name);
  }
}

TEST(Console, ReportsStatusPoseAndMap) {
  auto reply = command("status");
  CHECK_EQUAL(2U, reply.size());
  STRCMP_CONTAINS("state=look estop=none paused=0", reply[0].c_str());
  STRCMP_CONTAINS(
      "cycles=4 pieces=17 features=321 obstacle_points=34 exploration_points=5 target=none "
      "frames=",
      reply[0].c_str());
  reply = command("pose");
  STRCMP_EQUAL("pose x_m=1.250 y_m=-0.500 yaw_rad=0.7500", reply.at(0).c_str());
  reply = command("map");
  STRCMP_EQUAL(
      "map polygon_vertices=12 obstacle_points=34 exploration_points=5 grid_tiles=0 grid_bytes=0 "
      "free_m2=0.00 occupied_m2=0.00 grid_dropped=0 frontiers=0 blacklisted=0 goal=none "
      "target=none",
      reply.at(0).c_str());
  CHECK_EQUAL("OK", reply.back());
}

TEST(Console, MapSummarisesTheWorldMemoryAndTheGoalOnIt) {
  view.counts.grid_tiles = 40;
  view.counts.grid_bytes = 18432;
  view.counts.free_m2 = 21.5F;
  view.counts.occupied_m2 = 1.25F;
  view.counts.grid_dropped = 3;
  view.counts.frontiers = 4;
  view.counts.blacklisted = 1;
  view.counts.goal = GoalKind::kFrontier;
  view.counts.goal_x_m = 2.5F;
  view.counts.goal_y_m = -1.0F;
  view.counts.goal_path_m = 3.75F;
  STRCMP_EQUAL(
      "map polygon_vertices=12 obstacle_points=34 exploration_points=5 grid_tiles=40 "
      "grid_bytes=18432 free_m2=21.50 occupied_m2=1.25 grid_dropped=3 frontiers=4 blacklisted=1 "
      "goal=frontier goal_x_m=2.500 goal_y_m=-1.000 goal_path_m=3.75 target=none",
      command("map").at(0).c_str());
  view.counts.goal = GoalKind::kTarget;
  STRCMP_CONTAINS(" goal=target goal_x_m=2.500 ", command("map").at(0).c_str());
}

TEST(Console, BaseCalibrationSaysWhatItLacksThenTheValuesForTheConfigFile) {
  view.calibration.intervals = 3;
  view.calibration.turned_rad = 3.14159265F;
  view.calibration.driven_m = 1.5F;
  auto reply = command("base-calibration");
  STRCMP_EQUAL(
      "base-calibration intervals=3 turned_deg=180 driven_m=1.50 not enough yet (4 intervals, "
      "360 deg turned and 2 m driven, with register_looks)",
      reply.at(0).c_str());
  CHECK_EQUAL("OK", reply.back());
  view.calibration = {true, 21, 60.0F, 14.25F, 1.0123F, 0.0021F, 0.9951F, 0.0034F};
  reply = command("base-calibration");
  STRCMP_EQUAL(
      "base-calibration intervals=21 turned_deg=3438 driven_m=14.25 odometry_track_scale=1.0123 "
      "sd=0.0021 odometry_diameter_ratio=0.9951 sd=0.0034",
      reply.at(0).c_str());
  CHECK_EQUAL("OK", reply.back());
  STRCMP_CONTAINS("takes no arguments", command("base-calibration now").at(0).c_str());
}

TEST(Console, CameraCalibrationSaysWhatItLacksThenTheFloorsRatioAndTheCorrection) {
  view.camera.self_calibrating = true;
  auto reply = command("camera-calibration");
  STRCMP_EQUAL(
      "camera-calibration bases=0 no check yet (30 stereo points low on obstacles whose base the "
      "floor shows) self_calibration=on inverse_range_bias_per_m=0.0000 focal_scale=1.0000 "
      "tilt_step_error_deg=0.000",
      reply.at(0).c_str());
  CHECK_EQUAL("OK", reply.back());
  view.camera = {412, 0.9431F, false, 0.0476F, 1.0100F, 0.001344F};
  reply = command("camera-calibration");
  STRCMP_EQUAL(
      "camera-calibration bases=412 stereo_to_floor=0.943 self_calibration=off "
      "inverse_range_bias_per_m=0.0476 focal_scale=1.0100 tilt_step_error_deg=0.077",
      reply.at(0).c_str());
  CHECK_EQUAL("OK", reply.back());
  STRCMP_CONTAINS("takes no arguments", command("camera-calibration now").at(0).c_str());
}

TEST(Console, ReportsTheTargetEstimateOnceTheMissionHasOne) {
  view.target_value = {TargetStatus::kSeen, 1, 2.5F, -1.0F, 0.4F};
  STRCMP_CONTAINS("target=seen target_x_m=2.500 target_y_m=-1.000 target_z_m=0.400 sightings=1 ",
                  command("status").at(0).c_str());
  view.target_value = {TargetStatus::kConfirmed, 3, 2.25F, -1.5F, 0.35F};
  STRCMP_EQUAL(
      "map polygon_vertices=12 obstacle_points=34 exploration_points=5 grid_tiles=0 grid_bytes=0 "
      "free_m2=0.00 occupied_m2=0.00 grid_dropped=0 frontiers=0 blacklisted=0 goal=none "
      "target=confirmed target_x_m=2.250 target_y_m=-1.500 target_z_m=0.350 sightings=3",
      command("map").at(0).c_str());
  CHECK_EQUAL("OK", command("set telemetry_ms 100").at(0));
  port.clear_written();
  service(10);
  STRCMP_CONTAINS("estop=none waits_for=none target=confirmed", port.written().c_str());
}

TEST(Console, ShowsExecutiveTimingPerTask) {
  for (int i = 0; i < 10; ++i) exec.run_frame();
  const auto reply = command("stats");
  CHECK_EQUAL(5U, reply.size());
  STRCMP_CONTAINS("task estop", reply[0].c_str());
  STRCMP_CONTAINS("runs=10", reply[0].c_str());
  STRCMP_CONTAINS("task camera", reply[1].c_str());
  STRCMP_CONTAINS("runs=5", reply[1].c_str());
  STRCMP_CONTAINS("frame frame_us=10000 frames=10", reply[2].c_str());
  STRCMP_CONTAINS("background util_pct=", reply[3].c_str());
  CHECK_EQUAL("OK", command("stats reset").back());
  STRCMP_CONTAINS("runs=0", command("stats").at(0).c_str());
}

TEST(Console, ShowsTheHostsTimingsBesideTheBoardsWhenTheExecutiveHasAHostClock) {
  // A lockstep board clock: the board's figures stay 0, the host's show what the work took.
  FakeHostClock host;
  Executive timed{clock, &host};
  class HostWork final : public Task {
   public:
    explicit HostWork(FakeHostClock& h) : host_(h) {}
    void run(std::uint64_t) override { host_.spend(180000, 150000); }

   private:
    FakeHostClock& host_;
  } work{host};
  CHECK(timed.add_task({"estop", 10000, 200}, work, &error));
  CHECK(timed.add_task({"camera", 20000, 2000}, idle, &error));
  CHECK(timed.start(ExecutiveConfig{}, &error));
  for (int i = 0; i < 10; ++i) timed.run_frame();
  ParameterTable timed_parameters;
  Console timed_console{port, timed, safety, view, timed_parameters};
  timed_console.set_telemetry_ms(0.0F);
  port.clear_written();
  port.feed("stats\r");
  for (int i = 0; i < 3; ++i) timed_console.service(now_us += 10000);
  const auto reply = lines_of(port.written());
  CHECK_EQUAL(9U, reply.size());
  STRCMP_CONTAINS("task estop    period_us=10000 budget_us=200 runs=10 avg_us=0 worst_us=0",
                  reply[0].c_str());
  STRCMP_CONTAINS("host task estop    budget_us=200 runs=10 wall_avg_us=180.0", reply[4].c_str());
  STRCMP_CONTAINS("cpu_worst_us=150.0", reply[4].c_str());
  STRCMP_CONTAINS("host task camera   budget_us=2000 runs=5", reply[5].c_str());
  STRCMP_CONTAINS("host background limit_us=9000 slices=0", reply[6].c_str());
  STRCMP_CONTAINS("host frame frame_us=10000 frames=10 work_wall_p99_us=180.0", reply[7].c_str());
  CHECK_EQUAL("OK", reply.back());
}

TEST(Console, SaysThereIsNoModelUntilTheMissionHasOne) {
  const auto reply = command("model");
  CHECK_EQUAL(1U, reply.size());
  STRCMP_EQUAL("ERR no model yet", reply[0].c_str());
  CHECK_FALSE(view.held);  // nothing to send: nothing kept from the mission
}

namespace {
ModelText g_texts;  // two 64 KB buffers: static
std::string model_of(const char* form) {
  std::string text = "VARIABLES 3\r\n";
  while (text.size() < 3 * Console::kTxBytes) text += form;
  return text;
}
void publish(ModelText& texts, const std::string& text) {
  std::copy(text.begin(), text.end(), texts.back().begin());
  texts.publish(text.size());
}
}  // namespace

TEST(Console, AModelFittedWhileTheReplyStreamsNeitherTearsItNorIsLost) {
  const std::string first = model_of("LINEARFORM 0.125 -0.5 1.0 0.25\r\n");
  const std::string second = model_of("LINEARFORM 9.875 -7.5 3.0 0.75\r\n");
  g_texts.clear();
  publish(g_texts, first);
  view.source = &g_texts;
  port.set_write_limit(0);  // the line is busy: the reply waits in the output ring
  port.clear_written();
  port.feed("model\r");
  service(5);
  CHECK(view.held);  // still streaming ...
  // ... while two cycles end, each with a new model (the second written where the first went)
  publish(g_texts, model_of("LINEARFORM 5.5 -2.25 1.0 0.5\r\n"));
  publish(g_texts, second);
  port.set_write_limit(100);
  service(600);
  CHECK_FALSE(view.held);
  std::string out = port.written();
  CHECK(out.rfind(first, 0) == 0);  // the old text whole, not the new one's tail
  CHECK_EQUAL(first.size() + 4, out.size());
  port.clear_written();
  port.feed("model\r");
  service(600);
  out = port.written();
  CHECK(out.rfind(second, 0) == 0);  // and the new one for the next `model`
}

TEST(Console, StreamsAModelLargerThanItsOutputBufferThroughASlowLine) {
  std::string text = "VARIABLES 3\r\n";
  while (text.size() < 3 * Console::kTxBytes) text += "LINEARFORM 0.125 -0.5 1.0 0.25\r\n";
  view.model = text;
  port.set_write_limit(100);  // about what 115200 baud moves in a 10 ms frame
  port.clear_written();
  port.feed("model\rstatus\r");
  service(600);
  const std::string& out = port.written();
  CHECK(out.rfind(text, 0) == 0);  // the whole text first, intact
  const auto reply = lines_of(out.substr(text.size()));
  CHECK_EQUAL(3U, reply.size());
  CHECK_EQUAL("OK", reply[0]);  // model's end
  STRCMP_CONTAINS("status state=look", reply[1].c_str());
  CHECK_EQUAL("OK", reply[2]);
}

TEST(Console, SendsEachLineOfAModelWithBareLineFeedsAsACrLfLine) {
  // The ALN writer ends lines with "\n"; on the console every line ends with CRLF.
  std::string text;
  while (text.size() < 2 * Console::kTxBytes) text += "0 : 0.125 (x0 - 1) - 1 (x3 - 0.5);\n";
  text += "BLOCKS = 1;\n0 : MIN(0, 1);";  // no final newline: the console adds it
  view.model = text;
  port.set_write_limit(100);
  port.clear_written();
  port.feed("model\r");
  service(600);
  const std::string& out = port.written();
  for (std::size_t i = 0; i < out.size(); ++i) {
    if (out[i] == '\n') CHECK_TEXT(i > 0 && out[i - 1] == '\r', "a bare LF");
    if (out[i] == '\r') CHECK_TEXT(i + 1 < out.size() && out[i + 1] == '\n', "a bare CR");
  }
  const auto lines = lines_of(out);
  CHECK_EQUAL(static_cast<std::size_t>(std::count(text.begin(), text.end(), '\n')) + 2,
              lines.size());
  CHECK_EQUAL("0 : MIN(0, 1);", lines[lines.size() - 2]);
  CHECK_EQUAL("OK", lines.back());
}

TEST(Console, PausesAndResumesTheBackgroundWork) {
  CHECK_EQUAL("OK", command("pause").back());
  CHECK(exec.background_paused());
  STRCMP_CONTAINS("paused=1", command("status").at(0).c_str());
  CHECK_EQUAL("OK", command("resume").back());
  CHECK_FALSE(exec.background_paused());
}

TEST(Console, EstopStopsTheBaseAndOnlyClearEstopThenResumeStartItAgain) {
  auto reply = command("estop");
  CHECK_EQUAL("OK", reply.at(0));
  // The latch's change is logged, with the input that stopped the base and what to type.
  CHECK_EQUAL(2U, reply.size());
  STRCMP_EQUAL("LOG warn e-stop engaged: console (base stopped), latched until clear-estop",
               reply.back().c_str());
  CHECK(base.health() == boticelli::hal::BaseHealth::kStopped);
  CHECK(safety.cause() == StopCause::kConsole);
  STRCMP_CONTAINS("estop=console paused=0 waits_for=clear-estop ", command("status").at(0).c_str());
  // Resume before the reset is refused and changes nothing.
  STRCMP_EQUAL("ERR e-stop latched: clear-estop first", command("resume").at(0).c_str());
  CHECK(safety.engaged());
  button.level = true;
  STRCMP_EQUAL("ERR e-stop button still pressed", command("clear-estop").at(0).c_str());
  CHECK(safety.engaged());
  button.level = false;
  // The reset: the latch released, the base still stopped until resume.
  reply = command("clear-estop");
  CHECK_EQUAL("OK", reply.at(0));
  STRCMP_EQUAL("LOG info e-stop cleared (was console), base stopped until resume",
               reply.back().c_str());
  CHECK_FALSE(safety.engaged());
  CHECK(base.health() == boticelli::hal::BaseHealth::kStopped);
  STRCMP_CONTAINS("estop=none paused=0 waits_for=resume ", command("status").at(0).c_str());
  // The restart.
  reply = command("resume");
  CHECK_EQUAL("OK", reply.at(0));
  STRCMP_EQUAL("LOG info resumed after the e-stop: base released", reply.back().c_str());
  CHECK(base.health() == boticelli::hal::BaseHealth::kReady);
  CHECK_FALSE(safety.holds());
  STRCMP_CONTAINS("estop=none paused=0 waits_for=none ", command("status").at(0).c_str());
}

TEST(Console, ResumeAfterTheResetAlsoEndsAPause) {
  CHECK_EQUAL("OK", command("pause").back());
  STRCMP_CONTAINS("paused=1 waits_for=resume ", command("status").at(0).c_str());
  CHECK_EQUAL("OK", command("estop").at(0));
  CHECK_EQUAL("OK", command("clear-estop").at(0));
  CHECK(exec.background_paused());
  CHECK_EQUAL("OK", command("resume").at(0));
  CHECK_FALSE(exec.background_paused());
  CHECK_FALSE(safety.holds());
}

TEST(Console, GetsAndSetsParametersWithinTheirRange) {
  auto reply = command("get gain");
  STRCMP_EQUAL("gain=2 range=[0,10] a gain [1]", reply.at(0).c_str());
  CHECK_EQUAL("OK", command("set gain 7.5").back());
  DOUBLES_EQUAL(7.5, gain, 0.0);
  reply = command("get");
  CHECK_EQUAL(parameters.size() + 1, reply.size());
  for (const char* bad :
       {"set gain 11", "set gain -0.1", "set gain abc", "set gain 0x3", "set gain nan", "set gain",
        "set nothing 1", "set gain 1 2", "set telemetry_ms 10.5", "set echo 2", "get nothing"}) {
    reply = command(bad);
    CHECK_EQUAL_TEXT(1U, reply.size(), bad);
    CHECK_TEXT(reply[0].rfind("ERR ", 0) == 0, bad);
  }
  DOUBLES_EQUAL(7.5, gain, 0.0);
}

TEST(Console, ChangesTheLogLevelAndFiltersLogLines) {
  STRCMP_EQUAL("log level=info", command("log").at(0).c_str());
  STRCMP_EQUAL("log level=warn", command("log warn").at(0).c_str());
  CHECK(console.log_level() == LogLevel::kWarn);
  STRCMP_EQUAL("ERR unknown log level", command("log loud").at(0).c_str());
  port.clear_written();
  console.log(LogLevel::kInfo, "hidden %d", 1);
  console.log(LogLevel::kError, "shown %d", 2);
  service();
  const auto out = lines_of(port.written());
  CHECK_EQUAL(1U, out.size());
  STRCMP_EQUAL("LOG error shown 2", out[0].c_str());
}

TEST(Console, AnswersBadInputWithOneErrorLineAndChangesNothing) {
  const std::string too_long(LineAssembler::kMaxLineBytes + 10, 'x');
  for (const std::string& bad :
       {std::string("fly"), std::string("pose extra"), std::string("a b c d e"), too_long,
        std::string("st\x01"
                    "atus"),
        std::string("estop now")}) {
    const auto reply = command(bad);
    CHECK_EQUAL_TEXT(1U, reply.size(), bad.c_str());
    CHECK_TEXT(reply[0].rfind("ERR ", 0) == 0, bad.c_str());
  }
  CHECK_FALSE(safety.engaged());
  CHECK_FALSE(console.shutdown_requested());
  DOUBLES_EQUAL(2.0, gain, 0.0);
}

TEST(Console, RequestsShutdownOnQuit) {
  CHECK_EQUAL("OK shutting down", command("quit").back());
  CHECK(console.shutdown_requested());
}

TEST(Console, EchoesTypedCharactersWhenAsked) {
  CHECK_EQUAL("OK", command("set echo 1").back());
  port.clear_written();
  port.feed("poz\x7fse\r");
  service(2);
  CHECK(port.written().rfind("poz\b \bse\r\npose x_m=", 0) == 0);
}

TEST(Console, RecallsTheLastCommandsWithUpAndDownWhenEchoIsOn) {
  CHECK_EQUAL("OK", command("set echo 1").back());
  command("pose");
  port.clear_written();
  port.feed("\x1b[A\x1b[A");  // up twice: "pose", then "set echo 1"
  service(2);
  CHECK_EQUAL(std::string("\r\x1b[Kpose\r\x1b[Kset echo 1"), port.written());
  port.clear_written();
  port.feed("\x1b[B\r");  // down: back to "pose", and run it
  service(2);
  CHECK(port.written().rfind("\r\x1b[Kpose\r\npose x_m=1.250", 0) == 0);
}

TEST(Console, IgnoresArrowKeysWithoutEchoAsBadCharacters) {
  command("pose");
  const auto reply = command("\x1b[A");
  CHECK_EQUAL(1U, reply.size());
  STRCMP_EQUAL("ERR bad character in line", reply[0].c_str());
}

TEST(Console, RedrawsAHalfTypedLineAfterTelemetryWhenEchoIsOn) {
  CHECK_EQUAL("OK", command("set telemetry_ms 100").at(0));
  CHECK_EQUAL("OK", command("set echo 1").at(0));
  service(10);  // the telemetry line after the command, on a line of its own
  port.clear_written();
  port.feed("sta");
  service(12);
  const std::string out = port.written();
  // The typed text first, then each telemetry line on a line of its own with the typed text
  // after it again: never "staTLM ...".
  CHECK(out.rfind("sta\r\x1b[KTLM t_s=", 0) == 0);
  CHECK(out.find("staTLM") == std::string::npos);
  CHECK(out.size() > 3 && out.substr(out.size() - 5) == "\r\nsta");
  port.clear_written();
  port.feed("tus\r");
  service(1);
  STRCMP_CONTAINS("tus\r\nstatus state=look", port.written().c_str());
}

// The console's log lines of info and above reach the journal under their level (faults at
// run time are not only on the console); debug lines do not.
TEST(Console, LogLinesOfInfoAndAboveGoToTheJournalUnderTheirLevel) {
  static JournalForwarder journal;
  int fds[2];
  CHECK(::pipe(fds) == 0);
  CHECK(::fcntl(fds[0], F_SETFL, O_NONBLOCK) == 0);
  console.set_journal(&journal);
  console.log(LogLevel::kWarn, "PTU: no reply for %.1f s", 0.5);
  console.log(LogLevel::kInfo, "devices back");
  console.log(LogLevel::kDebug, "not for the journal");
  journal.set_fd(fds[1]);
  journal.drain();
  STRCMP_EQUAL("<4>PTU: no reply for 0.5 s\n<6>devices back\n", read_pipe(fds[0]).c_str());
  ::close(fds[0]);
  ::close(fds[1]);
  console.set_journal(nullptr);
}

TEST(Console, ShowsTheLastLogLinesFromItsRing) {
  LogRing ring;
  console.set_log_ring(&ring, &clock);
  service(1);
  console.log(LogLevel::kWarn, "first %d", 1);
  clock.advance_us(1500000);
  console.log(LogLevel::kInfo, "second %d", 2);
  console.log(LogLevel::kDebug, "not kept at level info");
  CHECK_EQUAL(2U, ring.size());
  service(1);  // the LOG lines themselves go out first
  auto reply = command("log show");
  CHECK_EQUAL(3U, reply.size());
  STRCMP_EQUAL("log t_s=0.000 warn first 1", reply[0].c_str());
  STRCMP_EQUAL("log t_s=1.500 info second 2", reply[1].c_str());
  CHECK_EQUAL("OK", reply[2]);
  reply = command("log show 1");
  CHECK_EQUAL(2U, reply.size());
  STRCMP_EQUAL("log t_s=1.500 info second 2", reply[0].c_str());
  for (const char* bad :
       {"log show 0", "log show 65", "log show 1.5", "log show x", "log show 1 2"}) {
    reply = command(bad);
    CHECK_EQUAL_TEXT(1U, reply.size(), bad);
    CHECK_TEXT(reply[0].rfind("ERR ", 0) == 0, bad);
  }
  // A full ring through a slow line: every line whole, then OK, and no LOG line inside. At
  // level warn the info lines are not sent but still kept.
  CHECK_EQUAL("log level=warn", command("log warn").at(0));
  for (int i = 0; i < 100; ++i) {
    console.log(LogLevel::kInfo, "line %03d %s", i, std::string(110, 'y').c_str());
  }
  port.set_write_limit(100);
  port.clear_written();
  port.feed("log show\r");
  service(1);
  console.log(LogLevel::kError, "during the reply");
  service(400);
  reply = lines_of(port.written());
  // The reply's lines, its OK, and only then the LOG line logged while it was queued.
  CHECK(reply.size() >= LogRing::kLines + 1);
  STRCMP_CONTAINS("info line 036 yyy", reply[0].c_str());
  STRCMP_CONTAINS("line 099", reply[LogRing::kLines - 1].c_str());
  CHECK_EQUAL("OK", reply[LogRing::kLines]);
  for (std::size_t i = 0; i < LogRing::kLines; ++i) CHECK(reply[i].rfind("log t_s=", 0) == 0);
}

TEST(Console, ReportsTheVersionAndTheBoard) {
  console.set_board_name("sim");
  const auto reply = command("ver");
  CHECK_EQUAL(2U, reply.size());
  STRCMP_CONTAINS("ver version=", reply[0].c_str());
  STRCMP_CONTAINS(" board=sim", reply[0].c_str());
  STRCMP_EQUAL("ERR ver takes no arguments", command("ver x").at(0).c_str());
}

TEST(Console, SendsTelemetryAtTheConfiguredPeriod) {
  CHECK_EQUAL("OK", command("set telemetry_ms 500").at(0));
  port.clear_written();
  service(500);  // 5 s of 10 ms service calls
  const auto out = lines_of(port.written());
  CHECK_EQUAL(10U, out.size());
  STRCMP_CONTAINS("TLM t_s=", out[0].c_str());
  STRCMP_CONTAINS(
      "state=look cycles=4 pan_rad=0.500 features=321 pieces=17 x_m=1.250 y_m=-0.500 "
      "yaw_rad=0.750 estop=none waits_for=none target=none",
      out[0].c_str());
  CHECK_EQUAL("OK", command("set telemetry_ms 0").at(0));
  port.clear_written();
  service(300);
  CHECK_EQUAL(0U, port.written().size());
}

// At the orderly stop one more line, whatever the period: the state the mission ended in.
TEST(Console, SendsOneFinalTelemetryLineAtTheStopUnlessTelemetryIsOff) {
  CHECK_EQUAL("OK", command("set telemetry_ms 500").at(0));
  service(1);
  port.clear_written();
  service(10);  // 0.1 s: the next periodic line is 0.4 s away
  CHECK_EQUAL(0U, port.written().size());
  console.send_final_telemetry(now_us);
  console.drain();
  const auto out = lines_of(port.written());
  CHECK_EQUAL(1U, out.size());
  STRCMP_CONTAINS("TLM t_s=", out[0].c_str());
  STRCMP_CONTAINS("state=look cycles=4 ", out[0].c_str());
  CHECK_EQUAL("OK", command("set telemetry_ms 0").at(0));
  port.clear_written();
  console.send_final_telemetry(now_us);
  console.drain();
  CHECK_EQUAL(0U, port.written().size());
}

TEST(Console, SurvivesAFloodOfRandomBytesAndStillAnswers) {
  std::uint32_t x = 12345;
  std::string noise;
  for (int round = 0; round < 200; ++round) {
    noise.clear();
    for (int i = 0; i < 500; ++i) {
      x = x * 1664525U + 1013904223U;
      noise.push_back(static_cast<char>(x >> 24));
    }
    port.clear_written();
    port.feed(noise);
    service(20);
    for (const auto& l : lines_of(port.written())) {
      // Every line the console sends is a protocol line, whatever came in.
      bool known = l.rfind("ERR ", 0) == 0 || l == "OK" || l.rfind("LOG ", 0) == 0;
      for (const char* data : {"status ", "task ", "frame ", "background ", "pose ", "map ",
                               "log level=", "OK shutting down"}) {
        known = known || l.rfind(data, 0) == 0;
      }
      CHECK_TEXT(known, l.c_str());
    }
  }
  CHECK(gain >= 0.0F && gain <= 10.0F);
  port.clear_written();
  port.feed("\x03\rpose\r");
  service(3);
  STRCMP_CONTAINS("pose x_m=1.250", port.written().c_str());
}

TEST(Console, HandlesBytesAndLinesWithoutAllocating) {
  console.set_telemetry_ms(100.0F);
  service(2);
  port.clear_written();
  port.feed("status\rstats\rpose\rset gain 3\rget gain\rbogus\rlog debug\r");
  port.feed(std::string(300, 'z') + "\r\x1b[A\rhelp\r");
  LogRing ring;
  console.set_log_ring(&ring, &clock);
  console.log(LogLevel::kWarn, "a line for log show");
  port.feed("set echo 1\rver\rlog show\rlog show 3\r\x1b[A\x1b[A\x1b[B\rsta");
  CHECK_NO_ALLOCATION(service(50));
  STRCMP_CONTAINS("warn a line for log show", port.written().c_str());
  CHECK(port.written().size() > 1000U);
  DOUBLES_EQUAL(3.0, gain, 0.0);
}

TEST(Console, ParamShowListsOnlyTheParametersThatDifferFromTheirDefaults) {
  auto reply = command("param show");
  CHECK_EQUAL(1U, reply.size());
  CHECK_EQUAL("OK", reply[0]);
  CHECK_EQUAL("OK", command("set gain 4.5").at(0));
  CHECK_EQUAL("OK", command("set echo 0").at(0));  // set, but to its default
  reply = command("param show");
  CHECK_EQUAL(2U, reply.size());
  CHECK_EQUAL("gain=4.5 default=2", reply[0]);
  CHECK_EQUAL("OK", reply[1]);
  CHECK_EQUAL("OK", command("set gain 2").at(0));
  CHECK_EQUAL(1U, command("param show").size());
  CHECK_EQUAL("ERR usage: param show or param save", command("param").at(0));
  CHECK_EQUAL("ERR usage: param show or param save", command("param show all").at(0));
}

TEST(Console, ParamSaveIsRefusedWithoutAStateDirectory) {
  CHECK_EQUAL("ERR no state directory (start with --state DIR)", command("param save").at(0));
}

TEST(Console, ParamSaveWritesTheChangedValuesIntoTheStateDirectoryWithoutAllocating) {
  char templ[] = "/tmp/boticelli-console-XXXXXX";
  const std::string dir = mkdtemp(templ);
  static StateStore store;
  char why[256] = "";
  CHECK(store.open(dir.c_str(), why, sizeof why));
  StateSaver saver(store);  // no thread: written at once (as on the sim board)
  console.set_parameter_saver(&saver);
  port.clear_written();
  port.feed("set gain 7.25\rparam save\r");
  CHECK_NO_ALLOCATION(service(5));
  const auto reply = lines_of(port.written());
  CHECK_EQUAL(3U, reply.size());  // written at once: the reply says so, no LOG line follows
  CHECK_EQUAL("param save changed=1 file=" + dir + "/parameters.conf", reply[1]);
  CHECK_EQUAL("OK", reply[2]);
  std::string text(256, '\0');
  FILE* f = std::fopen((dir + "/parameters.conf").c_str(), "rb");
  CHECK(f != nullptr);
  text.resize(std::fread(text.data(), 1, text.size(), f));
  std::fclose(f);
  STRCMP_CONTAINS("\ngain = 7.25\n", text.c_str());
  CHECK(text.find("telemetry_ms") == std::string::npos);
  // A failed save answers ERR with the reason.
  unlink((dir + "/parameters.conf").c_str());
  rmdir(dir.c_str());
  const std::string failed = command("param save").at(0);
  STRCMP_CONTAINS("ERR cannot save: cannot create", failed.c_str());
}

TEST(Console, LogMissionShowsTheMissionLogKeptInTheStateFile) {
  CHECK_EQUAL("OK", command("log mission").at(0));  // nothing yet
  for (int c = 1; c <= 5; ++c) view.add_log(static_cast<std::uint64_t>(c), "cycle done");
  view.add_log(5, "target confirmed");
  auto reply = command("log mission");
  CHECK_EQUAL(7U, reply.size());
  CHECK_EQUAL("mission cycle=1 cycle done", reply[0]);
  CHECK_EQUAL("mission cycle=5 target confirmed", reply[5]);
  CHECK_EQUAL("OK", reply[6]);
  reply = command("log mission 2");
  CHECK_EQUAL(3U, reply.size());
  CHECK_EQUAL("mission cycle=5 cycle done", reply[0]);
  CHECK_EQUAL("mission cycle=5 target confirmed", reply[1]);
  for (const char* bad : {"log mission 0", "log mission 129", "log mission 1.5", "log mission x"}) {
    CHECK_EQUAL_TEXT("ERR N must be a whole number from 1 to 128", command(bad).at(0), bad);
  }
  CHECK_EQUAL("ERR usage: log mission [N]", command("log mission 1 2").at(0));
}

TEST(Console, LogMissionStreamsAFullLogWithoutAllocating) {
  for (int c = 0; c < 128; ++c) {
    view.add_log(static_cast<std::uint64_t>(c), std::string(90, static_cast<char>('a' + c % 26)));
  }
  view.log_dropped = 1000;  // numbered as after a long run
  port.clear_written();
  port.reserve_written(32768);  // the fake port's own buffer
  port.feed("log mission\r");
  CHECK_NO_ALLOCATION(service(40));
  const auto reply = lines_of(port.written());
  CHECK_EQUAL(129U, reply.size());
  STRCMP_CONTAINS("mission cycle=0 aaaa", reply[0].c_str());
  STRCMP_CONTAINS("mission cycle=127 xxxx", reply[127].c_str());
  CHECK_EQUAL("OK", reply[128]);
}

#ifndef BOTICELLI_TESTS_UNDER_EMULATOR
TEST(Console, ParamSaveThroughTheWriterThreadReportsTheResultAsALogLine) {
  char templ[] = "/tmp/boticelli-console-XXXXXX";
  const std::string dir = mkdtemp(templ);
  static StateStore store;
  char why[256] = "";
  CHECK(store.open(dir.c_str(), why, sizeof why));
  StateSaver saver(store);
  saver.start();
  console.set_parameter_saver(&saver);
  const auto reply = command("param save");
  CHECK_EQUAL("param save changed=0 file=" + dir + "/parameters.conf queued", reply.at(0));
  saver.flush();
  port.clear_written();
  service(2);
  STRCMP_CONTAINS(("LOG info parameters saved to " + dir + "/parameters.conf").c_str(),
                  port.written().c_str());
  unlink((dir + "/parameters.conf").c_str());
  rmdir(dir.c_str());
}
#endif

namespace {
// Records what the console asks the board to inject.
class RecordingInjection final : public FaultInjection {
 public:
  bool inject(std::string_view device, std::string_view type, double seconds,
              TextBufferBase& reply) override {
    last_device = std::string(device);
    last_type = std::string(type);
    last_seconds = seconds;
    if (device != "camera") {
      reply.append("unknown device");
      return false;
    }
    reply.appendf("fault %s %s seconds=%.1f from_t_s=1.00", last_device.c_str(), last_type.c_str(),
                  seconds);
    return true;
  }
  void describe_active(TextBufferBase& out) const override {
    out.append("fault camera off since_t_s=1.00 until_t_s=6.00\r\n");
  }
  std::string last_device;
  std::string last_type;
  double last_seconds = -1.0;
};
}  // namespace

TEST(Console, TheFaultCommandNeedsABoardThatInjectsFaults) {
  STRCMP_EQUAL("ERR no fault injection on this board (sim board only)",
               command("fault camera off").at(0).c_str());
}

TEST(Console, TheFaultCommandHandsTheFaultToTheBoardAndListsTheActiveOnes) {
  RecordingInjection faults;
  console.set_fault_injection(&faults);
  auto reply = command("fault camera off 5");
  STRCMP_EQUAL("fault camera off seconds=5.0 from_t_s=1.00", reply.at(0).c_str());
  CHECK_EQUAL("OK", reply.at(1));
  STRCMP_CONTAINS("LOG warn fault camera off seconds=5.0 from_t_s=1.00 injected",
                  reply.back().c_str());
  CHECK_EQUAL("camera", faults.last_device);
  CHECK_EQUAL("off", faults.last_type);
  DOUBLES_EQUAL(5.0, faults.last_seconds, 1e-9);
  command("fault camera stuck");
  DOUBLES_EQUAL(0.0, faults.last_seconds, 0.0);  // until the end
  reply = command("fault");
  STRCMP_EQUAL("fault camera off since_t_s=1.00 until_t_s=6.00", reply.at(0).c_str());
  CHECK_EQUAL("OK", reply.at(1));
  // Refusals: the board's reason, or bad arguments; the board is not asked.
  STRCMP_EQUAL("ERR unknown device", command("fault toaster off").at(0).c_str());
  faults.last_device.clear();
  STRCMP_EQUAL("ERR SECONDS must be a number in (0, 1e6]",
               command("fault camera off -1").at(0).c_str());
  STRCMP_EQUAL("ERR SECONDS must be a number in (0, 1e6]",
               command("fault camera off 0x10").at(0).c_str());
  STRCMP_EQUAL("ERR usage: fault DEVICE TYPE [SECONDS]", command("fault camera").at(0).c_str());
  CHECK(faults.last_device.empty());
}
