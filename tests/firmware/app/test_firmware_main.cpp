// Tests of firmware_main on a fake board (lockstep fake clock): exit codes, MISSION line, console
// quit, --state/--resume.
#include <fcntl.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <array>
#include <csignal>
#include <cstdio>
#include <cstdlib>
#include <ctime>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "child_process.h"
#include "fake_clock.h"
#include "fake_serial_port.h"
#include "firmware/app/device_tasks.h"
#include "firmware/app/firmware_main.h"
#include "firmware/safety/safety.h"
#include "firmware/state/persistence.h"
#include "firmware_fakes.h"

#include "CppUTest/TestHarness.h"

using namespace boticelli::firmware;
using namespace boticelli::test;

namespace {

// Refuses to arm unless `accept` (then counts its starts and keeps the timeout asked for);
// refuses keep-alives while `clock` reads within [refuse_from_us, refuse_until_us).
class NullWatchdog final : public boticelli::hal::Watchdog {
 public:
  bool start(std::uint32_t timeout_ms) override {
    if (!accept) return false;
    ++starts;
    started_ms = timeout_ms;
    return true;
  }
  bool kick() override {
    const std::uint64_t now = clock != nullptr ? clock->now_us() : 0;
    refusing = clock != nullptr && now >= refuse_from_us && now < refuse_until_us;
    return !refusing;
  }
  void stop() override {}
  const char* error() const override {
    return refusing ? "watchdog: keep-alive refused: Input/output error" : "no watchdog in tests";
  }
  bool accept = false;
  int starts = 0;
  std::uint32_t started_ms = 0;
  boticelli::hal::Clock* clock = nullptr;
  std::uint64_t refuse_from_us = 0;
  std::uint64_t refuse_until_us = 0;
  bool refusing = false;
};

// A camera whose frames are of no use (2x2, no time stamp: the look never takes one) until
// `good_after_us` of board time, then frames of the configured 160x120 size, time-stamped.
class TestCamera final : public boticelli::hal::Camera {
 public:
  explicit TestCamera(boticelli::hal::Clock& clock) : clock_(clock) {}
  bool init() override { return !fail_init; }
  boticelli::hal::CameraPoll poll(boticelli::hal::Frame& frame) override {
    if (++polls % 3 != 0) return boticelli::hal::CameraPoll::kNoFrame;
    const bool good = good_after_us != 0 && clock_.now_us() >= good_after_us;
    frame.data = kGood.data();
    frame.width_px = good ? 160 : 2;
    frame.height_px = good ? 120 : 2;
    frame.stride_bytes = frame.width_px * 2;
    frame.timestamp_us = good ? clock_.now_us() : 0;
    frame.sequence = sequence++;
    return boticelli::hal::CameraPoll::kFrame;
  }
  void release() override {}
  std::uint32_t width_px() const override { return 160; }
  std::uint32_t height_px() const override { return 120; }
  const char* error() const override { return fail_init ? "no such device" : ""; }
  bool fail_init = false;
  std::uint64_t good_after_us = 0;  // 0: never

 private:
  static inline const std::array<std::uint8_t, 160 * 120 * 2> kGood = [] {
    std::array<std::uint8_t, 160 * 120 * 2> a{};
    a.fill(128);
    return a;
  }();
  boticelli::hal::Clock& clock_;
  int polls = 0;
  std::uint32_t sequence = 0;
};

// Everything fake; the clock moves only in sleep_until_us (lockstep, like the sim board).
class FakeBoard final : public Board {
 public:
  const BoardInfo& info() const override { return kInfo; }
  const BoardConfig& config() const override { return config_; }
  // Binds the keys to config_ as the test prepared it (no reset to other defaults).
  bool reset_config(ConfigSchema& schema) override {
    return add_board_config_keys(schema, config_);
  }
  const char* default_config_path() const override { return default_config; }
  bool init(const Options&, char* error, std::size_t size) override {
    if (refuse) {
      std::snprintf(error, size, "fake board refuses");
      return false;
    }
    return true;
  }
  boticelli::hal::Hal& hal() override { return hal_; }

  bool refuse = false;
  const char* default_config = nullptr;       // the board's default configuration file
  std::function<void(FakeBoard&)> after_run;  // looks at the devices after the run
  const MainHooks* hooks = nullptr;           // handed to firmware_main
  BoardConfig config_{};
  boticelli::fakes::FakeClock clock{1000};
  boticelli::fakes::FakeSerialPort console;
  TestCamera camera{clock};
  FakePanTilt ptu;
  FakeBase base{&clock};
  FakeInput estop, bumper;
  FakeOutput led;
  NullWatchdog watchdog;

 private:
  static constexpr BoardInfo kInfo{"fake", "test board", false};
  boticelli::hal::Hal hal_{camera, ptu, base, estop, bumper, led, console, clock, watchdog};
};

struct Run {
  int exit_code = -1;
  std::string out;
  std::string err;
};

std::string slurp(int fd) {
  std::string s;
  char buf[4096];
  ssize_t n = 0;
  lseek(fd, 0, SEEK_SET);
  while ((n = read(fd, buf, sizeof buf)) > 0) s.append(buf, static_cast<std::size_t>(n));
  return s;
}

// Runs firmware_main in this process on a fresh fake board, with stdout and stderr sent to
// temporary files. (firmware_main rebuilds its static objects on every call.)
template <typename Prepare>
Run run_firmware(std::vector<const char*> args, Prepare prepare) {
  args.insert(args.begin(), "boticelli");
  char out_name[] = "/tmp/boticelli-out-XXXXXX";
  char err_name[] = "/tmp/boticelli-err-XXXXXX";
  const int out_fd = mkstemp(out_name);
  const int err_fd = mkstemp(err_name);
  unlink(out_name);
  unlink(err_name);
  std::fflush(stdout);
  std::fflush(stderr);
  const int saved_out = dup(STDOUT_FILENO);
  const int saved_err = dup(STDERR_FILENO);
  dup2(out_fd, STDOUT_FILENO);
  dup2(err_fd, STDERR_FILENO);
  Run r;
  {
    auto board = std::make_unique<FakeBoard>();
    prepare(*board);
    r.exit_code = firmware_main(static_cast<int>(args.size()), args.data(), *board, board->hooks);
    if (board->after_run) board->after_run(*board);
  }
  std::fflush(stdout);
  std::fflush(stderr);
  dup2(saved_out, STDOUT_FILENO);
  dup2(saved_err, STDERR_FILENO);
  close(saved_out);
  close(saved_err);
  r.out = slurp(out_fd);
  r.err = slurp(err_fd);
  close(out_fd);
  close(err_fd);
  return r;
}

Run run_firmware(std::vector<const char*> args) {
  return run_firmware(std::move(args), [](FakeBoard&) {});
}

std::string last_line(const std::string& s) {
  const std::size_t end = s.find_last_not_of('\n');
  const std::size_t start = s.rfind('\n', end);
  return s.substr(start == std::string::npos ? 0 : start + 1,
                  end - (start == std::string::npos ? 0 : start + 1) + 1);
}

}  // namespace

TEST_GROUP(FirmwareMain) {
  std::string dir;
  void setup() override {
    char templ[] = "/tmp/boticelli-fw-XXXXXX";
    dir = mkdtemp(templ);
  }
  void teardown() override {
    for (const char* name : {"/mission.state", "/mission.state.a", "/mission.state.b"}) {
      unlink((dir + name).c_str());
    }
    for (int i = 1; i <= StateStore::kKeptStates; ++i) {
      unlink((dir + "/mission.state." + std::to_string(i)).c_str());
    }
    unlink((dir + "/parameters.conf").c_str());
    unlink((dir + "/boticelli.conf").c_str());
    rmdir(dir.c_str());
  }
};

// The fake board's camera never delivers a frame of the configured size: the camera task is
// unhealthy after 2 s and the mission's look holds after its frame timeout (3 s), trying
// again every second; 30 s (the device retry time) after the camera turned unhealthy the
// firmware gives up and exits with the code the service unit restarts on.
TEST(FirmwareMain, GivesUpOnACameraThatNeverDeliversAfterTheRetryTimeAndExitsForARestart) {
  const Run r = run_firmware({"--max-cycles", "3"});
  CHECK_EQUAL(kExitFailure, r.exit_code);
  STRCMP_CONTAINS("boticelli 0.1.0 board=fake (test board)", r.out.c_str());
  const std::string line = last_line(r.out);
  STRCMP_CONTAINS("MISSION result=aborted cycles=0 collisions=0 sim_time_s=32.", line.c_str());
  STRCMP_CONTAINS("wall_time_s=", line.c_str());
  STRCMP_CONTAINS("target_error_m=nan", line.c_str());
  STRCMP_CONTAINS(
      "reason=\"gave up: camera unhealthy for 30 s: no new frame for 2.0 s: frames of the "
      "wrong size\"",
      line.c_str());
  STRCMP_CONTAINS(
      "boticelli: gave up: camera unhealthy for 30 s: no new frame for 2.0 s: frames "
      "of the wrong size: exiting for a restart (--resume carries the mission on)",
      r.err.c_str());
}

// A device whose task stays healthy but that the mission cannot use (a PTU that answers every
// move with an error) is held and retried by the mission itself, which gives up after the
// retry time: the same exit for a restart.
TEST(FirmwareMain, TheMissionGivesUpOnAPtuThatRefusesEveryMoveAfterTheRetryTime) {
  const Run r = run_firmware({}, [](FakeBoard& b) {
    b.config_.camera_width_px = 160;
    b.config_.camera_height_px = 120;
    b.camera.good_after_us = 1;
    b.ptu.refuse_moves = true;
  });
  CHECK_EQUAL(kExitFailure, r.exit_code);
  const std::string line = last_line(r.out);
  STRCMP_CONTAINS("MISSION result=aborted cycles=0 collisions=0 sim_time_s=30.", line.c_str());
  STRCMP_CONTAINS("reason=\"gave up after 30 s: pan-tilt unit refused a move\"", line.c_str());
  STRCMP_CONTAINS("exiting for a restart", r.err.c_str());
}

namespace {
struct SigtermAt {
  boticelli::hal::Clock* clock = nullptr;
  std::uint64_t at_us = 0;
};
void sigterm_at(void* context) {
  auto* s = static_cast<SigtermAt*>(context);
  if (s->at_us != 0 && s->clock->now_us() >= s->at_us) {
    s->at_us = 0;
    std::raise(SIGTERM);
  }
}

// The saved mission log of a run that held for a device: its first line says why (`held`
// begins it), the second that the devices came back.
void check_held_then_back(const std::string& dir, const char* held) {
  static MissionState state;
  static StateStore store;
  char error[256] = "";
  CHECK(store.open(dir.c_str(), error, sizeof error));
  CHECK(store.load(state, error, sizeof error) == LoadResult::kLoaded);
  CHECK(state.log.size() >= 2U);
  STRCMP_CONTAINS(held, std::string(state.log[0].view()).c_str());
  STRCMP_CONTAINS("devices back after ", std::string(state.log[1].view()).c_str());
}
}  // namespace

// Shorter than the retry time, a fault is ridden out: a camera that delivers again after 10 s
// of holds and retries lets the look go on, and 45 s in nothing has been given up.
TEST(FirmwareMain, ACameraBackWithinTheRetryTimeLetsTheLookGoOnWithNothingGivenUp) {
  static SigtermAt stop;
  static MainHooks hooks;
  hooks.after_frame = sigterm_at;
  hooks.context = &stop;
  const Run r = run_firmware({"--state", dir.c_str()}, [&](FakeBoard& b) {
    b.config_.camera_width_px = 160;
    b.config_.camera_height_px = 120;
    b.camera.good_after_us = 10000000;
    stop = SigtermAt{&b.clock, 45000000};
    b.hooks = &hooks;
  });
  CHECK_EQUAL(kExitNotFound, r.exit_code);  // stopped by the signal, not a give-up (1)
  STRCMP_CONTAINS("reason=\"SIGTERM\"", last_line(r.out).c_str());
  CHECK(r.err.find("gave up") == std::string::npos);
  check_held_then_back(dir, "held: no camera frame");
}

// Keep-alives the watchdog device refuses (the board may reset any moment) hold the robot
// stopped; once one is taken again the mission carries on.
TEST(FirmwareMain, TheMissionHoldsWhileTheWatchdogRefusesKeepAlivesAndCarriesOnAfter) {
  static SigtermAt stop;
  static MainHooks hooks;
  hooks.after_frame = sigterm_at;
  hooks.context = &stop;
  const Run r = run_firmware({"--state", dir.c_str()}, [&](FakeBoard& b) {
    b.config_.camera_width_px = 160;
    b.config_.camera_height_px = 120;
    b.camera.good_after_us = 1;
    b.watchdog.accept = true;
    b.watchdog.clock = &b.clock;
    b.watchdog.refuse_from_us = 2000000;
    b.watchdog.refuse_until_us = 6000000;
    stop = SigtermAt{&b.clock, 20000000};
    b.hooks = &hooks;
  });
  CHECK_EQUAL(kExitNotFound, r.exit_code);
  CHECK(r.err.find("gave up") == std::string::npos);
  check_held_then_back(dir,
                       "held: watchdog refusing keep-alives (a reset may come): "
                       "watchdog: keep-alive refused");
}

TEST(FirmwareMain, ExitsWithTheUsageCodeOnABadOption) {
  const Run r = run_firmware({"--warp"});
  CHECK_EQUAL(kExitUsage, r.exit_code);
  STRCMP_CONTAINS("unknown option '--warp'", r.err.c_str());
}

TEST(FirmwareMain, PrintsTheBoardsReasonWhenItsInitFails) {
  const Run r = run_firmware({}, [](FakeBoard& b) { b.refuse = true; });
  CHECK_EQUAL(kExitFailure, r.exit_code);
  STRCMP_CONTAINS("boticelli: fake board refuses", r.err.c_str());
  const Run cam = run_firmware({}, [](FakeBoard& b) { b.camera.fail_init = true; });
  CHECK_EQUAL(kExitFailure, cam.exit_code);
  STRCMP_CONTAINS("boticelli: camera: no such device", cam.err.c_str());
}

// After a package upgrade (postinst leaves DIR/start-held) the firmware starts held, as by
// `pause`, until the operator's `resume`; the file is used up, the next start is not held.
TEST(FirmwareMain, AStartHeldFileHoldsTheStartUntilResumeAndIsUsedUp) {
  const std::string held = dir + "/start-held";
  FILE* f = std::fopen(held.c_str(), "w");
  CHECK(f != nullptr);
  std::fclose(f);
  std::string console_output;
  Run r = run_firmware({"--state", dir.c_str()}, [&](FakeBoard& b) {
    b.console.feed("status\rquit\r");
    b.after_run = [&](FakeBoard& done) { console_output = done.console.written(); };
  });
  STRCMP_CONTAINS(("started held (" + held + ", left by a package upgrade)").c_str(),
                  r.err.c_str());
  STRCMP_CONTAINS("started held", console_output.c_str());
  STRCMP_CONTAINS("paused=1 waits_for=resume", console_output.c_str());
  CHECK(access(held.c_str(), F_OK) != 0);
  r = run_firmware({"--state", dir.c_str()}, [&](FakeBoard& b) {
    b.console.feed("status\rquit\r");
    b.after_run = [&](FakeBoard& done) { console_output = done.console.written(); };
  });
  CHECK(r.err.find("started held") == std::string::npos);
  STRCMP_CONTAINS("paused=0", console_output.c_str());
}

TEST(FirmwareMain, StopsOnTheConsolesQuitCommandAfterAnsweringOnTheConsole) {
  std::string console_output;
  const Run r = run_firmware({}, [&](FakeBoard& b) {
    b.console.feed("status\restop\rquit\r");
    b.after_run = [&](FakeBoard& done) {
      console_output = done.console.written();
      CHECK(done.base.health() == boticelli::hal::BaseHealth::kStopped);
    };
  });
  CHECK_EQUAL(kExitNotFound, r.exit_code);
  STRCMP_CONTAINS("MISSION result=aborted cycles=0", last_line(r.out).c_str());
  STRCMP_CONTAINS("status state=look estop=none", console_output.c_str());
  STRCMP_CONTAINS("OK shutting down", console_output.c_str());
  STRCMP_CONTAINS("LOG info stopping: console shutdown", console_output.c_str());
}

TEST(FirmwareMain, RunsAgainInTheSameProcess) {
  CHECK_EQUAL(kExitFailure, run_firmware({"--max-cycles", "2"}).exit_code);
  const Run r = run_firmware({"--max-cycles", "1"});
  CHECK_EQUAL(kExitFailure, r.exit_code);
  STRCMP_CONTAINS("MISSION result=aborted cycles=0 ", last_line(r.out).c_str());
}

TEST(FirmwareMain, SavesEachCycleAndResumesFromTheStateDirectory) {
  Run r = run_firmware({"--max-cycles", "4", "--state", dir.c_str(), "--seed", "9"});
  CHECK_EQUAL(kExitFailure, r.exit_code);
  static MissionState state;  // large: static storage
  static StateStore store;
  char error[256] = "";
  CHECK(store.open(dir.c_str(), error, sizeof error));
  CHECK(store.load(state, error, sizeof error) == LoadResult::kLoaded);
  CHECK_EQUAL(0U, state.cycle);  // the look never finished (camera fault) ...
  CHECK_EQUAL(9U, state.seed);
  CHECK_EQUAL(2U, state.log.size());  // ... the hold and the end were saved with their reasons
  STRCMP_CONTAINS("held: no camera frame", std::string(state.log[0].view()).c_str());
  STRCMP_CONTAINS("mission aborted: gave up: camera unhealthy for 30 s",
                  std::string(state.log[1].view()).c_str());
  // A device fault ends this run only: the state keeps the mission running for --resume.
  CHECK(state.end == MissionEnd::kRunning);

  r = run_firmware({"--max-cycles", "2", "--state", dir.c_str(), "--resume"});
  CHECK_EQUAL(kExitFailure, r.exit_code);
  STRCMP_CONTAINS("resumed from", r.err.c_str());
  STRCMP_CONTAINS("MISSION result=aborted cycles=0", last_line(r.out).c_str());
  CHECK(store.load(state, error, sizeof error) == LoadResult::kLoaded);
  CHECK_EQUAL(9U, state.seed);  // the mission's seed survives the resume
  CHECK_EQUAL(4U, state.log.size());
}

TEST(FirmwareMain, StartsANewMissionWhenThereIsNothingToResume) {
  const Run r = run_firmware({"--state", dir.c_str(), "--resume", "--max-cycles", "1"});
  CHECK_EQUAL(kExitFailure, r.exit_code);
  STRCMP_CONTAINS("starting a new mission", r.err.c_str());
  STRCMP_CONTAINS("MISSION result=aborted cycles=0", last_line(r.out).c_str());
}

TEST(FirmwareMain, RefusesToResumeFromACorruptState) {
  FILE* f = std::fopen((dir + "/mission.state").c_str(), "wb");
  std::fputs("BOTICELLI-STATE 1\ncycle 3\n", f);
  std::fclose(f);
  const Run r = run_firmware({"--state", dir.c_str(), "--resume"});
  // The usage code: the service unit does not restart on it (a restart cannot mend a file).
  CHECK_EQUAL(kExitUsage, r.exit_code);
  STRCMP_CONTAINS("boticelli: cannot resume:", r.err.c_str());
  CHECK(r.out.find("MISSION") == std::string::npos);
}

TEST(FirmwareMain, AStateDirectoryOthersMayWriteInStopsTheStartWithTheUsageCode) {
  CHECK_EQUAL(0, chmod(dir.c_str(), 0777));
  const Run r = run_firmware({"--state", dir.c_str(), "--resume"});
  // The operator must fix the directory; a restart cannot (the unit does not restart on 2).
  CHECK_EQUAL(kExitUsage, r.exit_code);
  STRCMP_CONTAINS(("boticelli: state directory " + dir +
                   " refused: writable by group and others (mode 0777; chmod go-w ")
                      .c_str(),
                  r.err.c_str());
  CHECK(r.out.find("MISSION") == std::string::npos);
  CHECK_EQUAL(0, chmod(dir.c_str(), 0700));
}

namespace {
// Saves a state of `cycle` cycles, ended as `end` (or running), in `dir` as the firmware would.
void save_state(const std::string& dir, std::uint64_t cycle, MissionEnd end, const char* why,
                std::int64_t pose_time_ms = 0) {
  static MissionState state;  // large: static storage
  static StateStore store;
  char error[256] = "";
  CHECK_TRUE_TEXT(store.open(dir.c_str(), error, sizeof error), error);
  state.clear();
  state.cycle = cycle;
  state.seed = 3;
  state.add_log(cycle, "looked");
  state.pose = {1.25F, -0.5F, 0.75F};
  state.pose_time_ms = pose_time_ms;
  if (end != MissionEnd::kRunning) state.set_end(end, why);
  CHECK_TRUE_TEXT(store.save(state, error, sizeof error), error);
}

struct FramesThenSignal {
  int frames = 0;
  int at_frame = 0;
  float fastest_m_s = 0.0F;
  FakeBoard* board = nullptr;
};
void count_then_sigterm(void* context) {
  auto* f = static_cast<FramesThenSignal*>(context);
  const float v = f->board->base.v_m_s < 0.0F ? -f->board->base.v_m_s : f->board->base.v_m_s;
  if (v > f->fastest_m_s) f->fastest_m_s = v;
  if (++f->frames == f->at_frame) std::raise(SIGTERM);
}
}  // namespace

TEST(FirmwareMain, AMissionThatHasEndedIsNotResumedAndTheFirmwareStaysUpWithTheRobotStopped) {
  save_state(dir, 5, MissionEnd::kFound, "within the stand-off of the target");
  static FramesThenSignal watch;
  watch = FramesThenSignal{0, 500, 0.0F, nullptr};
  static MainHooks hooks;
  hooks.after_frame = count_then_sigterm;
  hooks.context = &watch;
  std::string console_output;
  const Run r = run_firmware({"--state", dir.c_str(), "--resume"}, [&](FakeBoard& b) {
    b.hooks = &hooks;
    watch.board = &b;
    b.console.feed("status\r");
    b.after_run = [&](FakeBoard& done) { console_output = done.console.written(); };
  });
  STRCMP_CONTAINS(
      "the saved mission has ended (found at cycle 5: within the stand-off of the target): not "
      "resumed, the robot stays stopped; start without --resume for a new mission",
      r.err.c_str());
  // It did not end by itself: it ran until the signal, 5 s of board time, without moving.
  CHECK_EQUAL(500, watch.frames);
  DOUBLES_EQUAL(0.0, watch.fastest_m_s, 0.0);
  STRCMP_CONTAINS("status state=done", console_output.c_str());
  STRCMP_CONTAINS("mission already ended (found: within the stand-off of the target)",
                  console_output.c_str());
  // The MISSION line and the exit code are the saved result's; the state keeps it.
  CHECK_EQUAL(kExitFound, r.exit_code);
  STRCMP_CONTAINS("MISSION result=found cycles=5 ", last_line(r.out).c_str());
  static MissionState state;
  static StateStore store;
  char error[256] = "";
  CHECK(store.open(dir.c_str(), error, sizeof error));
  CHECK(store.load(state, error, sizeof error) == LoadResult::kLoaded);
  CHECK(state.end == MissionEnd::kFound);
  CHECK_EQUAL(5U, state.cycle);
  // With --max-cycles there is nothing to run: it ends at once, with the same words.
  const Run once = run_firmware({"--state", dir.c_str(), "--resume", "--max-cycles", "2"});
  CHECK_EQUAL(kExitFound, once.exit_code);
  STRCMP_CONTAINS("not resumed", once.err.c_str());
  STRCMP_CONTAINS("MISSION result=found cycles=5 ", last_line(once.out).c_str());
}

TEST(FirmwareMain, AnOperatorsStopLeavesTheMissionToResumeButNothingLeftEndsIt) {
  // A console shutdown (like a signal or --max-cycles) stops this run only.
  save_state(dir, 2, MissionEnd::kRunning, "");
  Run r = run_firmware({"--state", dir.c_str(), "--resume"},
                       [](FakeBoard& b) { b.console.feed("quit\r"); });
  CHECK_EQUAL(kExitNotFound, r.exit_code);
  STRCMP_CONTAINS("resumed from", r.err.c_str());
  r = run_firmware({"--state", dir.c_str(), "--resume"},
                   [](FakeBoard& b) { b.console.feed("quit\r"); });
  STRCMP_CONTAINS("resumed from", r.err.c_str());
  // Nothing left to explore is an end: the next start says so and does not carry it on.
  save_state(dir, 9, MissionEnd::kNotFound, "nothing left to explore");
  r = run_firmware({"--state", dir.c_str(), "--resume", "--max-cycles", "1"});
  STRCMP_CONTAINS("the saved mission has ended (not_found at cycle 9: nothing left to explore)",
                  r.err.c_str());
  CHECK_EQUAL(kExitNotFound, r.exit_code);
  STRCMP_CONTAINS("MISSION result=not_found cycles=9 ", last_line(r.out).c_str());
}

TEST(FirmwareMain, TheWatchdogIsOffOnlyByItsKeyEveryStartWarnsOfItAndStatusShowsItsState) {
  const std::string conf = dir + "/boticelli.conf";
  FILE* f = std::fopen(conf.c_str(), "w");
  std::fputs("[watchdog]\nenabled = false\n", f);
  std::fclose(f);
  for (int start = 0; start < 2; ++start) {
    std::string console_output;
    int starts = -1;
    const Run r = run_firmware({"--config", conf.c_str()}, [&](FakeBoard& b) {
      b.watchdog.accept = true;
      b.console.feed("status\rquit\r");
      b.after_run = [&](FakeBoard& done) {
        console_output = done.console.written();
        starts = done.watchdog.starts;
      };
    });
    CHECK_EQUAL(kExitNotFound, r.exit_code);
    STRCMP_CONTAINS(
        "boticelli: hardware watchdog disabled by the configuration ([watchdog] enabled = "
        "false): a hang that systemd cannot end is not reset",
        r.err.c_str());
    CHECK_EQUAL(0, starts);
    STRCMP_CONTAINS("unhealthy=none watchdog=disabled ", console_output.c_str());
  }
  // Enabled (the default): armed with the configured timeout, and said so.
  std::string console_output;
  std::uint32_t started_ms = 0;
  Run r = run_firmware({}, [&](FakeBoard& b) {
    b.watchdog.accept = true;
    b.console.feed("status\rquit\r");
    b.after_run = [&](FakeBoard& done) {
      console_output = done.console.written();
      started_ms = done.watchdog.started_ms;
    };
  });
  CHECK(r.err.find("watchdog") == std::string::npos);
  CHECK_EQUAL(2000U, started_ms);
  STRCMP_CONTAINS("watchdog=armed ", console_output.c_str());
  // A device that cannot be armed: a warning, and status does not pretend it is.
  r = run_firmware({}, [&](FakeBoard& b) {
    b.console.feed("status\rquit\r");
    b.after_run = [&](FakeBoard& done) { console_output = done.console.written(); };
  });
  STRCMP_CONTAINS("boticelli: watchdog not armed (no watchdog in tests)", r.err.c_str());
  STRCMP_CONTAINS("watchdog=unavailable ", console_output.c_str());
  // 0 no longer means "off": it is refused with the reason.
  f = std::fopen(conf.c_str(), "w");
  std::fputs("[watchdog]\ntimeout_ms = 0\n", f);
  std::fclose(f);
  r = run_firmware({"--config", conf.c_str()});
  CHECK_EQUAL(kExitUsage, r.exit_code);
  STRCMP_CONTAINS("watchdog.timeout_ms = 0 is out of range (1000 to 60000): shorter",
                  r.err.c_str());
}

// A base that stopped by itself is restarted by the base task every second (the fault
// policy); one that refuses every restart is given up on after the retry time: the firmware
// exits with the code the service unit restarts on, the mission kept running in the state.
TEST(FirmwareMain, ABaseThatCannotBeRestartedIsRetriedEverySecondThenGivenUpForARestart) {
  int resumes = 0;
  const Run r = run_firmware({"--state", dir.c_str()}, [&](FakeBoard& b) {
    b.base.stop();
    b.base.refuse_resume = true;
    b.after_run = [&](FakeBoard& done) { resumes = done.base.resume_calls; };
  });
  CHECK_EQUAL(kExitFailure, r.exit_code);
  STRCMP_CONTAINS("reason=\"gave up: base unhealthy for 30 s: stopped by itself\"",
                  last_line(r.out).c_str());
  STRCMP_CONTAINS("exiting for a restart", r.err.c_str());
  CHECK(resumes >= 28 && resumes <= 31);
  static MissionState state;
  static StateStore store;
  char error[256] = "";
  CHECK(store.open(dir.c_str(), error, sizeof error));
  CHECK(store.load(state, error, sizeof error) == LoadResult::kLoaded);
  CHECK(state.end == MissionEnd::kRunning);
}

// A base restarted into the same fault (accepted, stopped again half a second later: a
// jammed wheel, an intermittent bus) is retried a second after each stop three times more (an
// intermittent fault that ends soon), then 2, 4, 8, 8 s after each stop; once it runs 10 s
// the next stop is retried after a second again.
TEST(FirmwareMain, ABaseRestartedIntoTheSameFaultIsRetriedLessAndLessOftenUntilItRunsAgain) {
  FakeInput estop, bumper;
  FakeBase base;
  boticelli::firmware::Safety safety{estop, bumper, base};
  boticelli::firmware::BaseTask task{base, safety};
  std::vector<double> resumes_s;
  std::uint64_t stop_at_us = 0;
  base.stop();
  int calls = 0;
  for (std::uint64_t t = 10000; t <= 40000000; t += 10000) {
    if (stop_at_us != 0 && t >= stop_at_us) {
      base.stop();  // the fault is still there
      stop_at_us = 0;
    }
    task.run(t);
    if (base.resume_calls != calls) {
      calls = base.resume_calls;
      resumes_s.push_back(static_cast<double>(t) * 1e-6);
      stop_at_us = t + 500000;
    }
  }
  CHECK(resumes_s.size() >= 8);
  const double expected_gaps[] = {1.5, 1.5, 1.5, 2.5, 4.5, 8.5, 8.5};  // 0.5 s running, then
  for (std::size_t i = 0; i + 1 < resumes_s.size() && i < 7; ++i) {
    DOUBLES_EQUAL(expected_gaps[i], resumes_s[i + 1] - resumes_s[i], 0.011);
  }
  DOUBLES_EQUAL(1.0, resumes_s[0] - 0.01, 0.011);  // the first a second after the stop
  // Well again: runs 10 s, then a new stop is retried after a second.
  std::uint64_t t = 40000000;
  for (; t <= 62000000; t += 10000) task.run(t);  // the next retry (8 s at most), 10 s running
  CHECK(base.health() != boticelli::hal::BaseHealth::kStopped);
  CHECK_EQUAL(boticelli::firmware::BaseTask::kRetryIntervalUs, task.retry_interval_us());
  base.stop();
  const int before = base.resume_calls;
  for (std::uint64_t end = t + 1000000; t <= end; t += 10000) task.run(t);
  CHECK_EQUAL(before + 1, base.resume_calls);
}

namespace {
void press_bumper_at_frame_50(void* context) {
  auto* f = static_cast<FramesThenSignal*>(context);
  if (++f->frames == 50) f->board->bumper.level = true;
}
}  // namespace

TEST(FirmwareMain, ABumperContactEndsTheMissionForGoodAndTheNextStartSaysSo) {
  static FramesThenSignal watch;
  watch = FramesThenSignal{};
  static MainHooks hooks;
  hooks.after_frame = press_bumper_at_frame_50;
  hooks.context = &watch;
  Run r = run_firmware({"--state", dir.c_str()}, [&](FakeBoard& b) {
    b.hooks = &hooks;
    watch.board = &b;
  });
  STRCMP_CONTAINS("MISSION result=aborted cycles=0 ", last_line(r.out).c_str());
  STRCMP_CONTAINS("reason=\"bumper contact\"", last_line(r.out).c_str());
  static MissionState state;
  static StateStore store;
  char error[256] = "";
  CHECK(store.open(dir.c_str(), error, sizeof error));
  CHECK(store.load(state, error, sizeof error) == LoadResult::kLoaded);
  CHECK(state.end == MissionEnd::kAborted);
  STRCMP_EQUAL("bumper contact", state.end_reason.data());
  r = run_firmware({"--state", dir.c_str(), "--resume", "--max-cycles", "1"});
  STRCMP_CONTAINS("the saved mission has ended (aborted at cycle 0: bumper contact)",
                  r.err.c_str());
  CHECK_EQUAL(kExitNotFound, r.exit_code);
}

// The robot is trusted to stand where its pose was saved: a resumed run says how old that
// pose is by the board's wall clock, and warns when it is old enough for someone to have
// moved the robot.
TEST(FirmwareMain, AResumedRunSaysHowOldItsPoseIs) {
  constexpr std::int64_t kSavedMs = 1780000000000LL;
  save_state(dir, 3, MissionEnd::kRunning, "", kSavedMs);
  Run r = run_firmware({"--state", dir.c_str(), "--resume", "--max-cycles", "1"},
                       [](FakeBoard& b) { b.clock.wall_ms_at_zero = kSavedMs + 12000; });
  STRCMP_CONTAINS("boticelli: resumed pose x=1.250 y=-0.500 yaw=0.750 saved 12.0 s ago\n",
                  r.err.c_str());
  // The run saved its own pose at its end with the wall clock's time then (after its 30 s of
  // holds and retries for the fake camera).
  {
    static MissionState state;
    static StateStore store;
    char error[256] = "";
    CHECK(store.open(dir.c_str(), error, sizeof error));
    CHECK(store.load(state, error, sizeof error) == LoadResult::kLoaded);
    CHECK(state.pose_time_ms >= kSavedMs + 12000 + 30000);
    CHECK(state.pose_time_ms <= kSavedMs + 12000 + 40000);
  }
  save_state(dir, 3, MissionEnd::kRunning, "", kSavedMs);
  r = run_firmware({"--state", dir.c_str(), "--resume", "--max-cycles", "1"},
                   [](FakeBoard& b) { b.clock.wall_ms_at_zero = kSavedMs + 7200000; });
  STRCMP_CONTAINS(
      "boticelli: resumed pose x=1.250 y=-0.500 yaw=0.750 saved 7200.0 s ago: if the robot was "
      "moved since, its map is off (start a new mission without --resume)",
      r.err.c_str());
  save_state(dir, 3, MissionEnd::kRunning, "", kSavedMs);
  r = run_firmware({"--state", dir.c_str(), "--resume", "--max-cycles", "1"});
  STRCMP_CONTAINS(
      "resumed pose x=1.250 y=-0.500 yaw=0.750, its age unknown (no wall clock on "
      "this board)",
      r.err.c_str());
}

TEST(FirmwareMain, ADamagedNewestStateCopyIsPassedOverWithAWarningAndTheOlderOneResumed) {
  save_state(dir, 3, MissionEnd::kRunning, "");
  save_state(dir, 4, MissionEnd::kRunning, "");
  FILE* f = std::fopen((dir + "/mission.state.b").c_str(), "r+b");
  std::fseek(f, 30, SEEK_SET);
  std::fputc('#', f);
  std::fclose(f);
  const Run r = run_firmware({"--state", dir.c_str(), "--resume", "--max-cycles", "1"});
  CHECK_EQUAL(kExitFailure, r.exit_code);
  STRCMP_CONTAINS(("boticelli: state copy damaged: " + dir +
                   "/mission.state.b: checksum mismatch (corrupt file); loaded " + dir +
                   "/mission.state.a (sequence 1) instead")
                      .c_str(),
                  r.err.c_str());
  STRCMP_CONTAINS(("resumed from " + dir + "/mission.state.a at cycle 3").c_str(), r.err.c_str());
}

// qemu-user cannot be trusted to fork a process it emulates (the child hangs): native only.
#ifndef BOTICELLI_TESTS_UNDER_EMULATOR
namespace {
// Runs firmware_main in a forked child whose stdout is a pipe nobody reads any more (read
// end closed) and SIGPIPE at its default action, as `boticelli ... | head -1` after head
// ended. The child's wait status, or -1 when the child did not end within 60 s.
int run_with_stdout_a_closed_pipe(const std::vector<const char*>& args) {
  std::fflush(stdout);
  std::fflush(stderr);
  const pid_t child = fork();
  if (child < 0) return -1;
  if (child == 0) {
    int fds[2];
    if (pipe(fds) != 0) _exit(100);
    close(fds[0]);
    dup2(fds[1], STDOUT_FILENO);
    close(fds[1]);
    const int null_fd = open("/dev/null", O_WRONLY);
    if (null_fd >= 0) dup2(null_fd, STDERR_FILENO);
    signal(SIGPIPE, SIG_DFL);
    std::vector<const char*> argv{"boticelli"};
    argv.insert(argv.end(), args.begin(), args.end());
    auto board = std::make_unique<FakeBoard>();
    const int code = firmware_main(static_cast<int>(argv.size()), argv.data(), *board);
    std::fflush(stdout);
    _exit(code);
  }
  return boticelli::test::wait_for_child(child, 60000);
}
}  // namespace

TEST(FirmwareMain, OutputToAClosedPipeDoesNotKillItAndTheMissionEndsWithItsSave) {
  const int status =
      run_with_stdout_a_closed_pipe({"--state", dir.c_str(), "--max-cycles", "1", "--seed", "4"});
  CHECK_TEXT(status != -1, "the child did not end (fork under an emulator?)");
  CHECK_FALSE_TEXT(WIFSIGNALED(status) && WTERMSIG(status) == SIGPIPE, "killed by SIGPIPE");
  CHECK(WIFEXITED(status));
  CHECK_EQUAL(kExitFailure, WEXITSTATUS(status));
  // The orderly end ran: the state was saved with the mission's end in its log.
  static MissionState state;
  static StateStore store;
  char error[256] = "";
  CHECK(store.open(dir.c_str(), error, sizeof error));
  CHECK_TRUE_TEXT(store.load(state, error, sizeof error) == LoadResult::kLoaded, error);
  CHECK_EQUAL(4U, state.seed);
  CHECK_EQUAL(2U, state.log.size());
}

namespace {
// How a forked firmware dies at its 20th frame.
enum class Crash { kAbort, kBadAccess };
struct CrashPlan {
  Crash how = Crash::kAbort;
  int frames = 0;
};
void crash_at_frame_20(void* context) {
  auto* plan = static_cast<CrashPlan*>(context);
  if (++plan->frames < 20) return;
  if (plan->how == Crash::kAbort) std::abort();
  volatile std::uintptr_t address = 8;  // a real fault: the kernel raises SIGSEGV
  *reinterpret_cast<volatile int*>(address) = 1;
}
// Runs firmware_main in a forked child that crashes as planned; what its base's last gasp
// wrote (to a pipe) and the child's wait status (-1: it did not end within 60 s).
std::string crash_and_read_gasp(Crash how, const std::string& dir, int& status) {
  int fds[2];
  CHECK(pipe(fds) == 0);
  std::fflush(stdout);
  std::fflush(stderr);
  const pid_t child = fork();
  if (child == 0) {
    close(fds[0]);
    const int null_fd = open("/dev/null", O_WRONLY);
    if (null_fd >= 0) {
      dup2(null_fd, STDOUT_FILENO);
      dup2(null_fd, STDERR_FILENO);
    }
    static CrashPlan plan;
    plan.how = how;
    static MainHooks hooks;
    hooks.after_frame = crash_at_frame_20;
    hooks.context = &plan;
    auto board = std::make_unique<FakeBoard>();
    board->base.gasp_fd = fds[1];
    const std::vector<const char*> argv{"boticelli", "--state", dir.c_str()};
    const int code = firmware_main(static_cast<int>(argv.size()), argv.data(), *board, &hooks);
    _exit(code == 0 ? 99 : code);
  }
  close(fds[1]);
  status = boticelli::test::wait_for_child(child, 60000);
  std::string gasp;
  char c = 0;
  while (read(fds[0], &c, 1) == 1) gasp.push_back(c);
  close(fds[0]);
  return gasp;
}
}  // namespace

// A crash brakes the base before the process dies, and it still dies of its signal (core
// dump, the wait status systemd restarts on), once.
TEST(FirmwareMain, AnAbortCommandsTheBaseToStopOnceAndStillDiesOfIt) {
  int status = 0;
  STRCMP_EQUAL("G", crash_and_read_gasp(Crash::kAbort, dir, status).c_str());
  CHECK_TEXT(status != -1, "the child did not end");
  CHECK(WIFSIGNALED(status));
  CHECK_EQUAL(SIGABRT, WTERMSIG(status));
}

TEST(FirmwareMain, ABadMemoryAccessCommandsTheBaseToStopOnceAndStillKillsTheProcess) {
  int status = 0;
  STRCMP_EQUAL("G", crash_and_read_gasp(Crash::kBadAccess, dir, status).c_str());
  CHECK_TEXT(status != -1, "the child did not end");
#if defined(__SANITIZE_ADDRESS__)
  // AddressSanitizer's handler (the one found when the last gasp was armed) reports it.
  CHECK(WIFSIGNALED(status) || (WIFEXITED(status) && WEXITSTATUS(status) != 0));
#else
  CHECK(WIFSIGNALED(status));
  CHECK_EQUAL(SIGSEGV, WTERMSIG(status));
#endif
}

// After firmware_main returns, nothing of its last gasp is left armed.
TEST(FirmwareMain, AFinishedRunLeavesNoFatalSignalHandlerBehind) {
  struct sigaction before {};
  sigaction(SIGSEGV, nullptr, &before);
  const Run r = run_firmware({"--max-cycles", "1"});
  CHECK_EQUAL(kExitFailure, r.exit_code);
  struct sigaction after {};
  sigaction(SIGSEGV, nullptr, &after);
  CHECK((before.sa_flags & SA_SIGINFO) == (after.sa_flags & SA_SIGINFO));
  CHECK(reinterpret_cast<void*>(before.sa_sigaction) ==
        reinterpret_cast<void*>(after.sa_sigaction));
}
#endif  // BOTICELLI_TESTS_UNDER_EMULATOR

namespace {
std::string read_all(const std::string& path) {
  std::string s;
  FILE* f = std::fopen(path.c_str(), "rb");
  if (f == nullptr) return "(missing)";
  char buf[4096];
  std::size_t n = 0;
  while ((n = std::fread(buf, 1, sizeof buf, f)) > 0) s.append(buf, n);
  std::fclose(f);
  return s;
}
// The copy (A or B) with the higher sequence number: the state a --resume would load.
std::string read_newest(const std::string& dir) {
  const std::string a = read_all(dir + "/mission.state.a");
  const std::string b = read_all(dir + "/mission.state.b");
  const auto sequence = [](const std::string& f) {
    const std::size_t at = f.find("\nsequence ");
    return at == std::string::npos ? -1L : std::atol(f.c_str() + at + 10);
  };
  return sequence(a) > sequence(b) ? a : b;
}
}  // namespace

TEST(FirmwareMain, ANewMissionKeepsTheSavedOneInsteadOfOverwritingIt) {
  CHECK_EQUAL(kExitNotFound,
              run_firmware({"--state", dir.c_str(), "--seed", "5"}, [](FakeBoard& b) {
                b.console.feed("quit\r");
              }).exit_code);
  const std::string first = read_newest(dir);
  STRCMP_CONTAINS("seed 5", first.c_str());
  Run r = run_firmware({"--state", dir.c_str(), "--seed", "6"},
                       [](FakeBoard& b) { b.console.feed("quit\r"); });
  CHECK_EQUAL(kExitNotFound, r.exit_code);
  STRCMP_CONTAINS(("the saved one is kept as " + dir + "/mission.state.1").c_str(), r.err.c_str());
  CHECK(first == read_all(dir + "/mission.state.1"));
  STRCMP_CONTAINS("seed 6", read_newest(dir).c_str());
  // Older copies shift up; the oldest beyond kKeptStates is dropped.
  for (int i = 0; i < StateStore::kKeptStates; ++i) {
    r = run_firmware({"--state", dir.c_str()}, [](FakeBoard& b) { b.console.feed("quit\r"); });
    CHECK_EQUAL(kExitNotFound, r.exit_code);
  }
  // Three more starts: the seed-6 mission has moved up to the last copy, the first is gone.
  STRCMP_CONTAINS(
      "seed 6",
      read_all(dir + "/mission.state." + std::to_string(StateStore::kKeptStates)).c_str());
  STRCMP_EQUAL(
      "(missing)",
      read_all(dir + "/mission.state." + std::to_string(StateStore::kKeptStates + 1)).c_str());
  // --resume continues the newest one and keeps nothing.
  r = run_firmware({"--state", dir.c_str(), "--resume"},
                   [](FakeBoard& b) { b.console.feed("quit\r"); });
  CHECK(r.err.find("is kept as") == std::string::npos);
}

namespace {
struct SignalAfter {
  int frames = 0;
  int signal = 0;
  int at_frame = 0;
};
void raise_after(void* context) {
  auto* s = static_cast<SignalAfter*>(context);
  if (++s->frames == s->at_frame) std::raise(s->signal);
}
}  // namespace

TEST(FirmwareMain, ASighupStopsInAnOrderlyWayWithTheBaseStoppedAndTheMissionLine) {
  static SignalAfter signal_after;
  signal_after = SignalAfter{0, SIGHUP, 30};
  static MainHooks hooks;
  hooks.after_frame = raise_after;
  hooks.context = &signal_after;
  std::string console_output;
  bool stopped = false;
  const Run r = run_firmware({}, [&](FakeBoard& b) {
    b.hooks = &hooks;
    b.after_run = [&](FakeBoard& done) {
      console_output = done.console.written();
      stopped = done.base.health() == boticelli::hal::BaseHealth::kStopped;
    };
  });
  CHECK_EQUAL(kExitNotFound, r.exit_code);
  CHECK_EQUAL(30, signal_after.frames);  // stopped right after the frame the signal came in
  CHECK(stopped);
  STRCMP_CONTAINS("LOG info stopping: SIGHUP", console_output.c_str());
  STRCMP_CONTAINS("MISSION result=aborted cycles=0", last_line(r.out).c_str());
}

namespace {
// The e-stop pressed 0.5 s into the first look and released at 1 s; the operator asks for the
// status at 6 s, types `clear-estop` at 6.1 s, asks again at 7 s, types `resume` at 7.1 s and
// asks once more at 7.3 s (board time).
struct EstopOperator {
  FakeBoard* board = nullptr;
  int step = 0;
  bool stopped_at_7_s = false;  // the base still stopped after the reset, before resume
};
void estop_operator(void* context) {
  auto* o = static_cast<EstopOperator*>(context);
  FakeBoard& b = *o->board;
  constexpr std::uint64_t kAtUs[] = {500000, 1000000, 6000000, 6100000, 7000000, 7100000, 7300000};
  if (o->step >= 7 || b.clock.now_us() < kAtUs[o->step]) return;
  switch (o->step++) {
    case 0:
      b.estop.level = true;
      break;
    case 1:
      b.estop.level = false;
      break;
    case 2:
    case 4:
    case 6:
      b.console.feed("status\r");
      break;
    case 3:
      b.console.feed("clear-estop\r");
      break;
    case 5:
      o->stopped_at_7_s = b.base.health() == boticelli::hal::BaseHealth::kStopped;
      b.console.feed("resume\r");
      break;
  }
}
}  // namespace

TEST(FirmwareMain, AReleasedEstopHoldsTheMissionUntilClearEstopAndThenResume) {
  static EstopOperator op;
  op = EstopOperator{};
  static MainHooks hooks;
  hooks.after_frame = estop_operator;
  hooks.context = &op;
  std::string console_output;
  const Run r = run_firmware({"--max-cycles", "1"}, [&](FakeBoard& b) {
    op.board = &b;
    b.hooks = &hooks;
    b.after_run = [&](FakeBoard& done) { console_output = done.console.written(); };
  });
  CHECK_EQUAL(7, op.step);
  // Five seconds after the release the mission still holds, waiting for the reset; after it,
  // for resume; only then it goes on.
  const std::size_t held =
      console_output.find("status state=hold estop=button paused=0 waits_for=clear-estop ");
  CHECK_TEXT(held != std::string::npos, console_output.c_str());
  const std::size_t reset =
      console_output.find("status state=hold estop=none paused=0 waits_for=resume ", held);
  CHECK_TEXT(reset != std::string::npos, console_output.c_str());
  CHECK(op.stopped_at_7_s);
  const std::size_t resumed =
      console_output.find("LOG info resumed after the e-stop: base released", reset);
  CHECK_TEXT(resumed != std::string::npos, console_output.c_str());
  CHECK_TEXT(console_output.find("status state=look estop=none paused=0 waits_for=none ",
                                 resumed) != std::string::npos,
             console_output.c_str());
  // The look goes on where it was held (the fake camera never delivers: its frame timeout).
  STRCMP_CONTAINS("MISSION result=aborted cycles=0", last_line(r.out).c_str());
}

namespace {
void write_text(const std::string& path, const char* text) {
  FILE* f = std::fopen(path.c_str(), "wb");
  CHECK(f != nullptr);
  std::fputs(text, f);
  std::fclose(f);
}
}  // namespace

TEST(FirmwareMain, AMissingFileAtTheDefaultPathIsFineButAMissingConfigFileIsAnError) {
  Run r = run_firmware({"--max-cycles", "1"},
                       [](FakeBoard& b) { b.default_config = "/nonexistent/boticelli.conf"; });
  CHECK_EQUAL(kExitFailure, r.exit_code);
  STRCMP_CONTAINS("no /nonexistent/boticelli.conf: compiled-in defaults", r.err.c_str());
  r = run_firmware({"--config", "/nonexistent/other.conf"});
  CHECK_EQUAL(kExitUsage, r.exit_code);
  STRCMP_CONTAINS("configuration: /nonexistent/other.conf: No such file or directory",
                  r.err.c_str());
  CHECK(r.out.find("MISSION") == std::string::npos);  // stopped before anything ran
}

TEST(FirmwareMain, ABadConfigFileStopsTheStartWithFileLineWhy) {
  const std::string conf = dir + "/boticelli.conf";
  write_text(conf, "[console]\ntelemetry_period_ms = 90000\n");
  Run r = run_firmware({"--config", conf.c_str()});
  CHECK_EQUAL(kExitUsage, r.exit_code);
  STRCMP_CONTAINS(
      (conf + ":2: console.telemetry_period_ms = 90000 is out of range (0 to 60000)").c_str(),
      r.err.c_str());
  // The same file at the board's default path is just as fatal.
  r = run_firmware({}, [&](FakeBoard& b) { b.default_config = conf.c_str(); });
  CHECK_EQUAL(kExitUsage, r.exit_code);
}

TEST(FirmwareMain, TheConfigFileSetsWhatTheFirmwareStartsWith) {
  const std::string conf = dir + "/boticelli.conf";
  write_text(conf, "[console]\ntelemetry_period_ms = 250\n");
  std::string console_output;
  const Run r = run_firmware({"--config", conf.c_str()}, [&](FakeBoard& b) {
    b.console.feed("get telemetry_ms\rparam show\rquit\r");
    b.after_run = [&](FakeBoard& done) { console_output = done.console.written(); };
  });
  CHECK_EQUAL(kExitNotFound, r.exit_code);
  STRCMP_CONTAINS(("configuration from " + conf).c_str(), r.err.c_str());
  STRCMP_CONTAINS("telemetry_ms=250 range=[0,60000]", console_output.c_str());
  // The configured value is the parameter's default: nothing to show.
  CHECK(console_output.find("telemetry_ms=250 default") == std::string::npos);
}

TEST(FirmwareMain, SavedParametersSurviveARestart) {
  std::string console_output;
  Run r = run_firmware({"--state", dir.c_str()}, [&](FakeBoard& b) {
    b.console.feed("set telemetry_ms 250\rset bg_slice_us 3000\rparam save\rquit\r");
    b.after_run = [&](FakeBoard& done) { console_output = done.console.written(); };
  });
  CHECK_EQUAL(kExitNotFound, r.exit_code);
  STRCMP_CONTAINS(("param save changed=2 file=" + dir + "/parameters.conf").c_str(),
                  console_output.c_str());
  r = run_firmware({"--state", dir.c_str()}, [&](FakeBoard& b) {
    b.console.feed("param show\rquit\r");
    b.after_run = [&](FakeBoard& done) { console_output = done.console.written(); };
  });
  CHECK_EQUAL(kExitNotFound, r.exit_code);
  STRCMP_CONTAINS("parameters from ", r.err.c_str());
  STRCMP_CONTAINS("telemetry_ms=250 default=1000\r\nbg_slice_us=3000 default=0\r\nOK",
                  console_output.c_str());
}

TEST(FirmwareMain, ASavedParameterTheFirmwareNoLongerHasIsSkippedButAFileThatIsNotTomlStops) {
  write_text(dir + "/parameters.conf", "retired_gain = 3\ntelemetry_ms = 500\n");
  std::string console_output;
  Run r = run_firmware({"--state", dir.c_str()}, [&](FakeBoard& b) {
    b.console.feed("get telemetry_ms\rquit\r");
    b.after_run = [&](FakeBoard& done) { console_output = done.console.written(); };
  });
  CHECK_EQUAL(kExitNotFound, r.exit_code);
  STRCMP_CONTAINS("parameters.conf:1: retired_gain: unknown parameter; default kept",
                  r.err.c_str());
  STRCMP_CONTAINS("telemetry_ms=500 ", console_output.c_str());
  write_text(dir + "/parameters.conf", "telemetry_ms = \n");
  r = run_firmware({"--state", dir.c_str()});
  CHECK_EQUAL(kExitUsage, r.exit_code);
  STRCMP_CONTAINS("saved parameters: ", r.err.c_str());
  STRCMP_CONTAINS("parameters.conf:1: ", r.err.c_str());
}
