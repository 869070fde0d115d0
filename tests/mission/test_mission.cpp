// The mission end to end on the sim board: Look-Think-Drive finds the target without touching
// anything, checked against the world's geometry from the trace, and is deterministic.
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <csignal>
#include <cstring>
#include <numbers>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <limits>
#include <memory>
#include <optional>
#include <sstream>
#include <string>
#include <vector>

#include "algo/core/geometry.h"
#include "firmware/common/board_config.h"
#include "firmware/executive/executive.h"
#include "firmware/app/firmware_main.h"
#include "firmware/state/persistence.h"
#include "child_process.h"
#include "hal/sim/world.h"
#include "hal/sim/world_geometry.h"
#include "mission_runner.h"
#include "png_image.h"
#include "sim_board.h"
#include "world_truth_file.h"

#include "alloc_guard.h"
#include "CppUTest/TestHarness.h"
#include "CppUTest/MemoryLeakWarningPlugin.h"

namespace sim = boticelli::hal::sim;

using boticelli::test::slurp;

namespace {

// The board is large (world, textures): one static instance, re-initialised by every run.
boticelli::boards::sim::SimBoard g_board;

struct MissionRun {
  int exit_code = -1;
  std::string mission_line;
  std::string trace_text;  // the trace file as written (the file and its folder are removed)
  std::vector<sim::TraceRow> trace;
  sim::TraceCheck check{};
  double target_error_m = -1.0;
  bool telemetry_confirmed = false;     // a TLM line reported the target confirmed
  boticelli::core::Pose2 final_pose{};  // the robot's true pose when the firmware returned
  boticelli::core::Point2 target{};     // the true target (its foot on the floor)
  double calibration_ratio = -1.0;      // the end's `mission calibration` line, −1 if none
  int calibration_bases = 0;
  bool calibration_warned = false;  // the mission log said the calibration is suspect
  std::string output;               // everything the console wrote
};

// Runs firmware_main on the sim board with stdout captured; checks the trace against the
// world's colliders with the robot's disc (not the simulator's own contact counter). The
// console's stdin is at its end, or `console_in` (a pipe's read end the test types into).
MissionRun run_mission(const char* world, const char* seed, float odometry_noise = 0.0F,
                       const boticelli::firmware::MainHooks* hooks = nullptr,
                       const std::vector<const char*>& extra = {}, int console_in = -1) {
  char dir_template[] = "/tmp/boticelli-mission-XXXXXX";
  const std::string dir = mkdtemp(dir_template);
  MissionRun run;
  const std::string trace_path = dir + "/trace.csv";
  const std::string out = dir + "/stdout.txt";
  // A shipped world by name, or this test's own worlds by their path.
  const std::string path = world[0] == '/'
                               ? std::string(world)
                               : std::string(BOTICELLI_WORLDS_DIR) + "/" + world + ".sdf";
  g_board.settings() = boticelli::boards::sim::make_settings(g_board.config(), 1);
  g_board.settings().physics.base.odometry_noise = odometry_noise;
  // The console on stdio, stdin at end of file and stdout (telemetry, the MISSION line) into
  // a file.
  std::vector<const char*> argv = {"boticelli", "--world",     path.c_str(),       "--seed",
                                   seed,        "--trace",     trace_path.c_str(), "--console",
                                   "stdio",     "--max-cycles"};
  argv.push_back("45");
  for (const char* arg : extra) argv.push_back(arg);
  run.exit_code = boticelli::test::run_captured(g_board, argv, out, hooks, console_in);
  run.final_pose = g_board.robot_pose();
  run.target = {g_board.target_m().x(), g_board.target_m().y()};
  const std::string text = slurp(out);
  run.telemetry_confirmed = text.find("target=confirmed\r\n") != std::string::npos;
  const std::size_t at = text.rfind("MISSION ");
  if (at != std::string::npos) run.mission_line = text.substr(at, text.find('\n', at) - at);
  const std::size_t e = run.mission_line.find("target_error_m=");
  if (e != std::string::npos) run.target_error_m = std::atof(run.mission_line.c_str() + e + 15);
  const std::size_t k = text.find("mission calibration stereo_to_floor=");
  if (k != std::string::npos) {
    run.calibration_ratio = std::atof(text.c_str() + k + 36);
    const std::size_t b = text.find("bases=", k);
    if (b != std::string::npos) run.calibration_bases = std::atoi(text.c_str() + b + 6);
  }
  run.calibration_warned = text.find("calibration suspect") != std::string::npos;
  run.output = text;
  std::string error;
  run.trace_text = slurp(trace_path);
  if (sim::read_trace(trace_path.c_str(), run.trace, error)) {
    const auto& c = g_board.config();
    run.check = sim::check_trace(g_board.world(), run.trace, c.robot_radius_m, c.robot_height_m);
  } else {
    run.mission_line += " trace: " + error;
  }
  std::remove(out.c_str());
  std::remove(trace_path.c_str());
  rmdir(dir.c_str());
  return run;
}

// The thesis room at seed 1 with an operator: `after_frame` runs after every frame with
// `script`, whose console_fd is the write end of the console's stdin (set here).
template <class Script>
MissionRun run_mission_typing(Script& script, void (*after_frame)(void*),
                              const std::vector<const char*>& extra) {
  int console[2] = {-1, -1};
  CHECK(pipe(console) == 0);
  script.console_fd = console[1];
  boticelli::firmware::MainHooks hooks;
  hooks.after_frame = after_frame;
  hooks.context = &script;
  const MissionRun r = run_mission("thesis_room", "1", 0.0F, &hooks, extra, console[0]);
  close(console[0]);
  close(console[1]);
  return r;
}

// Loads the mission state a run saved in `dir` into `into` (large: the caller's static); false
// with the reason in `why`.
bool load_state(const std::string& dir, boticelli::firmware::MissionState& into, std::string& why) {
  static boticelli::firmware::StateStore store;
  char error[256] = "";
  const bool ok = store.open(dir.c_str(), error, sizeof error) &&
                  store.load(into, error, sizeof error) == boticelli::firmware::LoadResult::kLoaded;
  why = error;
  return ok;
}

// Removes a mission's state directory: its two state copies and the sim world's truth file.
void remove_state_dir(const std::string& dir) {
  for (const char* name : {"/mission.state.a", "/mission.state.b", "/sim-world.truth"}) {
    std::remove((dir + name).c_str());
  }
  rmdir(dir.c_str());
}

// Where each look began: the trace's rows where the state becomes "look".
std::vector<sim::TraceRow> look_starts(const MissionRun& r) {
  std::vector<sim::TraceRow> looks;
  for (std::size_t i = 1; i < r.trace.size(); ++i) {
    if (std::string(r.trace[i].state) == "look" && std::string(r.trace[i - 1].state) != "look") {
      looks.push_back(r.trace[i]);
    }
  }
  return looks;
}

// The cycles the MISSION line reports.
int cycles_of(const MissionRun& r) {
  const std::size_t c = r.mission_line.find("cycles=");
  return c == std::string::npos ? -1 : std::atoi(r.mission_line.c_str() + c + 7);
}

void check_found_safely(const MissionRun& r) {
  CHECK_EQUAL_TEXT(0, r.exit_code, r.mission_line.c_str());
  STRCMP_CONTAINS("MISSION result=found", r.mission_line.c_str());
  CHECK_TEXT(r.check.rows > 100, r.mission_line.c_str());
  UNSIGNED_LONGS_EQUAL_TEXT(0, r.check.collisions, r.mission_line.c_str());
  CHECK_TEXT(r.check.min_clearance_m > 0.0, r.mission_line.c_str());
  CHECK_TEXT(r.check.max_gap_s <= 0.1001, "a trace row at least every 0.1 s");
  CHECK_TEXT(r.target_error_m >= 0.0 && r.target_error_m <= 0.3, r.mission_line.c_str());
  CHECK_TEXT(r.telemetry_confirmed, "telemetry shows the confirmed target");
  // Where the robot stopped, not only where it thinks the target is: within the stand-off
  // (and its arrival tolerance) of the estimate, which is within 0.3 m of the truth, with
  // 0.1 m for the odometry.
  const boticelli::firmware::BoardConfig defaults;
  const float stopped_m =
      boticelli::core::distance_m({r.final_pose.x_m, r.final_pose.y_m}, r.target);
  const std::string why =
      r.mission_line + " stopped " + std::to_string(stopped_m) + " m from the true target";
  CHECK_TEXT(stopped_m <= defaults.goal_standoff_m + 0.05F + 0.3F + 0.1F, why.c_str());
}

}  // namespace

// The board allocates its world, textures and buffers at init and keeps them for the next run
// (static storage, as on the robot): not leaks, so CppUTest's leak check is off here.
#define MISSION_GROUP(name)                                        \
  TEST_GROUP(name) {                                               \
    void setup() override {                                        \
      MemoryLeakWarningPlugin::saveAndDisableNewDeleteOverloads(); \
    }                                                              \
    void teardown() override {                                     \
      MemoryLeakWarningPlugin::restoreNewDeleteOverloads();        \
    }                                                              \
  }

MISSION_GROUP(MissionThesisRoom);
MISSION_GROUP(MissionSeeds);
MISSION_GROUP(MissionRooms);
MISSION_GROUP(MissionEstop);
MISSION_GROUP(MissionResume);

namespace {
// How far the run's odometry (mapped from the start pose) ended from the trace's last, true
// pose [m].
double odometry_drift_m(const MissionRun& r) {
  const sim::TraceRow& first = r.trace.front();
  const sim::TraceRow& last = r.trace.back();
  CHECK(last.has_pose_columns);
  const double* odo = last.odo;  // mission frame
  const boticelli::core::Point2 odo_world =
      boticelli::core::to_world({static_cast<float>(first.x_m), static_cast<float>(first.y_m),
                                 static_cast<float>(first.yaw_rad)},
                                {static_cast<float>(odo[0]), static_cast<float>(odo[1])});
  return std::hypot(static_cast<double>(odo_world.x_m) - last.x_m,
                    static_cast<double>(odo_world.y_m) - last.y_m);
}
}  // namespace

TEST(MissionSeeds, FindsItWithTwoPercentOdometryNoiseAndTheTraceShowsTheTruePose) {
  // The same seed without noise: odometry ends where the robot truly is (to float rounding).
  const MissionRun clean = run_mission("thesis_room", "2", 0.0F);
  check_found_safely(clean);
  const double clean_drift = odometry_drift_m(clean);
  const MissionRun r = run_mission("thesis_room", "2", 0.02F);
  check_found_safely(r);
  // The trace's pose is the simulator's true one (where the robot stopped), not odometry,
  // which the noise has carried away from it (odometry columns, mapped from the start pose).
  const sim::TraceRow& last = r.trace.back();
  const boticelli::core::Pose2 truth = g_board.sim().true_pose();
  DOUBLES_EQUAL(truth.x_m, last.x_m, 0.02);
  DOUBLES_EQUAL(truth.y_m, last.y_m, 0.02);
  const double drift = odometry_drift_m(r);
  // Measured: 0.01-0.02 mm without noise, 4-17 mm with it (depending on the path's length).
  const std::string drift_text = "odometry " + std::to_string(drift) + " m from the true pose (" +
                                 std::to_string(clean_drift) + " m without noise)";
  CHECK_TEXT(clean_drift < 0.0005, drift_text.c_str());
  CHECK_TEXT(drift > 0.001 && drift > 20.0 * clean_drift, drift_text.c_str());
}

// With seed 2 above and seeds 1 and 3 below: five seeds.
TEST(MissionSeeds, FindsItForTwoMoreSeeds) {
  for (const char* seed : {"4", "5"}) {
    const MissionRun r = run_mission("thesis_room", seed);
    check_found_safely(r);
  }
}

// Counts heap allocations from the loop's first frame to its last (after every init). Frame
// overruns are not checked here: the sim board's time moves only when the executive sleeps,
// so every measured duration is 0 and such a check could not fail.
struct LoopCount {
  std::size_t allocations = 0;
  std::uint64_t frames = 0;
  bool ended = false;
};
std::optional<boticelli::test::AllocationGuard> g_loop_guard;

void on_loop_started(void*) {
  g_loop_guard.emplace();
}

void on_loop_ended(void* context, const boticelli::firmware::Executive& executive) {
  auto* count = static_cast<LoopCount*>(context);
  count->allocations = g_loop_guard->allocations();
  g_loop_guard.reset();
  const boticelli::firmware::FrameStats& stats = executive.frame_stats();
  count->frames = stats.frames;
  count->ended = true;
}

TEST(MissionThesisRoom, AWholeMissionAfterInitAllocatesNothing) {
  // The guard sees allocations with the leak check's operators off (this group's setting):
  // a canary, so the zero below means something.
  std::size_t canary = 0;
  {
    boticelli::test::AllocationGuard guard;
    int* volatile p = new int(1);
    delete p;
    canary = guard.allocations();
  }
  CHECK(canary > 0);
  LoopCount count;
  boticelli::firmware::MainHooks hooks;
  hooks.loop_started = on_loop_started;
  hooks.loop_ended = on_loop_ended;
  hooks.context = &count;
  // With --snapshots: the pictures are drawn and encoded on the same allocation-free path.
  char dir_template[] = "/tmp/boticelli-snapshots-XXXXXX";
  const std::string dir = mkdtemp(dir_template);
  const MissionRun r = run_mission("thesis_room", "1", 0.0F, &hooks, {"--snapshots", dir.c_str()});
  check_found_safely(r);
  CHECK(count.ended);
  CHECK(count.frames > 10000);
  UNSIGNED_LONGS_EQUAL_TEXT(0, count.allocations, "heap allocations after init");
  // The CPU each stage took, as the end of the run reports it: every stage had its share, and
  // every kind of unit ran (snapshots included).
  const auto number_after = [&](const char* line_start, const char* key) {
    const std::size_t line = r.output.find(line_start);
    if (line == std::string::npos) return -1.0;
    const std::size_t at = r.output.find(std::string(" ") + key + "=", line);
    const std::size_t eol = r.output.find('\n', line);
    if (at == std::string::npos || at > eol) return -1.0;
    return std::atof(r.output.c_str() + at + std::strlen(key) + 2);
  };
  for (const char* stage : {"look_s", "think_s", "plan_s"}) {
    CHECK_TEXT(number_after("mission cpu ", stage) > 0.0, stage);
  }
  for (const char* unit : {"view", "model", "map", "value", "step", "snapshot"}) {
    CHECK_TEXT(number_after("mission longest_ms ", unit) > 0.0, unit);
  }
  // One PNG per cycle, the last one included.
  const int cycles = cycles_of(r);
  CHECK(cycles > 1);
  for (int i = 1; i <= cycles; ++i) {
    char name[64];
    std::snprintf(name, sizeof name, "/cycle-%06d.png", i);
    const std::string png = slurp(dir + name);
    CHECK_TEXT(png.size() > 1000 && png.compare(0, 8, "\x89PNG\r\n\x1a\n") == 0, name);
    // The last picture shows what the mission passed it: the world's true walls (magenta,
    // the sim's truth) and the world memory's free and occupied cells (the grid).
    if (i == cycles) {
      boticelli::test::RgbImage last;
      CHECK_TEXT(boticelli::test::read_png(dir + name, last), name);
      CHECK_TEXT(last.count({255, 0, 255}) > 200, "the true walls drawn");
      CHECK_TEXT(last.count({232, 232, 232}) > 200, "the grid's free cells drawn");
      CHECK_TEXT(last.count({70, 70, 70}) > 20, "the grid's occupied cells drawn");
    }
    std::remove((dir + name).c_str());
  }
  CHECK_TEXT(rmdir(dir.c_str()) == 0, "nothing else in the snapshot folder");
}

TEST(MissionThesisRoom, TheSameSeedGivesTheSameTraceBitForBit) {
  const MissionRun a = run_mission("thesis_room", "3");
  const MissionRun b = run_mission("thesis_room", "3");
  check_found_safely(a);
  CHECK(a.trace_text == b.trace_text);
  // The calibration self-check: with the camera as configured the stereo's distances at the
  // obstacles' bases are the floor's, and nothing is reported.
  CHECK_TEXT(a.calibration_bases >= 100, a.mission_line.c_str());
  DOUBLES_EQUAL(1.0, a.calibration_ratio, 0.03);
  CHECK_FALSE(a.calibration_warned);
}

// A camera whose focal length is 1 % longer than configured, or whose lens is 0.15 more barrel
// than configured (an uncalibrated webcam), the simulator drawing through it and the firmware
// told the configured one: after the first look the console says the calibration is suspect.
// The focal length's bias, learnt from that look, goes into the state: the mission resumed
// reads its first look corrected (the floor's ratio within 1 ± 0.03, nothing suspect).
TEST(MissionThesisRoom, ACalibrationOffIsReportedAfterTheFirstLook) {
  for (const char* error : {"focal_scale = 1.01", "lens_k1_error = -0.15"}) {
    char dir_template[] = "/tmp/boticelli-calibration-XXXXXX";
    const std::string dir = mkdtemp(dir_template);
    const std::string conf = dir + "/sim.conf";
    FILE* f = std::fopen(conf.c_str(), "w");
    CHECK(f != nullptr);
    std::fprintf(f, "[sim]\n%s\n", error);
    std::fclose(f);
    const MissionRun r =
        run_mission("thesis_room", "1", 0.0F, nullptr,
                    {"--config", conf.c_str(), "--state", dir.c_str(), "--max-cycles", "1"});
    const std::string what = std::string(error) + ": " + r.mission_line;
    CHECK_TEXT(r.calibration_warned, what.c_str());
    CHECK_TEXT(r.calibration_bases >= 30, what.c_str());
    CHECK_TEXT(std::fabs(r.calibration_ratio - 1.0) > 0.03, what.c_str());
    if (std::strncmp(error, "focal", 5) == 0) {
      const MissionRun resumed = run_mission(
          "thesis_room", "1", 0.0F, nullptr,
          {"--config", conf.c_str(), "--state", dir.c_str(), "--resume", "--max-cycles", "1"});
      const std::string again = "resumed: " + resumed.mission_line;
      CHECK_TEXT(resumed.calibration_bases >= 30, again.c_str());
      DOUBLES_EQUAL_TEXT(1.0, resumed.calibration_ratio, 0.03, again.c_str());
      CHECK_FALSE_TEXT(resumed.calibration_warned, again.c_str());
    }
    std::remove(conf.c_str());
    remove_state_dir(dir);
  }
}

namespace {
// The operator pauses the mission at 31 s of simulated time and resumes it at 33 s: later
// than the device retry time (30 s) after the mission began.
struct PauseScript {
  int console_fd = -1;
  int typed = 0;
};
void on_frame_pause(void* context) {
  auto* p = static_cast<PauseScript*>(context);
  const std::uint64_t now = g_board.sim().now_us();
  const char* text = p->typed == 0 && now >= 6500000U    ? "pause\r"
                     : p->typed == 1 && now >= 12000000U ? "resume\r"
                     : p->typed == 2 && now >= 31000000U ? "pause\r"
                     : p->typed == 3 && now >= 33000000U ? "resume\r"
                                                         : nullptr;
  if (text == nullptr) return;
  CHECK(write(p->console_fd, text, std::strlen(text)) == static_cast<ssize_t>(std::strlen(text)));
  ++p->typed;
}
}  // namespace

// The camera gone for 5 s in the first look (a cable pulled and pushed back): the mission holds,
// its telemetry says so, and it goes on looking once frames come again. The operator pauses
// during the outage (6.5 s) and resumes at 12 s: the camera coming back does not end a hold the
// operator asked for. A pause and resume afterwards (31 s, 33 s) is a hold of its own: the
// device hold is over, so it does not count the time since the camera's fault and give up.
TEST(MissionThesisRoom, ACameraGoneForFiveSecondsHoldsTheMissionUntilFramesComeAgain) {
  char dir_template[] = "/tmp/boticelli-faults-XXXXXX";
  const std::string dir = mkdtemp(dir_template);
  const std::string plan = dir + "/faults.txt";
  FILE* f = std::fopen(plan.c_str(), "w");
  CHECK(f != nullptr);
  std::fputs("3 camera off 5\n", f);
  std::fclose(f);
  PauseScript pause;
  const MissionRun r =
      run_mission_typing(pause, on_frame_pause, {"--faults", plan.c_str(), "--max-cycles", "1"});
  std::remove(plan.c_str());
  rmdir(dir.c_str());
  const std::size_t hold = r.output.find("state=hold");
  CHECK_TEXT(hold != std::string::npos, r.mission_line.c_str());
  const std::size_t looking = r.output.find("state=look", hold);
  CHECK_TEXT(looking != std::string::npos, r.mission_line.c_str());
  CHECK_EQUAL(4, pause.typed);
  // Held from the outage until the operator's resume, though the camera came back at 8 s.
  bool looked_after_resume = false;
  double held_from_s = -1.0;
  for (const sim::TraceRow& row : r.trace) {
    if (held_from_s < 0.0 && std::string(row.state) == "hold") held_from_s = row.t_s;
    if (held_from_s >= 0.0 && row.t_s < 11.9) {
      STRCMP_EQUAL_TEXT("hold", row.state, std::to_string(row.t_s).c_str());
    }
    looked_after_resume =
        looked_after_resume || (row.t_s > 12.0 && std::string(row.state) == "look");
  }
  CHECK_TEXT(held_from_s > 3.0 && held_from_s < 6.4, std::to_string(held_from_s).c_str());
  CHECK(looked_after_resume);
  CHECK_TEXT(r.output.find("state=hold", looking) != std::string::npos, "held by the pause");
  CHECK_TEXT(r.mission_line.find("result=aborted") == std::string::npos, r.mission_line.c_str());
  UNSIGNED_LONGS_EQUAL(0, r.check.collisions);
  STRCMP_CONTAINS("cycles=1", r.mission_line.c_str());
}

// A pan-tilt unit that refuses every move from 3 s on, with the device retry time cut to 5 s
// (`[faults] retry_s`): its driver stays healthy (it answers), so the mission's own hold gives
// up: it holds, tries the move again every second, and after 5 s ends for a restart (exit 1,
// the state still running, so `--resume` carries it on). Its reason is the hold's, once (not a
// copy per retry), and the mission log's last entry holds it whole, as far as an entry's 95
// bytes go.
TEST(MissionThesisRoom, APanTiltUnitRefusingEveryMoveEndsTheMissionForARestartWithTheReasonOnce) {
  char dir_template[] = "/tmp/boticelli-giveup-XXXXXX";
  const std::string dir = mkdtemp(dir_template);
  const std::string plan = dir + "/faults.txt";
  const std::string conf = dir + "/boticelli.conf";
  std::ofstream(plan) << "3 ptu wrong 600\n";
  std::ofstream(conf) << "[faults]\nretry_s = 5\n";
  const MissionRun r = run_mission("thesis_room", "1", 0.0F, nullptr,
                                   {"--faults", plan.c_str(), "--config", conf.c_str(), "--state",
                                    dir.c_str(), "--max-cycles", "3"});
  static boticelli::firmware::MissionState state;
  std::string error;
  const bool loaded = load_state(dir, state, error);
  std::remove(plan.c_str());
  std::remove(conf.c_str());
  remove_state_dir(dir);
  CHECK_TEXT(loaded, error.c_str());
  CHECK_EQUAL_TEXT(boticelli::firmware::kExitFailure, r.exit_code, r.mission_line.c_str());
  STRCMP_CONTAINS("MISSION result=aborted", r.mission_line.c_str());
  const std::size_t q = r.mission_line.find("reason=\"");
  CHECK_TEXT(q != std::string::npos, r.mission_line.c_str());
  const std::string reason = r.mission_line.substr(q + 8, r.mission_line.size() - q - 9);
  // The hold's first entry in the mission log gives its reason; the give-up repeats it once.
  std::string held;
  for (const boticelli::firmware::MissionLogEntry& e : state.log) {
    const std::string text = e.text.data();
    if (held.empty() && text.rfind("held: ", 0) == 0) held = text.substr(6);
  }
  STRCMP_CONTAINS_TEXT("pan-tilt unit refused a move", held.c_str(), reason.c_str());
  STRCMP_EQUAL(("gave up after 5 s: " + held).c_str(), reason.c_str());
  CHECK_TEXT(state.end == boticelli::firmware::MissionEnd::kRunning, "resumable");
  CHECK_TEXT(!state.log.empty(), "a mission log");
  const std::string last = state.log.back().text.data();
  const std::string whole =
      ("mission aborted: " + reason).substr(0, boticelli::firmware::MissionLogEntry::kMaxTextBytes);
  STRCMP_EQUAL(whole.c_str(), last.c_str());
  // Long enough that a shorter entry would cut it (the PTU's own words follow).
  CHECK_TEXT(whole.size() >= boticelli::firmware::MissionLogEntry::kMaxTextBytes - 1, last.c_str());
  UNSIGNED_LONGS_EQUAL(0, r.check.collisions);
}

namespace {
// Takes the target away once the robot is within 1.2 m of it (on its way to the stand-off,
// 0.75 m, to a confirmed target or a provisional candidate).
struct TakeTarget {
  bool removed = false;
};
void on_frame_take_target(void* context) {
  auto* t = static_cast<TakeTarget*>(context);
  if (t->removed) return;
  const boticelli::core::Pose2 p = g_board.robot_pose();
  const Eigen::Vector3f target = g_board.target_m();
  if (std::hypot(p.x_m - target.x(), p.y_m - target.y()) < 1.2F) {
    g_board.remove_target();
    t->removed = true;
  }
}

// `world` at seed 1 for at most `max_cycles`, the target taken away as the robot comes within
// 1.2 m of it (checked to have happened), the run's state left in `state`.
MissionRun run_taking_target(const char* world, const char* max_cycles,
                             boticelli::firmware::MissionState& state) {
  char dir_template[] = "/tmp/boticelli-take-XXXXXX";
  const std::string dir = mkdtemp(dir_template);
  TakeTarget take;
  boticelli::firmware::MainHooks hooks;
  hooks.after_frame = on_frame_take_target;
  hooks.context = &take;
  const MissionRun r =
      run_mission(world, "1", 0.0F, &hooks, {"--state", dir.c_str(), "--max-cycles", max_cycles});
  std::string error;
  const bool loaded = load_state(dir, state, error);
  remove_state_dir(dir);
  CHECK_TEXT(loaded, error.c_str());
  CHECK(take.removed);
  return r;
}
}  // namespace

// A confirmed target that is gone when the robot reaches its stand-off is not found: the
// glance from the stand-off misses it (one miss, the aimed pair's), the next look's aimed pair
// misses it again and revokes it, and the mission goes on without it.
TEST(MissionThesisRoom, AConfirmedTargetGoneWhenTheRobotArrivesIsMissedThenRevokedNotFound) {
  static boticelli::firmware::MissionState state;
  const MissionRun r = run_taking_target("thesis_room", "20", state);
  // The state holds the world memory as the last cycle left it (what a resume starts from).
  DOUBLES_EQUAL(0.05, state.grid_cell_m, 1e-6);
  CHECK_TEXT(state.grid.size() > 20, std::to_string(state.grid.size()).c_str());
  CHECK_TEXT(r.telemetry_confirmed, r.mission_line.c_str());
  CHECK_TEXT(r.mission_line.find("result=found") == std::string::npos, r.mission_line.c_str());
  UNSIGNED_LONGS_EQUAL(0, r.check.collisions);
  // The mission log: the stand-off's miss, then the revocation.
  std::string first_standoff;
  bool revoked = false;
  std::string entries;
  for (const boticelli::firmware::MissionLogEntry& e : state.log) {
    const std::string text = e.text.data();
    entries += text + " | ";
    if (first_standoff.empty() && text.find("stand-off") != std::string::npos &&
        text.find("at the target's stand-off") == std::string::npos) {
      first_standoff = text;
    }
    revoked = revoked || text.find("revoked") != std::string::npos;
  }
  STRCMP_CONTAINS_TEXT("target not seen from its stand-off", first_standoff.c_str(),
                       entries.c_str());
  CHECK_TEXT(revoked, entries.c_str());
}

// A candidate two views of the first look agree on is gone to before any second place has
// seen it (MissionParams::candidate_as_goal); taken away as the robot comes near, it is not
// seen from its stand-off and is dismissed: never confirmed, not found, nothing touched.
TEST(MissionThesisRoom, ACandidateGoneWhenTheRobotArrivesIsDismissedNotConfirmed) {
  static boticelli::firmware::MissionState state;
  const MissionRun r = run_taking_target("rectangular_room", "4", state);
  CHECK_TEXT(!r.telemetry_confirmed, r.mission_line.c_str());
  CHECK_TEXT(r.mission_line.find("result=found") == std::string::npos, r.mission_line.c_str());
  UNSIGNED_LONGS_EQUAL(0, r.check.collisions);
  std::vector<std::string> entries;
  std::string all;
  for (const boticelli::firmware::MissionLogEntry& e : state.log) {
    entries.emplace_back(e.text.data());
    all += entries.back() + " | ";
  }
  // The first cycle: the candidate's stand-off reached; the glance's miss dismisses it.
  CHECK_TEXT(entries.size() >= 2, all.c_str());
  STRCMP_CONTAINS_TEXT("at the target's stand-off", entries[0].c_str(), all.c_str());
  STRCMP_CONTAINS_TEXT("target candidate not seen from its stand-off: dismissed",
                       entries[1].c_str(), all.c_str());
}

TEST(MissionRooms, EveryOtherShippedRoomWithATargetIsFoundWithoutTouchingAnything) {
  for (const char* world : {"box_in_cylindrical_room", "box_in_rectangular_room", "cluttered_room",
                            "corridor", "cylindrical_room", "cylindrical_room_offcentre",
                            "l_shaped_room", "rectangular_room", "two_rooms_doorway"}) {
    const MissionRun r = run_mission(world, "1");
    const std::string what = std::string(world) + ": " + r.mission_line;
    CHECK_EQUAL_TEXT(0, r.exit_code, what.c_str());
    UNSIGNED_LONGS_EQUAL_TEXT(0, r.check.collisions, what.c_str());
    CHECK_TEXT(r.check.rows > 100, what.c_str());
    CHECK_TEXT(r.target_error_m >= 0.0 && r.target_error_m <= 0.3, what.c_str());
  }
}

// A 6 x 6 m room of this test's own: the target on the north wall is seen from the start over
// a row of low crates that bars the straight way, with one gap at the row's east end. The
// robot goes round by the grid's path and steps to the target's stand-off by the grid when
// the look's polygon stops short of the wall: found, nothing touched, at most 3 times back
// the way it came (before the final approach by the grid it crawled along the wall, 8 times).
TEST(MissionRooms, AFarTargetBehindARowOfCratesIsReachedRoundItWithoutDrivingBackAndForth) {
  const std::string world = std::string(BOTICELLI_TEST_WORLDS_DIR) + "/barred_far_target.sdf";
  const MissionRun r = run_mission(world.c_str(), "1");
  check_found_safely(r);
  const std::size_t back = sim::count_reversals(r.trace);
  const std::string what = r.mission_line + ", " + std::to_string(back) + " reversals";
  CHECK_TEXT(back <= 3, what.c_str());
}

// A cluttered room of tests/worlds (low boxes, a table) at seed 1: at cycle 12 the robot finds
// no safe step a second time in a row and backs off along the step that brought it there.
// The back-off ends its cycle, and the robot looks again before it steps on: every cycle is
// one look (a step planned on the look from before the back-off would start from where that
// look no longer holds).
TEST(MissionRooms, AfterBackingOffTheRobotLooksAgainBeforeItStepsOn) {
  char dir_template[] = "/tmp/boticelli-backoff-XXXXXX";
  const std::string dir = mkdtemp(dir_template);
  const MissionRun r =
      run_mission(BOTICELLI_UNSEEN_WORLDS_DIR "/cluttered_low_boxes_table.sdf", "1", 0.0F, nullptr,
                  {"--state", dir.c_str(), "--max-cycles", "13"});
  static boticelli::firmware::MissionState state;
  std::string error;
  const bool loaded = load_state(dir, state, error);
  remove_state_dir(dir);
  CHECK_TEXT(loaded, error.c_str());
  bool backed_off = false;
  for (const boticelli::firmware::MissionLogEntry& e : state.log) {
    backed_off = backed_off || std::strstr(e.text.data(), "backed off") != nullptr;
  }
  CHECK_TEXT(backed_off, "a back-off to check (the scenario needs one)");
  UNSIGNED_LONGS_EQUAL_TEXT(0, r.check.collisions, r.mission_line.c_str());
  LONGS_EQUAL_TEXT(cycles_of(r), look_starts(r).size(), r.mission_line.c_str());
}

// A closed 3 x 3 m room whose target hangs outside it: the robot explores the room and gives
// up, and every time nothing is left to explore it first turns round where it stands and
// looks once more (the sector behind it is seen only at the image's edges, and a fresh look
// refits the model); it gives up only where it has turned round already.
TEST(MissionRooms, WithNothingLeftToExploreTheRobotTurnsRoundAndLooksOnceMoreBeforeGivingUp) {
  const std::string world =
      std::string(BOTICELLI_TEST_WORLDS_DIR) + "/closed_room_target_outside.sdf";
  const MissionRun r = run_mission(world.c_str(), "1");
  CHECK_TEXT(r.exit_code != 0, r.mission_line.c_str());
  STRCMP_CONTAINS("result=not_found", r.mission_line.c_str());
  STRCMP_CONTAINS("reason=\"nothing left to explore\"", r.mission_line.c_str());
  UNSIGNED_LONGS_EQUAL_TEXT(0, r.check.collisions, r.mission_line.c_str());
  // Where each look began; a turn round is a look begun where the last one was, half a turn
  // from its heading.
  const std::vector<sim::TraceRow> looks = look_starts(r);
  std::vector<std::size_t> turns;
  for (std::size_t i = 1; i < looks.size(); ++i) {
    const double moved =
        std::hypot(looks[i].x_m - looks[i - 1].x_m, looks[i].y_m - looks[i - 1].y_m);
    const double turned =
        std::fabs(std::remainder(looks[i].yaw_rad - looks[i - 1].yaw_rad, 2.0 * std::numbers::pi));
    if (moved < 0.02 && turned > std::numbers::pi - 0.2) turns.push_back(i);
  }
  CHECK_TEXT(!turns.empty(), r.mission_line.c_str());
  // Every cycle is one look, those after a turn round included (and the last, which ends in
  // its plan).
  LONGS_EQUAL_TEXT(cycles_of(r), looks.size(), r.mission_line.c_str());
  // The last look is within 0.5 m of the last turn's place.
  const sim::TraceRow& turn = looks[turns.back()];
  CHECK(std::hypot(looks.back().x_m - turn.x_m, looks.back().y_m - turn.y_m) < 0.5);
}

// Presses the e-stop the first time the base drives forward and releases it 3 s of simulated
// time later; the operator types `clear-estop` 5 s after the release and `resume` 2 s after
// that (into the console's stdin, a pipe). Records what the base did meanwhile.
struct EstopScript {
  enum Phase { kWaiting, kPressed, kReleased, kCleared, kResumed };
  Phase phase = kWaiting;
  int console_fd = -1;  // the write end of the console's stdin
  std::uint64_t pressed_us = 0;
  std::uint64_t released_us = 0;
  std::uint64_t cleared_us = 0;
  std::uint64_t resumed_us = 0;
  int frames_to_stop = -1;  // frames after the press until the base reported stopped
  int frames = 0;
  boticelli::core::Pose2 settled{};  // true pose 1 s after the press
  bool settled_taken = false;
  // Farthest from the settled pose (m + rad) while pressed, after the release until the
  // reset, and after the reset until the resume.
  float moved_while_pressed_m = -1.0F;
  float moved_after_release_m = -1.0F;
  float moved_after_reset_m = -1.0F;
  bool stopped_until_resume = true;  // the base reported stopped at every frame before it
  bool asked_status = false;         // `status` typed near the target, after the resume
};

void on_frame_estop(void* context) {
  auto* e = static_cast<EstopScript*>(context);
  sim::SimWorld& w = g_board.sim();
  const std::uint64_t now = w.now_us();
  if (e->phase == EstopScript::kWaiting) {
    if (w.odometry().v_m_s > 0.1F && w.base_health() == boticelli::hal::BaseHealth::kReady) {
      w.set_estop_pressed(true);
      e->pressed_us = now;
      e->phase = EstopScript::kPressed;
    }
    return;
  }
  if (e->phase == EstopScript::kResumed) {
    // Near the target (on the way to its stand-off, so confirmed): what the operator sees of
    // it; the reply is checked after the run.
    const boticelli::core::Pose2 p = w.true_pose();
    const Eigen::Vector3f target = g_board.target_m();
    if (!e->asked_status && std::hypot(p.x_m - target.x(), p.y_m - target.y()) < 1.2F) {
      e->asked_status = true;
      const char* text = "status\r";
      CHECK(write(e->console_fd, text, std::strlen(text)) ==
            static_cast<ssize_t>(std::strlen(text)));
    }
    return;
  }
  ++e->frames;
  const bool stopped = w.base_health() == boticelli::hal::BaseHealth::kStopped;
  if (e->frames_to_stop < 0 && stopped) e->frames_to_stop = e->frames;
  if (e->frames_to_stop >= 0 && !stopped) e->stopped_until_resume = false;
  const boticelli::core::Pose2 p = w.true_pose();
  if (!e->settled_taken && now >= e->pressed_us + 1000000U) {
    e->settled = p;
    e->settled_taken = true;
  }
  if (e->settled_taken) {
    const float moved = std::hypot(p.x_m - e->settled.x_m, p.y_m - e->settled.y_m) +
                        std::fabs(p.yaw_rad - e->settled.yaw_rad);
    float& farthest = e->phase == EstopScript::kPressed    ? e->moved_while_pressed_m
                      : e->phase == EstopScript::kReleased ? e->moved_after_release_m
                                                           : e->moved_after_reset_m;
    farthest = std::max(farthest, moved);
  }
  const auto type = [e](const char* text) {
    CHECK(write(e->console_fd, text, std::strlen(text)) == static_cast<ssize_t>(std::strlen(text)));
  };
  if (e->phase == EstopScript::kPressed && now >= e->pressed_us + 3000000U) {
    w.set_estop_pressed(false);
    e->released_us = now;
    e->phase = EstopScript::kReleased;
  } else if (e->phase == EstopScript::kReleased && now >= e->released_us + 5000000U) {
    type("clear-estop\r");
    e->cleared_us = now;
    e->phase = EstopScript::kCleared;
  } else if (e->phase == EstopScript::kCleared && now >= e->cleared_us + 2000000U) {
    type("resume\r");
    e->resumed_us = now;
    e->phase = EstopScript::kResumed;
  }
}

TEST(MissionEstop, PressedMidDriveTheBaseStopsAndStaysStoppedUntilClearEstopAndResume) {
  EstopScript e;
  const MissionRun r = run_mission_typing(e, on_frame_estop, {});
  CHECK_EQUAL(EstopScript::kResumed, e.phase);
  CHECK_TEXT(e.frames_to_stop >= 1 && e.frames_to_stop <= 1, "the base stops within one frame");
  // Not a millimetre while pressed, in the 5 s after the release (no reset) and in the 2 s
  // after the reset (no resume); the base stopped all along (what tells when the robot would
  // not move anyway: a held drive is followed by a look).
  DOUBLES_EQUAL(0.0, e.moved_while_pressed_m, 1e-6);
  DOUBLES_EQUAL(0.0, e.moved_after_release_m, 1e-6);
  DOUBLES_EQUAL(0.0, e.moved_after_reset_m, 1e-6);
  CHECK(e.stopped_until_resume);
  // The trace: held from the press to the resume, then more driving; the mission ends found.
  bool held = false;
  bool drove_after = false;
  for (const sim::TraceRow& row : r.trace) {
    const double t_us = row.t_s * 1e6;
    if (t_us < static_cast<double>(e.pressed_us) + 50000.0) continue;
    const bool hold = std::string(row.state) == "hold";
    if (t_us < static_cast<double>(e.resumed_us)) {
      CHECK_TEXT(hold, ("not held at t_s=" + std::to_string(row.t_s)).c_str());
    }
    held = held || hold;
    drove_after = drove_after ||
                  (t_us > static_cast<double>(e.resumed_us) && std::string(row.state) == "drive");
  }
  CHECK(held);
  CHECK(drove_after);
  check_found_safely(r);
  // `status` near the target gives it confirmed and where, in the mission frame (the start
  // pose's), within 0.3 m of the truth there.
  CHECK(e.asked_status);
  const std::size_t status = r.output.find("status state=");
  CHECK_TEXT(status != std::string::npos, "a status reply");
  const std::string reply = r.output.substr(status, r.output.find('\n', status) - status);
  STRCMP_CONTAINS_TEXT(" target=confirmed ", reply.c_str(), reply.c_str());
  const std::size_t x = reply.find("target_x_m=");
  const std::size_t y = reply.find("target_y_m=");
  CHECK_TEXT(x != std::string::npos && y != std::string::npos, reply.c_str());
  const sim::TraceRow& start = r.trace.front();
  const boticelli::core::Point2 truth =
      boticelli::core::to_robot({static_cast<float>(start.x_m), static_cast<float>(start.y_m),
                                 static_cast<float>(start.yaw_rad)},
                                r.target);
  const float off_m = std::hypot(static_cast<float>(std::atof(reply.c_str() + x + 11)) - truth.x_m,
                                 static_cast<float>(std::atof(reply.c_str() + y + 11)) - truth.y_m);
  CHECK_TEXT(off_m <= 0.3F, (reply + ", " + std::to_string(off_m) + " m off").c_str());
  // The interrupted step ends its cycle and the robot looks again before it drives: every
  // cycle is still one look, and one look more ends the mission (the glance from the
  // stand-off that sees the target ends it without ending a cycle).
  LONGS_EQUAL_TEXT(cycles_of(r) + 1, look_starts(r).size(), r.mission_line.c_str());
}

namespace {
// Watches the state directory frame by frame: a save replaces a copy (a new inode, the atomic
// rename), so each one is seen in the frame it happened; meanwhile the true pose tells when
// the robot moves.
struct PoseSaveWatch {
  std::string dir;
  bool started = false;
  std::uint64_t last_save_us = 0;
  std::uint64_t worst_gap_moving_us = 0;  // the longest time moving since the last save
  int saves_while_moving = 0;
  int moving_frames = 0;
  ino_t inodes[2] = {0, 0};
  bool was_moving = false;
  boticelli::core::Pose2 last{};
};
void watch_pose_saves(void* context) {
  auto* w = static_cast<PoseSaveWatch*>(context);
  const std::uint64_t now = g_board.hal().clock.now_us();
  const boticelli::core::Pose2 p = g_board.robot_pose();
  bool saved = false;
  const char* names[2] = {"/mission.state.a", "/mission.state.b"};
  for (int i = 0; i < 2; ++i) {
    struct stat st {};
    if (stat((w->dir + names[i]).c_str(), &st) == 0 && st.st_ino != w->inodes[i]) {
      w->inodes[i] = st.st_ino;
      saved = true;
    }
  }
  const bool moving = w->started && (std::hypot(p.x_m - w->last.x_m, p.y_m - w->last.y_m) > 1e-6F ||
                                     std::fabs(p.yaw_rad - w->last.yaw_rad) > 1e-6F);
  if (!w->started || saved) w->last_save_us = now;
  if (saved && moving) ++w->saves_while_moving;
  // From the start of a drive (still before) or the last save, whichever is later.
  if (moving && !w->was_moving) w->last_save_us = std::max(w->last_save_us, now);
  w->was_moving = moving;
  if (moving) {
    ++w->moving_frames;
    w->worst_gap_moving_us = std::max(w->worst_gap_moving_us, now - w->last_save_us);
  }
  w->started = true;
  w->last = p;
}
}  // namespace

// Resume keeps the pose: while the robot drives, its pose goes to the state at least every
// second (and at the end of each step), so a firmware killed mid-step resumes near where the
// robot stands, not where the last cycle ended.
TEST(MissionResume, WhileDrivingThePoseIsSavedAtLeastEverySecond) {
  char dir_template[] = "/tmp/boticelli-posesave-XXXXXX";
  static PoseSaveWatch watch;
  watch = PoseSaveWatch{};
  watch.dir = mkdtemp(dir_template);
  static boticelli::firmware::MainHooks hooks;
  hooks.after_frame = watch_pose_saves;
  hooks.context = &watch;
  const MissionRun run = run_mission("thesis_room", "1", 0.0F, &hooks,
                                     {"--state", watch.dir.c_str(), "--max-cycles", "2"});
  STRCMP_CONTAINS("MISSION result=not_found cycles=2 ", run.mission_line.c_str());
  CHECK_TEXT(watch.moving_frames > 300, "the robot drove for more than 3 s");
  CHECK(watch.saves_while_moving >= 3);
  // And not much more often (the state goes to storage: each save costs a write and an
  // fsync): once a second, where a turn becomes the straight, and at each step's end. Measured
  // 24 in 19 s of moving; a save at every frame of a turn would be hundreds.
  const std::string saves = std::to_string(watch.saves_while_moving) + " saves in " +
                            std::to_string(watch.moving_frames) + " frames moving";
  CHECK_TEXT(watch.saves_while_moving <= 2 * (watch.moving_frames / 100) + 10, saves.c_str());
  // A frame of slack: the save is due once a second has passed since the last.
  CHECK_TEXT(watch.worst_gap_moving_us <= 1010000U,
             std::to_string(watch.worst_gap_moving_us).c_str());
  remove_state_dir(watch.dir);
}

// Stopped after three cycles and started again with --resume: the robot is put back where it
// stopped, the mission carries on in the frame its map was saved in, and ends found.
TEST(MissionResume, AResumedMissionStartsWhereTheLastRunStoppedAndFindsTheTarget) {
  char dir_template[] = "/tmp/boticelli-resume-XXXXXX";
  const std::string dir = mkdtemp(dir_template);
  // Later --max-cycles options win over run_mission's own.
  const MissionRun first =
      run_mission("thesis_room", "1", 0.0F, nullptr, {"--state", dir.c_str(), "--max-cycles", "3"});
  STRCMP_CONTAINS("MISSION result=not_found cycles=3 ", first.mission_line.c_str());
  UNSIGNED_LONGS_EQUAL_TEXT(0, first.check.collisions, first.mission_line.c_str());
  const sim::TraceRow stopped = first.trace.back();
  CHECK_TEXT(std::hypot(stopped.x_m - first.trace.front().x_m,
                        stopped.y_m - first.trace.front().y_m) > 0.3,
             "the first run drove somewhere");
  // The pose the first run saved at shutdown (in the mission's frame).
  double saved[3] = {0.0, 0.0, 0.0};
  {
    // The newest of the two copies: the one with the higher sequence number.
    const std::string a = slurp(dir + "/mission.state.a");
    const std::string b = slurp(dir + "/mission.state.b");
    const auto sequence = [](const std::string& f) {
      const std::size_t at = f.find("\nsequence ");
      return at == std::string::npos ? -1L : std::atol(f.c_str() + at + 10);
    };
    std::istringstream state(sequence(a) > sequence(b) ? a : b);
    std::string line;
    bool found = false;
    while (std::getline(state, line)) {
      std::istringstream words(line);
      std::string key;
      if (words >> key && key == "pose")
        found = static_cast<bool>(words >> saved[0] >> saved[1] >> saved[2]);
    }
    CHECK_TEXT(found, "the state file holds the pose");
  }
  const MissionRun second =
      run_mission("thesis_room", "1", 0.0F, nullptr, {"--state", dir.c_str(), "--resume"});
  check_found_safely(second);
  // Where the base came to rest: the true pose when the first run's firmware returned (the
  // trace keeps 4 decimals). Its last trace row may be a frame older: the last cycle can end
  // mid-drive, and the base rolls on a few mm while it stops. The world's own file keeps
  // where the robot stands; the firmware's saved pose is not where the board puts it.
  const sim::TraceRow& resumed = second.trace.front();
  const double rest_x = first.final_pose.x_m;
  const double rest_y = first.final_pose.y_m;
  const double rest_yaw = first.final_pose.yaw_rad;
  DOUBLES_EQUAL(rest_x, resumed.x_m, 0.05);
  DOUBLES_EQUAL(rest_y, resumed.y_m, 0.05);
  DOUBLES_EQUAL(0.0, std::remainder(rest_yaw - resumed.yaw_rad, 2.0 * std::numbers::pi), 0.02);
  CHECK(std::hypot(stopped.x_m - resumed.x_m, stopped.y_m - resumed.y_m) < 0.1);
  // The pose in the mission's frame (the trace's estimate columns) carries on too, from the
  // pose saved at shutdown: the map and the goal saved in that frame still fit.
  CHECK(first.trace.back().has_pose_columns && second.trace.front().has_pose_columns);
  const double* before = first.trace.back().est;
  const double* after = second.trace.front().est;
  CHECK_TEXT(std::hypot(before[0], before[1]) > 0.3, "the first run's frame moved with the robot");
  CHECK(std::hypot(before[0] - saved[0], before[1] - saved[1]) < 0.05);
  // Saved where the base came to rest (perfect odometry: the true rest pose in the frame of the
  // start pose), not where the last cycle ended.
  {
    const sim::TraceRow& s0 = first.trace.front();
    const boticelli::core::Pose2 rest = boticelli::core::compose(
        boticelli::core::inverse({static_cast<float>(s0.x_m), static_cast<float>(s0.y_m),
                                  static_cast<float>(s0.yaw_rad)}),
        first.final_pose);
    const std::string at = "saved " + std::to_string(saved[0]) + " " + std::to_string(saved[1]) +
                           ", at rest " + std::to_string(rest.x_m) + " " + std::to_string(rest.y_m);
    CHECK_TEXT(std::hypot(saved[0] - static_cast<double>(rest.x_m),
                          saved[1] - static_cast<double>(rest.y_m)) < 0.001,
               at.c_str());
  }
  DOUBLES_EQUAL(saved[0], after[0], 0.002);
  DOUBLES_EQUAL(saved[1], after[1], 0.002);
  DOUBLES_EQUAL(0.0, std::remainder(saved[2] - after[2], 2.0 * std::numbers::pi), 0.002);
  // The cycle count carries on from the saved state.
  const std::size_t c = second.mission_line.find("cycles=");
  CHECK(c != std::string::npos);
  CHECK_TEXT(std::atoi(second.mission_line.c_str() + c + 7) > 3, second.mission_line.c_str());
  std::remove((dir + "/mission.state.a").c_str());
  std::remove((dir + "/mission.state.b").c_str());
  std::remove((dir + "/sim-world.truth").c_str());
  rmdir(dir.c_str());
}

namespace {
// Types `shutdown` once the robot drives at speed 0.15 m from where it started.
struct ShutdownScript {
  int console_fd = -1;
  bool typed = false;
  bool started = false;
  boticelli::core::Pose2 start{};
};
void on_frame_shutdown(void* context) {
  auto* script = static_cast<ShutdownScript*>(context);
  const boticelli::core::Pose2 p = g_board.sim().true_pose();
  if (!script->started) script->start = p;
  script->started = true;
  if (script->typed || g_board.sim().odometry().v_m_s < 0.2F ||
      std::hypot(p.x_m - script->start.x_m, p.y_m - script->start.y_m) < 0.15F) {
    return;
  }
  const char* text = "shutdown\r";
  CHECK(write(script->console_fd, text, std::strlen(text)) ==
        static_cast<ssize_t>(std::strlen(text)));
  script->typed = true;
}
}  // namespace

// An orderly stop typed mid-drive: the base stops, and the state's pose is where it came to
// rest (taken at the stop, after the base stood still), not where the last save while driving
// or the last cycle left it.
TEST(MissionResume, AShutdownMidDriveSavesWhereTheRobotCameToRest) {
  char dir_template[] = "/tmp/boticelli-shutdown-XXXXXX";
  const std::string dir = mkdtemp(dir_template);
  ShutdownScript script;
  const MissionRun r = run_mission_typing(script, on_frame_shutdown, {"--state", dir.c_str()});
  static boticelli::firmware::MissionState saved;
  std::string error;
  const bool loaded = load_state(dir, saved, error);
  remove_state_dir(dir);
  CHECK(script.typed);
  CHECK_TEXT(loaded, error.c_str());
  CHECK_TEXT(saved.cycle <= 1, r.mission_line.c_str());  // stopped in its first cycle's step
  // Perfect odometry: the mission frame is the start pose's.
  const sim::TraceRow& s0 = r.trace.front();
  const boticelli::core::Pose2 rest = boticelli::core::compose(
      boticelli::core::inverse(
          {static_cast<float>(s0.x_m), static_cast<float>(s0.y_m), static_cast<float>(s0.yaw_rad)}),
      r.final_pose);
  const double off_m = std::hypot(static_cast<double>(saved.pose.x_m - rest.x_m),
                                  static_cast<double>(saved.pose.y_m - rest.y_m));
  CHECK_TEXT(std::hypot(rest.x_m, rest.y_m) > 0.15F, "it drove before the stop");
  CHECK_TEXT(off_m < 0.001, (std::to_string(off_m) + " m from where it came to rest").c_str());
}

// qemu-user cannot be trusted to fork a process it emulates: native only.
#ifndef BOTICELLI_TESTS_UNDER_EMULATOR
namespace {
// A firmware killed (SIGKILL: no handler, no last save) at the first frame after 6 s, with a
// state saved, in which the robot drives straight at speed, or turns on the spot at speed.
// Or, kLooking, while the PTU moves and the base stands, once the robot has driven 0.3 m
// from where it started (a look after a completed cycle).
enum class KillWhile { kDriving, kTurning, kLooking };
struct KillPlan {
  KillWhile when = KillWhile::kDriving;
  int frames = 0;
  std::string state_a, state_b;  // nothing to resume before a state was saved
  boticelli::core::Pose2 start{};
  bool drove = false;
};
void kill_in_motion(void* context) {
  auto* plan = static_cast<KillPlan*>(context);
  const boticelli::core::Pose2 here = g_board.sim().true_pose();
  if (plan->frames == 0) plan->start = here;
  plan->drove =
      plan->drove || std::hypot(here.x_m - plan->start.x_m, here.y_m - plan->start.y_m) > 0.3F;
  if (++plan->frames < 600) return;
  if (access(plan->state_a.c_str(), F_OK) != 0 && access(plan->state_b.c_str(), F_OK) != 0) return;
  const auto s = g_board.sim().physical_state();
  const float v = 0.5F * (s.wheel_left_m_s + s.wheel_right_m_s);
  const float spin = 0.5F * (s.wheel_right_m_s - s.wheel_left_m_s);
  const bool driving = v > 0.25F && std::fabs(spin) < 0.02F;
  const bool turning = std::fabs(spin) > 0.1F && std::fabs(v) < 0.02F;
  const bool looking = plan->drove && std::fabs(v) < 1e-4F && std::fabs(spin) < 1e-4F &&
                       (g_board.sim().pan().moving() || g_board.sim().tilt().moving());
  if ((plan->when == KillWhile::kDriving && driving) ||
      (plan->when == KillWhile::kTurning && turning) ||
      (plan->when == KillWhile::kLooking && looking)) {
    ::raise(SIGKILL);
  }
}

// Kills a mission in `dir` as planned (in a forked child) and returns the child's status.
int kill_mission(KillWhile when, const std::string& dir,
                 const std::vector<const char*>& config = {}) {
  std::fflush(stdout);
  std::fflush(stderr);
  const pid_t child = fork();
  if (child == 0) {
    static KillPlan plan;
    plan.when = when;
    plan.state_a = dir + "/mission.state.a";
    plan.state_b = dir + "/mission.state.b";
    static boticelli::firmware::MainHooks hooks;
    hooks.after_frame = kill_in_motion;
    hooks.context = &plan;
    std::vector<const char*> args = {"--state", dir.c_str()};
    args.insert(args.end(), config.begin(), config.end());
    (void)run_mission("thesis_room", "1", 0.0F, &hooks, args);
    _exit(3);  // the mission ended before the kill
  }
  return boticelli::test::wait_for_child(child, 600000);
}

// Kills a mission in `dir` as planned (in a forked child), then resumes it here for one
// cycle. The resumed firmware's pose once its base is ready (the trace's estimate, mission
// frame) against the truth then, and the saved pose against the truth [m, rad].
struct KilledAndResumed {
  int child_status = 0;
  double estimate_off_m = -1.0, estimate_off_rad = -1.0;
  double saved_off_m = -1.0, saved_off_rad = -1.0;
  // The turn the resumed pose was carried on by [rad] (its first anchored estimate less the
  // saved heading), and what the mission log says of it [deg] (NaN without the line).
  double moved_rad = 0.0;
  double logged_moved_deg = std::numeric_limits<double>::quiet_NaN();
  std::string log;
};
KilledAndResumed kill_and_resume(KillWhile when, const std::string& dir,
                                 const std::vector<const char*>& config = {}) {
  KilledAndResumed out;
  out.child_status = kill_mission(when, dir, config);
  // The pose the killed firmware last saved (mission frame).
  static boticelli::firmware::MissionState saved;
  if (!load_state(dir, saved, out.log)) return out;
  std::vector<const char*> args = {"--state", dir.c_str(), "--resume", "--max-cycles", "1"};
  args.insert(args.end(), config.begin(), config.end());
  const MissionRun resumed = run_mission("thesis_room", "1", 0.0F, nullptr, args);
  out.log = resumed.trace_text.substr(0, 200) + " | " + resumed.mission_line;
  // The first row the mission no longer waits for its base in: anchored.
  std::size_t row = 0;
  while (row < resumed.trace.size() && std::string(resumed.trace[row].state) == "start") ++row;
  if (row == resumed.trace.size()) return out;
  const sim::TraceRow& t = resumed.trace[row];
  if (!t.has_pose_columns) return out;
  const double* f = t.est;  // the firmware's estimate, mission frame
  const boticelli::core::Pose2 start = g_board.world().start;
  const boticelli::core::Pose2 truth = boticelli::core::compose(
      boticelli::core::inverse(start),
      {static_cast<float>(t.x_m), static_cast<float>(t.y_m), static_cast<float>(t.yaw_rad)});
  const double tx = truth.x_m, ty = truth.y_m, tyaw = truth.yaw_rad;
  out.estimate_off_m = std::hypot(f[0] - tx, f[1] - ty);
  out.estimate_off_rad = std::fabs(std::remainder(f[2] - tyaw, 2.0 * std::numbers::pi));
  out.saved_off_m = std::hypot(static_cast<double>(saved.pose.x_m) - tx,
                               static_cast<double>(saved.pose.y_m) - ty);
  out.saved_off_rad = std::fabs(
      std::remainder(static_cast<double>(saved.pose.yaw_rad) - tyaw, 2.0 * std::numbers::pi));
  out.moved_rad =
      std::remainder(f[2] - static_cast<double>(saved.pose.yaw_rad), 2.0 * std::numbers::pi);
  // The resumed run's state: its mission log says how far the wheels carried the pose.
  static boticelli::firmware::MissionState after;
  std::string why;
  if (load_state(dir, after, why)) {
    for (const boticelli::firmware::MissionLogEntry& e : after.log) {
      const char* at = std::strstr(e.text.data(), "resumed pose moved on by the wheels: ");
      double metres = 0.0;
      double degrees = 0.0;
      if (at != nullptr && std::sscanf(at, "resumed pose moved on by the wheels: %lf m, %lf deg",
                                       &metres, &degrees) == 2) {
        out.logged_moved_deg = degrees;
      }
    }
  }
  return out;
}

}  // namespace

// Killed mid-drive at full speed: the last pose saved is up to a second old, and the wheels
// roll on until the ODrives' watchdog stops them. The world keeps where the robot truly
// stands (its own file); the resumed firmware carries its saved pose on by the wheel counters
// the motor controllers kept, and is within 5 cm and 1° of the truth.
TEST(MissionResume, KilledMidDriveItResumesWithinFiveCentimetresOfWhereTheRobotStands) {
  char dir_template[] = "/tmp/boticelli-kill-XXXXXX";
  const std::string dir = mkdtemp(dir_template);
  const KilledAndResumed r = kill_and_resume(KillWhile::kDriving, dir);
  remove_state_dir(dir);
  CHECK_TEXT(WIFSIGNALED(r.child_status) && WTERMSIG(r.child_status) == SIGKILL, r.log.c_str());
  CHECK_TEXT(r.saved_off_m > 0.05,
             ("the saved pose alone was off by " + std::to_string(r.saved_off_m) + " m").c_str());
  CHECK_TEXT(r.estimate_off_m >= 0.0 && r.estimate_off_m <= 0.05,
             (std::to_string(r.estimate_off_m) + " m off: " + r.log).c_str());
  CHECK_TEXT(r.estimate_off_rad <= 1.0 * std::numbers::pi / 180.0,
             std::to_string(r.estimate_off_rad).c_str());
}

// Killed in the middle of a look, after a completed cycle (nothing is saved during a look):
// the state holds that cycle's end, its log line and where the robot stands (it has not moved
// since), so a resumed mission loses none of what it had seen.
TEST(MissionResume, KilledMidLookTheStateHoldsTheLastCycleAndWhereTheRobotStands) {
  char dir_template[] = "/tmp/boticelli-kill-XXXXXX";
  const std::string dir = mkdtemp(dir_template);
  const int status = kill_mission(KillWhile::kLooking, dir);
  static boticelli::firmware::MissionState saved;
  std::string error;
  const bool loaded = load_state(dir, saved, error);
  // Where the killed firmware left the robot: the sim world's own file keeps it.
  static sim::World world;
  char why[256] = "";
  CHECK_TEXT(sim::load_world(BOTICELLI_WORLDS_DIR "/thesis_room.sdf", world, why, sizeof why), why);
  sim::SimWorld::PhysicalState stands{};
  const auto truth_loaded = boticelli::boards::sim::WorldTruthFile::load(
      (dir + "/sim-world.truth").c_str(), boticelli::boards::sim::WorldTruthFile::world_id(world),
      stands, why, sizeof why);
  remove_state_dir(dir);
  CHECK_TEXT(WIFSIGNALED(status) && WTERMSIG(status) == SIGKILL, "killed mid-look");
  CHECK_TEXT(loaded, error.c_str());
  CHECK_TEXT(truth_loaded == boticelli::boards::sim::WorldTruthFile::Load::kLoaded, why);
  CHECK(saved.cycle >= 1);
  CHECK(!saved.log.empty());
  const std::string last = saved.log.back().text.data();
  CHECK_EQUAL_TEXT(saved.cycle, saved.log.back().cycle, last.c_str());
  STRCMP_CONTAINS("cycle ", last.c_str());
  const boticelli::core::Pose2 truth =
      boticelli::core::compose(boticelli::core::inverse(world.start),
                               {static_cast<float>(stands.x_m), static_cast<float>(stands.y_m),
                                static_cast<float>(stands.yaw_rad)});
  const double off_m = std::hypot(static_cast<double>(saved.pose.x_m - truth.x_m),
                                  static_cast<double>(saved.pose.y_m - truth.y_m));
  CHECK_TEXT(off_m < 0.01, (std::to_string(off_m) + " m from where the robot stands").c_str());
}

// Killed while turning on the spot: the heading the saved pose misses comes back too. The
// base's wheels stand 10 % wider apart than the nominal track (`[sim] track_scale`), and the
// configuration says so (`[base] odometry_track_scale`, as a calibration would): the turn the
// wheels made while no firmware ran is taken at the calibrated track (at the nominal one it
// would be a tenth too large, about 3 degrees here).
TEST(MissionResume, KilledMidTurnItResumesWithinOneDegreeOfTheRobotsHeading) {
  char dir_template[] = "/tmp/boticelli-kill-XXXXXX";
  const std::string dir = mkdtemp(dir_template);
  const std::string conf = dir + "/boticelli.conf";
  std::ofstream(conf) << "[base]\nodometry_track_scale = 1.1\n[sim]\ntrack_scale = 1.1\n";
  const KilledAndResumed r = kill_and_resume(KillWhile::kTurning, dir, {"--config", conf.c_str()});
  std::remove(conf.c_str());
  remove_state_dir(dir);
  CHECK_TEXT(WIFSIGNALED(r.child_status) && WTERMSIG(r.child_status) == SIGKILL, r.log.c_str());
  CHECK_TEXT(r.saved_off_rad > 2.0 * std::numbers::pi / 180.0,
             ("the saved heading alone was off by " + std::to_string(r.saved_off_rad)).c_str());
  CHECK_TEXT(r.estimate_off_m >= 0.0 && r.estimate_off_m <= 0.05,
             (std::to_string(r.estimate_off_m) + " m off: " + r.log).c_str());
  CHECK_TEXT(r.estimate_off_rad <= 1.0 * std::numbers::pi / 180.0,
             std::to_string(r.estimate_off_rad).c_str());
  // The mission log tells the operator the turn in degrees, as the pose took it.
  DOUBLES_EQUAL(r.moved_rad * 180.0 / std::numbers::pi, r.logged_moved_deg, 0.1);
}
#endif  // BOTICELLI_TESTS_UNDER_EMULATOR
