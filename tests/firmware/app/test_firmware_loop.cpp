// The firmware's cyclic path around the mission (device tasks, console, telemetry, state saves
// from the background slot) runs without heap allocation; the mission's own share is proved by
// the whole-mission test (tests/mission).
#include <stdlib.h>
#include <sys/stat.h>
#include <unistd.h>

#include <string>

#include "fake_clock.h"
#include "fake_serial_port.h"
#include "firmware/console/console.h"
#include "firmware/app/device_tasks.h"
#include "firmware/app/runtime.h"
#include "firmware/executive/executive.h"
#include "firmware/telemetry/mission_view.h"
#include "firmware/common/text_buffer.h"
#include "firmware/state/persistence.h"
#include "firmware/app/service_notify.h"
#include "firmware/state/state_saver.h"
#include "firmware/executive/task_table.h"
#include "firmware_fakes.h"

#include "alloc_guard.h"
#include "CppUTest/TestHarness.h"

using namespace boticelli::firmware;
using namespace boticelli::test;

namespace {
MissionState g_loop_state;
StateStore g_loop_store;
// The mission task's slot in the table (this test runs the checkpoint cycle, no mission).
class IdleTask final : public Task {
 public:
  void run(std::uint64_t) override {}
};

// Background work in the mission's place: every `period_us` of board time a checkpoint (the
// odometry pose and a log line) handed to the StateSaver, as the mission does after a cycle.
class CheckpointWork final : public MissionView, public BackgroundWork, public FrameConsumer {
 public:
  CheckpointWork(boticelli::hal::Base& base, boticelli::hal::Clock& clock, MissionState& state,
                 StateSaver& saver, std::uint32_t period_us)
      : base_(base), clock_(clock), state_(state), saver_(saver), period_us_(period_us) {}
  void start(std::uint64_t now_us) { next_cycle_us_ = now_us + period_us_; }
  SliceResult run_slice(SliceBudget& budget) override {
    if (submit_pending_ && saver_.submit(state_)) submit_pending_ = false;
    if (clock_.now_us() < next_cycle_us_ || !budget.next_unit()) return SliceResult::kMore;
    next_cycle_us_ += period_us_;
    ++state_.cycle;
    ++cycles_this_run_;
    state_.pose = pose();
    TextBuffer<MissionLogEntry::kMaxTextBytes + 1> line;
    line.appendf("checkpoint x_m=%.3f", static_cast<double>(state_.pose.x_m));
    state_.add_log(state_.cycle, line.view());
    submit_pending_ = !saver_.submit(state_);
    return SliceResult::kDone;
  }
  void on_frame(const boticelli::hal::Frame&) override {}  // frames are taken and released
  const char* state_name() const override { return "checkpoint"; }
  boticelli::core::Pose2 pose() const override {
    const boticelli::hal::Odometry o = base_.odometry();
    return {static_cast<float>(o.x_m), static_cast<float>(o.y_m), static_cast<float>(o.yaw_rad)};
  }
  float pan_rad() const override { return 0.0F; }
  std::uint64_t cycles() const override { return state_.cycle; }
  std::uint64_t cycles_this_run() const { return cycles_this_run_; }
  void finish_saving() {
    while (submit_pending_) submit_pending_ = !saver_.submit(state_);
    saver_.flush();
  }

 private:
  boticelli::hal::Base& base_;
  boticelli::hal::Clock& clock_;
  MissionState& state_;
  StateSaver& saver_;
  std::uint32_t period_us_;
  std::uint64_t next_cycle_us_ = 0;
  std::uint64_t cycles_this_run_ = 0;
  bool submit_pending_ = false;
};
}  // namespace

TEST_GROUP(FirmwareLoop) {
  std::string dir;
  void setup() override {
    char templ[] = "/tmp/boticelli-loop-XXXXXX";
    dir = mkdtemp(templ);
  }
  void teardown() override {
    rmdir((dir + "/mission.state.a.tmp").c_str());
    for (const char* name : {"/mission.state.a", "/mission.state.b"}) unlink((dir + name).c_str());
    rmdir(dir.c_str());
  }
};

namespace {
// The firmware's Runtime (device tasks, console, state saver) on fakes, as firmware_main runs
// it, with a checkpoint saver in the mission's place (the mission task idle).
struct LoopRig {
  boticelli::fakes::FakeClock clock{0};
  boticelli::fakes::FakeSerialPort port;
  FakeCamera camera;
  FakePanTilt ptu;
  FakeBase base{&clock};
  FakeInput button, bumper;
  FakeOutput led;
  FakeWatchdog watchdog;
  boticelli::hal::Hal hal{camera, ptu, base, button, bumper, led, port, clock, watchdog};
  ParameterTable parameters;
  Runtime rt{hal, port, g_loop_store, parameters};
  // Not started: saves in the background slot, as on the sim board.
  StateSaver& saver = rt.saver;
  Executive& exec = rt.executive;
  CheckpointWork mission{base, clock, g_loop_state, saver, 1000000};
  IdleTask mission_task;

  Console& console() { return *rt.console; }
  void start(float telemetry_ms = 0.0F, bool parameter_saver = true) {
    const char* why = "";
    CHECK(rt.attach({mission_task, mission, mission, mission}, &why));
    CHECK(console().register_parameters());
    console().set_telemetry_ms(telemetry_ms);
    if (parameter_saver) console().set_parameter_saver(&saver);
    CHECK(exec.start(ExecutiveConfig{}, &why));
    mission.start(clock.now_us());
    port.reserve_written(64 * 1024);
  }
  void frames(int n) {
    for (int i = 0; i < n; ++i) exec.run_frame();
  }
};
}  // namespace

TEST(FirmwareLoop, AFailingStateSaveIsLoggedAtOnceAndMakesTheStorageUnhealthyUntilOneSucceeds) {
  char error[256] = "";
  CHECK(g_loop_store.open(dir.c_str(), error, sizeof error));
  g_loop_state.clear();
  // A directory where the temporary file must go: every save fails (as on a full or
  // read-only disk), also for root.
  // (The first save goes to copy A.)
  CHECK_EQUAL(0, mkdir((dir + "/mission.state.a.tmp").c_str(), 0700));
  LoopRig rig;
  rig.start();
  CHECK_NO_ALLOCATION(rig.frames(103));  // the first checkpoint at 1 s, then 3 frames
  CHECK_EQUAL(1U, rig.saver.failures());
  STRCMP_CONTAINS("LOG error storage unhealthy: state not saved (1 failed): ",
                  rig.port.written().c_str());
  STRCMP_CONTAINS("mission.state.a.tmp", rig.port.written().c_str());
  rig.port.feed("status\rstats\r");
  rig.frames(2);
  STRCMP_CONTAINS("healthy=0 unhealthy=storage watchdog=unavailable cycles=1",
                  rig.port.written().c_str());
  STRCMP_CONTAINS("storage saved=0 failed=1 healthy=0", rig.port.written().c_str());
  CHECK(rig.watchdog.kicks > 0);  // a restart cannot free a disk: the watchdog is still kicked
  const int kicks = rig.watchdog.kicks;
  rig.frames(20);
  CHECK(rig.watchdog.kicks > kicks);
  CHECK_EQUAL(0, rmdir((dir + "/mission.state.a.tmp").c_str()));
  rig.port.clear_written();
  rig.frames(100);  // the next checkpoint is saved
  STRCMP_CONTAINS("LOG info storage healthy again: state saved", rig.port.written().c_str());
  rig.port.feed("status\r");
  rig.frames(2);
  STRCMP_CONTAINS("healthy=1 unhealthy=none", rig.port.written().c_str());
}

TEST(FirmwareLoop, AnUnhealthyTaskIsLoggedWithItsNameAndReasonAndShownInStatusAndStats) {
  char error[256] = "";
  CHECK(g_loop_store.open(dir.c_str(), error, sizeof error));
  g_loop_state.clear();
  LoopRig rig;
  rig.start();
  rig.frames(10);
  rig.base.stop();  // stopped by itself (no e-stop): the base task is unhealthy
  rig.port.feed("status\rstats\r");
  CHECK_NO_ALLOCATION(rig.frames(5));
  const std::string out = rig.port.written();
  STRCMP_CONTAINS("LOG error base unhealthy: stopped by itself (held and retried)", out.c_str());
  STRCMP_CONTAINS("healthy=0 unhealthy=base watchdog=", out.c_str());
  STRCMP_CONTAINS("overruns=0 healthy=0 why=\"stopped by itself\"", out.c_str());
  STRCMP_CONTAINS("task ptu      period_us=20000 budget_us=500 runs=", out.c_str());
  CHECK(rig.base.resume());
  rig.port.clear_written();
  rig.frames(3);
  STRCMP_CONTAINS("LOG info base healthy again", rig.port.written().c_str());
}

TEST(FirmwareLoop, RunsTasksConsoleTelemetryAndCheckpointsWithoutAllocating) {
  char error[256] = "";
  CHECK(g_loop_store.open(dir.c_str(), error, sizeof error));
  g_loop_state.clear();
  LoopRig rig;
  rig.start(250.0F, false);
  rig.port.feed("status\rstats\rpose\rmap\rmodel\rget\rset telemetry_ms 500\rbogus\r");

  CHECK_NO_ALLOCATION(rig.frames(350));

  rig.mission.finish_saving();
  CHECK_EQUAL(3U, rig.mission.cycles_this_run());
  CHECK_EQUAL(3U, rig.saver.saved());
  CHECK_EQUAL(0U, rig.saver.failures());
  CHECK(rig.watchdog.kicks > 0);
  CHECK(rig.camera.releases > 0);
  CHECK(rig.port.written().find("TLM ") != std::string::npos);
  CHECK(rig.port.written().find("ERR unknown command") != std::string::npos);
  CHECK(g_loop_store.load(g_loop_state, error, sizeof error) == LoadResult::kLoaded);
  CHECK_EQUAL(3U, g_loop_state.cycle);
}
