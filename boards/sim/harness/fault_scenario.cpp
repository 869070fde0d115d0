// FaultScenario: the firmware's device tasks on the sim board around a stand-in mission, with
// one injected fault, measured frame by frame (see fault_scenario.h).
#include "fault_scenario.h"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cmath>
#include <cstdio>
#include <cstring>
#include <optional>
#include <string_view>

#include "firmware/console/console.h"
#include "firmware/app/device_tasks.h"
#include "firmware/executive/executive.h"
#include "firmware/telemetry/mission_view.h"
#include "firmware/common/parameters.h"
#include "firmware/state/persistence.h"
#include "firmware/safety/safety.h"
#include "firmware/app/runtime.h"
#include "firmware/app/service_notify.h"
#include "firmware/state/state_saver.h"
#include "firmware/executive/task_table.h"
#include "firmware/common/text_buffer.h"
#include "sim_board.h"

namespace boticelli::boards::sim {
namespace {

using hal::sim::FaultDevice;
using hal::sim::FaultType;
namespace fw = firmware;

// The pairs' expectations, by device then type (docs/reliability.md).
struct ExpectationRow {
  FaultDevice device;
  FaultType type;
  FaultExpectation expected;
};

// The mission's column (the fault policy, docs/reliability.md): a device fault holds the robot
// stopped and the device is retried every second; the mission carries on once it is back
// (within the retry time, 30 s; past it the firmware would exit for a restart).
constexpr const char* kCameraHold =
    "holds after the 3 s frame timeout (no camera frame), retries every second, carries on "
    "when the camera is back";
constexpr const char* kPtuHold =
    "holds (pan-tilt unit fault), retries every second, carries on when the PTU is back";
constexpr const char* kBaseRetry =
    "carries on: the base task restarts the base (every second) once the fault is over; a step "
    "finds it stopped only to hold until then";
constexpr const char* kCarriesOn = "carries on";
constexpr const char* kHoldsUntilReset =
    "holds until the operator's clear-estop and resume (typed 2 s after the line is back), "
    "then carries on";
// The driver's check of a wheel against its setpoint trips after 1 s (BaseParams
// follow_timeout_us), seen at the next frame; a jammed wheel first slows to a quarter of its
// setpoint (0.06 s at the brake deceleration).
constexpr const char* kWatchdogHold =
    "holds while the keep-alives are refused (a board that resets mid-drive lets the robot "
    "coast), carries on once one is taken; on a robot a refusal longer than the timeout resets "
    "the board and the service resumes at boot";
constexpr std::uint32_t kFollowDetectUs = 1010000;
constexpr std::uint32_t kJamDetectUs = 1100000;
constexpr ExpectationRow kExpectations[] = {
    {FaultDevice::kCamera,
     FaultType::kOff,
     {false, "camera unhealthy: no new frame for 2.0 s: camera: device gone", true, kCameraHold,
      false, false, true}},
    {FaultDevice::kCamera,
     FaultType::kStuck,
     {false, "camera unhealthy: no new frame for 2.0 s: the same frame again", true, kCameraHold,
      false, false, true}},
    {FaultDevice::kCamera,
     FaultType::kGarbage,
     {false, "camera unhealthy: no new frame for 2.0 s", true, kCameraHold, false, false, true}},
    {FaultDevice::kCamera,
     FaultType::kWrong,
     {false, "camera unhealthy: no new frame for 2.0 s: frames of the wrong size", true,
      kCameraHold, false, false, true}},
    {FaultDevice::kCamera, FaultType::kSlow, {false, "unhealthy=none", true, kCarriesOn}},
    {FaultDevice::kCamera, FaultType::kDelayed, {false, "unhealthy=none", true, kCarriesOn}},
    {FaultDevice::kCamera, FaultType::kIntermittent, {false, "unhealthy=none", true, kCarriesOn}},
    {FaultDevice::kPtu,
     FaultType::kOff,
     {false, "ptu unhealthy: PTU: no reply for 0.5 s", true, kPtuHold, false, false, true}},
    {FaultDevice::kPtu,
     FaultType::kStuck,
     {false, "ptu unhealthy: PTU: a move is not progressing", true,
      "carries on when the move ends within the 8 s move timeout, else holds and retries the "
      "move every second"}},
    {FaultDevice::kPtu,
     FaultType::kGarbage,
     {false, "ptu unhealthy: PTU: garbled reply", true, kPtuHold, false, false, true}},
    {FaultDevice::kPtu,
     FaultType::kWrong,
     {false, "unhealthy=none", true,
      "holds (pan-tilt unit refused a move), retries every second, carries on when the PTU "
      "takes moves again",
      false, false, true}},
    {FaultDevice::kPtu, FaultType::kSlow, {false, "unhealthy=none", true, kCarriesOn}},
    {FaultDevice::kPtu, FaultType::kDelayed, {false, "unhealthy=none", true, kCarriesOn}},
    {FaultDevice::kPtu,
     FaultType::kIntermittent,
     {false, "ptu unhealthy: PTU: garbled reply", true, kPtuHold, false, false, true}},
    {FaultDevice::kAxisLeft,
     FaultType::kOff,
     {true, "base unhealthy: base: left axis: heartbeat lost", true, kBaseRetry, false, false,
      false, true}},
    {FaultDevice::kAxisLeft,
     FaultType::kStuck,
     {true, "base unhealthy: base: left axis: wheel not following its setpoint", true, kBaseRetry,
      false, false, false, true, kFollowDetectUs, true}},
    {FaultDevice::kAxisLeft,
     FaultType::kWrong,
     {true, "base unhealthy: base: left axis: ODrive reports an axis error", true, kBaseRetry,
      false, false, false, true}},
    {FaultDevice::kAxisLeft,
     FaultType::kSlow,
     {true, "base unhealthy: base: left axis: wheel not following its setpoint", true, kBaseRetry,
      false, false, false, true, kJamDetectUs, true}},
    {FaultDevice::kAxisLeft,
     FaultType::kIntermittent,
     {true, "base unhealthy: base: left axis: heartbeat lost", true, kBaseRetry, false, false,
      false, true}},
    {FaultDevice::kAxisRight,
     FaultType::kOff,
     {true, "base unhealthy: base: right axis: heartbeat lost", true, kBaseRetry, false, false,
      false, true}},
    {FaultDevice::kAxisRight,
     FaultType::kStuck,
     {true, "base unhealthy: base: right axis: wheel not following its setpoint", true, kBaseRetry,
      false, false, false, true, kFollowDetectUs, true}},
    {FaultDevice::kAxisRight,
     FaultType::kWrong,
     {true, "base unhealthy: base: right axis: ODrive reports an axis error", true, kBaseRetry,
      false, false, false, true}},
    {FaultDevice::kAxisRight,
     FaultType::kSlow,
     {true, "base unhealthy: base: right axis: wheel not following its setpoint", true, kBaseRetry,
      false, false, false, true, kJamDetectUs, true}},
    {FaultDevice::kAxisRight,
     FaultType::kIntermittent,
     {true, "base unhealthy: base: right axis: heartbeat lost", true, kBaseRetry, false, false,
      false, true}},
    {FaultDevice::kCan,
     FaultType::kOff,
     {true, "base unhealthy: base: CAN bus-off", true, kBaseRetry, false, false, false, true}},
    {FaultDevice::kCan,
     FaultType::kDelayed,
     {false, "unhealthy=none", true,
      "carries on (setpoints and estimates 50 ms late stay within the driver's timeouts)"}},
    {FaultDevice::kCan,
     FaultType::kIntermittent,
     {true, "base unhealthy: base: CAN bus-off", true, kBaseRetry, false, false, false, true}},
    {FaultDevice::kEstop,
     FaultType::kOff,
     {true, "e-stop engaged: button (base stopped)", true, kHoldsUntilReset, false, true}},
    {FaultDevice::kEstop,
     FaultType::kStuck,
     {true, "e-stop engaged: button (base stopped)", true, kHoldsUntilReset, false, true}},
    {FaultDevice::kEstop,
     FaultType::kIntermittent,
     {true, "e-stop engaged: button (base stopped)", true, kHoldsUntilReset, false, true}},
    {FaultDevice::kBumper,
     FaultType::kOff,
     {true, "e-stop engaged: bumper (base stopped)", false,
      "aborted for good: bumper contact (not resumed at the next start)", true}},
    {FaultDevice::kBumper,
     FaultType::kStuck,
     {true, "e-stop engaged: bumper (base stopped)", false,
      "aborted for good: bumper contact (not resumed at the next start)", true}},
    {FaultDevice::kBumper,
     FaultType::kIntermittent,
     {true, "e-stop engaged: bumper (base stopped)", false,
      "aborted for good: bumper contact (not resumed at the next start)", true}},
    {FaultDevice::kStorage,
     FaultType::kOff,
     {false, "storage unhealthy: state not saved (1 failed): cannot create", true,
      "carries on; saves fail while it lasts, the last good state file stays"}},
    {FaultDevice::kStorage,
     FaultType::kStuck,
     {false, "Read-only file system", true,
      "carries on; saves fail while it lasts, the last good state file stays"}},
    {FaultDevice::kStorage,
     FaultType::kWrong,
     {false, "No space left on device", true,
      "carries on; saves fail while it lasts, the last good state file stays"}},
    {FaultDevice::kStorage,
     FaultType::kIntermittent,
     {false, "storage unhealthy: state not saved", true,
      "carries on; some saves fail, the last good state file stays"}},
    {FaultDevice::kMainLoop,
     FaultType::kStuck,
     {true, "base unhealthy: base: left axis: ODrive reports an axis error (0x00000800)", true,
      kBaseRetry, false, false, false, true}},
    {FaultDevice::kMainLoop,
     FaultType::kSlow,
     {false, "LOG warn overruns frame=", true, "carries on; frames overrun"}},
    {FaultDevice::kWatchdog,
     FaultType::kOff,
     {false, "watchdog unhealthy: watchdog: keep-alive refused", true, kWatchdogHold, false, false,
      true}},
    {FaultDevice::kWatchdog,
     FaultType::kStuck,
     {false, "watchdog=unavailable", true,
      "carries on without the hardware watchdog (the start's warning names the holder; systemd's "
      "own watchdog still restarts a hung firmware)",
      false, false, false, false, 0, false, true}},
    {FaultDevice::kWatchdog,
     FaultType::kIntermittent,
     {false, "watchdog unhealthy: watchdog: keep-alive refused", true, kWatchdogHold, false, false,
      true}},
};

constexpr FaultExpectation kNoExpectation{};

// The console's output, kept in a fixed buffer (beyond it the rest is dropped); input fed
// by the scenario.
class CapturePort final : public hal::SerialPort {
 public:
  bool open() override { return true; }
  std::ptrdiff_t read(std::uint8_t* buffer, std::size_t max) override {
    std::size_t n = 0;
    while (n < max && in_pos_ < in_len_) buffer[n++] = static_cast<std::uint8_t>(in_[in_pos_++]);
    return static_cast<std::ptrdiff_t>(n);
  }
  std::ptrdiff_t write(const std::uint8_t* data, std::size_t size) override {
    for (std::size_t i = 0; i < size; ++i) {
      if (out_len_ + 1 < out_.size()) out_[out_len_++] = static_cast<char>(data[i]);
    }
    out_[out_len_] = '\0';
    return static_cast<std::ptrdiff_t>(size);
  }
  void feed(std::string_view text) {
    if (in_pos_ == in_len_) in_pos_ = in_len_ = 0;  // all read: room again
    for (const char c : text) {
      if (in_len_ < in_.size()) in_[in_len_++] = c;
    }
  }
  std::string_view written() const { return {out_.data(), out_len_}; }
  void clear() {
    out_len_ = in_len_ = in_pos_ = 0;
    out_[0] = '\0';
  }

 private:
  std::array<char, 32768> out_{};
  std::size_t out_len_ = 0;
  std::array<char, 256> in_{};
  std::size_t in_len_ = 0;
  std::size_t in_pos_ = 0;
};

// In the mission's place: keeps the base turning in place (no contact possible) and the PTU
// scanning, takes frames, and saves a state every half second. Like the mission it holds while
// the e-stop latch does (engaged, or reset and waiting for the console's `resume`).
class StandIn final : public fw::Task,
                      public fw::MissionView,
                      public fw::FrameConsumer,
                      public fw::BackgroundWork {
 public:
  StandIn(hal::Hal& hal, fw::Safety& safety, fw::MissionState& state, fw::StateSaver* saver)
      : hal_(hal), safety_(safety), state_(state), saver_(saver) {}
  // Frames are taken (rendered) only when the camera is what is tested.
  void set_wants_frames(bool wants) { wants_frames_ = wants; }
  bool wants_frames() const override { return wants_frames_; }

  void run(std::uint64_t now_us) override {
    now_us_ = now_us;
    if (!safety_.holds() && hal_.base.health() == hal::BaseHealth::kReady) {
      hal_.base.set_velocity(0.0F, 0.4F);
    }
    const hal::PanTiltState ptu = hal_.pan_tilt.state();
    if (!ptu.moving && !ptu.fault) {
      pan_sign_ = -pan_sign_;
      if (hal_.pan_tilt.move_to(0.6F * pan_sign_, 0.0F)) ++ptu_moves_;
    }
  }
  void on_frame(const hal::Frame& frame) override {
    ++frames_;
    const double lag_ms = static_cast<double>(now_us_ - frame.timestamp_us) * 1e-3;
    if (lag_ms > worst_lag_ms_) worst_lag_ms_ = lag_ms;
  }
  fw::SliceResult run_slice(fw::SliceBudget& budget) override {
    if (saver_ == nullptr || now_us_ < next_save_us_ || !budget.next_unit()) {
      return fw::SliceResult::kMore;
    }
    next_save_us_ = now_us_ + 500000U;
    ++state_.cycle;
    const hal::Odometry o = hal_.base.odometry();
    state_.pose = {static_cast<float>(o.x_m), static_cast<float>(o.y_m),
                   static_cast<float>(o.yaw_rad)};
    (void)saver_->submit(state_);  // no writer thread on the sim board: saved here
    return fw::SliceResult::kDone;
  }
  const char* state_name() const override { return "exercise"; }
  core::Pose2 pose() const override {
    const hal::Odometry o = hal_.base.odometry();
    return {static_cast<float>(o.x_m), static_cast<float>(o.y_m), static_cast<float>(o.yaw_rad)};
  }
  float pan_rad() const override { return hal_.pan_tilt.state().pan_rad; }
  std::uint64_t cycles() const override { return state_.cycle; }

  std::uint64_t frames() const { return frames_; }
  std::uint64_t ptu_moves() const { return ptu_moves_; }
  double worst_lag_ms() const { return worst_lag_ms_; }

 private:
  hal::Hal& hal_;
  fw::Safety& safety_;
  fw::MissionState& state_;
  fw::StateSaver* saver_;
  std::uint64_t now_us_ = 0;
  std::uint64_t next_save_us_ = 0;
  std::uint64_t frames_ = 0;
  std::uint64_t ptu_moves_ = 0;
  double worst_lag_ms_ = 0.0;
  float pan_sign_ = 1.0F;
  bool wants_frames_ = true;
};

// The firmware's runtime around the stand-in, as firmware_main runs it around the mission
// (static storage: a few hundred kB, one scenario at a time).
struct Rig {
  Rig(hal::Hal& hal, fw::StateStore& store, bool saving)
      : runtime(hal, port, store, parameters),
        stand_in(hal, runtime.safety, state, saving ? &runtime.saver : nullptr) {}

  fw::MissionState state;
  CapturePort port;
  fw::ParameterTable parameters;
  fw::Runtime runtime;
  StandIn stand_in;
};

fw::StateStore g_store;
std::optional<Rig> g_rig;
fw::MissionState g_loaded;

// The true wheels (not the odometry, which a frozen encoder fools).
bool wheels_at_rest(const hal::sim::SimWorld& sim) {
  return sim.wheel_speed_m_s() < 1e-6F;
}

// Flips every bit of the byte in the middle of `path` (a damaged copy); false when it cannot.
// POSIX calls only: nothing allocates.
bool flip_middle_byte(const char* path) {
  const int fd = ::open(path, O_RDWR | O_CLOEXEC);
  if (fd < 0) return false;
  struct stat st {};
  bool ok = ::fstat(fd, &st) == 0 && st.st_size > 0;
  unsigned char byte = 0;
  const off_t at = ok ? st.st_size / 2 : 0;
  ok = ok && ::pread(fd, &byte, 1, at) == 1;
  byte = static_cast<unsigned char>(byte ^ 0xFFU);
  ok = ok && ::pwrite(fd, &byte, 1, at) == 1;
  ::close(fd);
  return ok;
}

bool contains(std::string_view text, const char* what) {
  return what[0] == '\0' || text.find(what) != std::string_view::npos;
}

// Inits the board (with its default_faults() as the plan) and the rig; false with the reason.
bool start_rig(SimBoard& board, const FaultScenarioConfig& config, bool wants_frames, char* error,
               std::size_t error_size) {
  board.settings().camera_fps = config.camera_fps;
  fw::Options options;
  options.world_file = config.world_file;
  options.seed = config.seed;
  if (!board.init(options, error, error_size)) return false;
  hal::Hal& hal = board.hal();
  if (config.state_dir != nullptr && !g_store.open(config.state_dir, error, error_size)) {
    return false;
  }
  if (!hal.base.init() || !hal.pan_tilt.init() || !hal.camera.init()) {
    std::snprintf(error, error_size, "device init failed");
    return false;
  }
  const bool watchdog_armed = hal.watchdog.start(board.config().watchdog_timeout_ms);
  g_rig.reset();
  g_rig.emplace(hal, g_store, config.state_dir != nullptr);
  Rig& rig = *g_rig;
  rig.state.clear();
  rig.stand_in.set_wants_frames(wants_frames);
  const char* why = "";
  if (!rig.runtime.attach({rig.stand_in, rig.stand_in, rig.stand_in, rig.stand_in}, &why)) {
    std::snprintf(error, error_size, "executive: %s", why);
    return false;
  }
  rig.runtime.console->set_telemetry_ms(0.0F);
  rig.runtime.console->set_watchdog_state(watchdog_armed
                                              ? fw::Console::WatchdogState::kArmed
                                              : fw::Console::WatchdogState::kUnavailable);
  rig.runtime.console->set_fault_injection(&board);
  if (config.state_dir != nullptr) rig.runtime.console->set_parameter_saver(&rig.runtime.saver);
  fw::ExecutiveConfig exec_config;
  exec_config.frame_us = board.config().minor_frame_us;
  exec_config.background_units_per_slice = board.config().background_units_per_slice;
  if (!rig.runtime.executive.start(exec_config, &why)) {
    std::snprintf(error, error_size, "executive: %s", why);
    return false;
  }
  return true;
}

}  // namespace

const FaultExpectation& expectation(FaultDevice device, FaultType type) {
  for (const ExpectationRow& row : kExpectations) {
    if (row.device == device && row.type == type) return row.expected;
  }
  return kNoExpectation;
}

bool run_fault_scenario(SimBoard& board, FaultDevice device, FaultType type,
                        const FaultScenarioConfig& config, FaultScenarioResult& out) {
  out = FaultScenarioResult{};
  if (!hal::sim::fault_applies(device, type)) {
    std::snprintf(out.error, sizeof out.error, "%s cannot be %s",
                  hal::sim::fault_device_name(device), hal::sim::fault_type_name(type));
    return false;
  }
  const FaultExpectation& expected = expectation(device, type);
  // The plan: the one fault.
  hal::sim::Fault fault;
  fault.device = device;
  fault.type = type;
  fault.start_us =
      expected.at_start ? 0U : static_cast<std::uint64_t>(std::llround(config.fault_start_s * 1e6));
  fault.duration_us = static_cast<std::uint64_t>(std::llround(config.fault_s * 1e6));
  board.default_faults().clear();
  (void)board.default_faults().add(fault);
  if (!start_rig(board, config, device == FaultDevice::kCamera, out.error, sizeof out.error)) {
    return false;
  }
  Rig& rig = *g_rig;
  hal::Hal& hal = board.hal();
  hal::sim::SimWorld& sim = board.sim();
  // (1 µs for a fault from the start: 0 is "none" in the bookkeeping below.)
  const std::uint64_t onset_us = fault.start_us != 0 ? fault.start_us : 1U;
  const std::uint64_t end_us = fault.end_us();
  const std::uint64_t stop_us =
      end_us + static_cast<std::uint64_t>(std::llround(config.after_s * 1e6));
  // The main loop's stall stops the wheels through the ODrives' own watchdog.
  const std::uint64_t allowed_us =
      (device == FaultDevice::kMainLoop ? 210000U : 10000U) + expected.detect_us;
  const std::uint64_t mid_us = onset_us + fault.duration_us * 3U / 4U;
  bool asked_mid = false;
  bool stopped_seen = false;
  bool broke_stop = false;
  bool after_seen = false;
  bool moved_after_end = false;
  std::uint64_t failing_since_us = 0;
  std::uint64_t frames_at_end = 0;
  std::uint64_t moves_at_end = 0;
  // The wheels at the onset (updated each frame before it, then at the start of the failing
  // spell that stopped the base): the faster wheel's speed and the ground covered so far.
  double onset_speed = 0.0;
  double onset_travel = 0.0;
  std::uint64_t stop_since_us = 0;   // the onset of the spell that stopped the base
  std::uint64_t ready_since_us = 0;  // driving while the fault is failing since (0: not)
  const hal::sim::BaseParams& bp = sim.params().base;
  const double decel =
      static_cast<double>(expected.coasts ? bp.coast_decel_m_s2 : bp.brake_decel_m_s2);
  // By then the wheels must be at rest (the stop due, then v/a, then a frame for rounding).
  const auto rest_due_us = [&](std::uint64_t since_us) {
    return since_us + allowed_us + static_cast<std::uint64_t>(onset_speed / decel * 1e6) + 10000U;
  };
  if (config.loop_started != nullptr) config.loop_started(config.context);
  while (hal.clock.now_us() < stop_us) {
    rig.runtime.executive.run_frame();
    ++out.frames;
    const std::uint64_t now = hal.clock.now_us();
    const bool at_rest = wheels_at_rest(sim);
    if (now < onset_us) {
      out.moving_before = !at_rest;
      onset_speed = static_cast<double>(sim.wheel_speed_m_s());
      onset_travel = sim.rim_travel_m();
      continue;
    }
    if (now < end_us) {
      if (!rig.runtime.executive.all_healthy() || !rig.runtime.console->storage_healthy()) {
        out.unhealthy_during = true;
      }
      // When the device began to misbehave: the onset, or for an intermittent fault the
      // start of its failing slot (slots are whole frames).
      hal::sim::FaultType active = type;
      const bool failing = sim.faults().failing(device, active);
      if (failing && failing_since_us == 0) {
        const std::uint64_t slot =
            (now / hal::sim::FaultInjector::kSlotUs) * hal::sim::FaultInjector::kSlotUs;
        failing_since_us = type == FaultType::kIntermittent && slot > onset_us ? slot : onset_us;
        if (!stopped_seen && failing_since_us > onset_us) {
          onset_speed = static_cast<double>(sim.wheel_speed_m_s());
          onset_travel = sim.rim_travel_m();
        }
      } else if (!failing) {
        failing_since_us = 0;
      }
      // The stop: commanded (the base no longer drives), then the wheels at rest.
      if (!stopped_seen && failing_since_us != 0 && sim.last_base_stop_us() >= failing_since_us) {
        stopped_seen = true;
        stop_since_us = failing_since_us;
        out.stop_latency_ms =
            static_cast<double>(sim.last_base_stop_us() - failing_since_us) * 1e-3;
        out.onset_wheel_speed_m_s = onset_speed;
        out.stop_distance_bound_m = onset_speed * onset_speed / (2.0 * decel) +
                                    onset_speed * static_cast<double>(allowed_us) * 1e-6 + 1e-4;
      }
      if (stopped_seen && out.stop_time_ms < 0.0 && at_rest &&
          sim.last_base_rest_us() >= sim.last_base_stop_us()) {
        out.stop_time_ms = static_cast<double>(sim.last_base_rest_us() - stop_since_us) * 1e-3;
        out.stop_distance_m = sim.rim_travel_at_rest_m() - onset_travel;
      }
      // While the device misbehaves (after one frame's grace) the base must not drive, and
      // the wheels must be at rest once they could be; a fault the base is restarted into
      // must stop it again within the time to see it each time.
      const bool ready = sim.base_health() == hal::BaseHealth::kReady;
      if (!failing || !ready) {
        ready_since_us = 0;
      } else if (ready_since_us == 0) {
        ready_since_us = now;
      }
      if (expected.restarts_into_it) {
        // (From the restart: the setpoint comes a frame later, the check starts a frame after.)
        if (ready_since_us != 0 && now - ready_since_us > allowed_us + 20000U) broke_stop = true;
      } else if (failing && failing_since_us != 0 && now - failing_since_us > allowed_us &&
                 (ready || (!at_rest && now > rest_due_us(failing_since_us)))) {
        broke_stop = true;
      }
      if (!asked_mid && now >= mid_us) {
        asked_mid = true;
        rig.port.feed("status\rstats\rfault\r");
      }
      frames_at_end = rig.stand_in.frames();
      moves_at_end = rig.stand_in.ptu_moves();
      continue;
    }
    if (!stopped_seen && sim.last_base_stop_us() >= onset_us && sim.last_base_stop_us() < end_us) {
      // Stopped while no frame of the firmware ran (the main loop's stall): by the ODrives'
      // own watchdog, and at rest when the firmware runs again.
      stopped_seen = true;
      out.stop_latency_ms = static_cast<double>(sim.last_base_stop_us() - onset_us) * 1e-3;
      out.onset_wheel_speed_m_s = onset_speed;
      out.stop_distance_bound_m = onset_speed * onset_speed / (2.0 * decel) +
                                  onset_speed * static_cast<double>(allowed_us) * 1e-6 + 1e-4;
      if (at_rest && sim.last_base_rest_us() >= sim.last_base_stop_us()) {
        out.stop_time_ms = static_cast<double>(sim.last_base_rest_us() - onset_us) * 1e-3;
        out.stop_distance_m = sim.rim_travel_at_rest_m() - onset_travel;
      }
      broke_stop = !at_rest;
    }
    if (!after_seen) {
      after_seen = true;
      frames_at_end = rig.stand_in.frames();
      moves_at_end = rig.stand_in.ptu_moves();
    }
    moved_after_end = moved_after_end || !at_rest;
  }
  if (expected.operator_reset) {
    // The operator, once the line has been back for after_s: `clear-estop`, and 0.5 s later
    // `resume`. The base must not move before the resume.
    out.held_until_reset = !moved_after_end;
    const auto run_for = [&](std::uint64_t us) {
      bool moved = false;
      const std::uint64_t until = hal.clock.now_us() + us;
      while (hal.clock.now_us() < until) {
        rig.runtime.executive.run_frame();
        ++out.frames;
        moved = moved || !wheels_at_rest(sim);
      }
      return moved;
    };
    rig.port.feed("clear-estop\r");
    out.held_until_resume = !run_for(kResetToResumeUs);
    rig.port.feed("resume\r");
    (void)run_for(kResetToResumeUs);
  }
  rig.port.feed("status\r");
  rig.runtime.executive.run_frame();
  rig.runtime.executive.run_frame();
  if (config.loop_ended != nullptr) config.loop_ended(config.context);
  out.stayed_stopped = stopped_seen && !broke_stop;
  out.moving_after = !wheels_at_rest(sim);
  out.healthy_after = rig.runtime.executive.all_healthy() && rig.runtime.console->storage_healthy();
  out.camera_frames_during = frames_at_end;
  out.camera_frames_after = rig.stand_in.frames() - frames_at_end;
  out.ptu_moves_after = rig.stand_in.ptu_moves() - moves_at_end;
  out.worst_frame_lag_ms = rig.stand_in.worst_lag_ms();
  out.frame_overruns = rig.runtime.executive.frame_stats().overruns;
  out.missed_frames = rig.runtime.executive.frame_stats().missed_frames;
  out.watchdog_expirations = sim.watchdog_expirations();
  out.collisions = sim.collisions();
  if (config.state_dir != nullptr) {
    out.saves = rig.runtime.saver.saved();
    out.save_failures = rig.runtime.saver.failures();
    char error[256] = "";
    const fw::LoadResult loaded = g_store.load(g_loaded, error, sizeof error);
    out.state_loadable =
        loaded == fw::LoadResult::kLoaded || (loaded == fw::LoadResult::kMissing && out.saves == 0);
    out.state_current =
        out.saves == 0 || (loaded == fw::LoadResult::kLoaded && g_loaded == rig.state);
  }
  const std::string_view text = rig.port.written();
  const std::size_t n = text.size() < out.console.size() - 1 ? text.size() : out.console.size() - 1;
  std::memcpy(out.console.data(), text.data(), n);
  out.console[n] = '\0';
  out.says_expected = contains(text, expected.console_says);
  // The verdict, on everything the expectation names.
  bool ok = out.collisions == 0 && out.state_loadable && out.state_current && out.says_expected;
  if (expected.stops_base) {
    ok = ok && out.moving_before && out.stayed_stopped && out.stop_latency_ms >= 0.0 &&
         out.stop_latency_ms * 1e3 <= static_cast<double>(allowed_us) && out.stop_time_ms >= 0.0 &&
         out.stop_distance_m <= out.stop_distance_bound_m;
  } else {
    // Nothing made a stop necessary (a fault from the start has no "before").
    ok = ok && (out.moving_before || expected.at_start) && !stopped_seen;
  }
  if (expected.operator_reset) ok = ok && out.held_until_reset && out.held_until_resume;
  if (expected.recovers) {
    ok = ok && out.healthy_after && out.moving_after;
  } else {
    ok = ok && !out.moving_after;
  }
  out.passed = ok;
  out.ran = true;
  g_rig.reset();
  return true;
}

bool run_fault_soak(SimBoard& board, const hal::sim::FaultPlan& plan, double run_s,
                    const FaultScenarioConfig& config, FaultSoakResult& out) {
  out = FaultSoakResult{};
  board.default_faults() = plan;
  if (!start_rig(board, config, true, out.error, sizeof out.error)) return false;
  Rig& rig = *g_rig;
  hal::Hal& hal = board.hal();
  hal::sim::SimWorld& sim = board.sim();
  const hal::sim::FaultInjector& faults = sim.faults();
  const auto end_us = static_cast<std::uint64_t>(std::llround(run_s * 1e6));
  constexpr std::uint64_t kSettleUs = 1500000;
  std::uint32_t ended_seen = 0;
  std::uint64_t check_at_us = 0;  // a quiet check is due then (0: none)
  std::uint64_t must_rest_since_us = 0;
  std::uint64_t rest_due_us = 0;
  const float brake_decel = sim.params().base.brake_decel_m_s2;
  const float coast_decel = sim.params().base.coast_decel_m_s2;
  bool coast_allowed = false;  // the axes were idled by a fault: the wheels can only coast
  // The operator: after a stop line was active, the wheels stay at rest until they have typed
  // `clear-estop` and `resume`, which they do kOperatorUs after the line's last fault ended.
  constexpr std::uint64_t kOperatorUs = 500000;
  bool reset_due = false;
  std::uint64_t reset_at_us = 0;
  // A fault that is not ridden out was active since the last quiet check: the check may wait
  // for the retries (until recover_until_us once it found something not yet back).
  bool retried_since_check = false;
  std::uint64_t recover_until_us = 0;
  if (config.loop_started != nullptr) config.loop_started(config.context);
  while (hal.clock.now_us() < end_us) {
    rig.runtime.executive.run_frame();
    ++out.frames;
    const std::uint64_t now = hal.clock.now_us();
    bool any_active = false;
    bool line_active = false;
    bool line_fault = false;
    for (std::size_t d = 0; d < hal::sim::kFaultDeviceCount; ++d) {
      FaultType type = FaultType::kOff;
      const auto device = static_cast<FaultDevice>(d);
      const bool active = faults.active(device, type);
      if (active) any_active = true;
      if (active && !hal::sim::fault_rides_out(device, type)) retried_since_check = true;
      if (device == FaultDevice::kEstop || device == FaultDevice::kBumper) {
        line_fault = line_fault || active;
        if (faults.failing(device, type)) line_active = true;
      }
    }
    if (line_active) reset_due = true;
    // The e-stop or bumper line active, or not yet reset and resumed by the operator: the
    // wheels at rest after one frame's grace.
    if (line_active || reset_due) {
      if (must_rest_since_us == 0) {
        must_rest_since_us = now;
        coast_allowed = false;
        // Braked from this speed: at rest v/a later (and a frame for the stop, one for rounding).
        rest_due_us = now + 20000U +
                      static_cast<std::uint64_t>(static_cast<double>(sim.wheel_speed_m_s()) /
                                                 static_cast<double>(brake_decel) * 1e6);
      }
      // A fault of another device (an axis, the bus, the ODrives' watchdog) idled the axes: no
      // closed loop is left to brake with and the wheels coast, from the speed they have then.
      if (!coast_allowed && sim.base_axes_idle() && !sim.base_braking() && !wheels_at_rest(sim)) {
        FaultType t = FaultType::kOff;
        bool base_fault = false;
        for (const FaultDevice d : {FaultDevice::kAxisLeft, FaultDevice::kAxisRight,
                                    FaultDevice::kCan, FaultDevice::kMainLoop}) {
          base_fault = base_fault || faults.active(d, t);
        }
        if (base_fault) {
          coast_allowed = true;
          const std::uint64_t coast_due_us =
              now + 20000U +
              static_cast<std::uint64_t>(static_cast<double>(sim.wheel_speed_m_s()) /
                                         static_cast<double>(coast_decel) * 1e6);
          if (coast_due_us > rest_due_us) rest_due_us = coast_due_us;
        }
      }
      // Not driving after a frame's grace, and at rest once braked.
      if ((now - must_rest_since_us > 10000U && sim.base_health() == hal::BaseHealth::kReady) ||
          (now > rest_due_us && !wheels_at_rest(sim))) {
        if (out.stop_violations == 0) {
          fw::TextBuffer<200> what;
          what.appendf(
              "t_s=%.2f since_s=%.2f ready=%d speed=%.3f faults:", static_cast<double>(now) * 1e-6,
              static_cast<double>(must_rest_since_us) * 1e-6,
              sim.base_health() == hal::BaseHealth::kReady ? 1 : 0,
              static_cast<double>(sim.wheel_speed_m_s()));
          for (std::size_t d = 0; d < hal::sim::kFaultDeviceCount; ++d) {
            FaultType t = FaultType::kOff;
            if (faults.active(static_cast<FaultDevice>(d), t)) {
              what.appendf(" %s %s", hal::sim::fault_device_name(static_cast<FaultDevice>(d)),
                           hal::sim::fault_type_name(t));
            }
          }
          std::snprintf(out.first_stop_violation, sizeof out.first_stop_violation, "%s",
                        what.c_str());
        }
        ++out.stop_violations;
      }
    } else {
      must_rest_since_us = 0;
    }
    if (reset_due && !line_fault) {
      if (reset_at_us == 0) {
        reset_at_us = now + kOperatorUs;
      } else if (now >= reset_at_us) {
        rig.port.feed("clear-estop\rresume\r");
        ++out.operator_resets;
        reset_due = false;
        reset_at_us = 0;
      }
    } else {
      reset_at_us = 0;
    }
    if (faults.ended() != ended_seen) {
      ended_seen = faults.ended();
      check_at_us = now + kSettleUs;
      recover_until_us = 0;
    }
    if (any_active) {
      if (check_at_us != 0 && now >= check_at_us) check_at_us = now + kSettleUs;  // wait on
      recover_until_us = 0;
      continue;
    }
    if (check_at_us == 0 || now < check_at_us) continue;
    const bool healthy =
        rig.runtime.executive.all_healthy() && rig.runtime.console->storage_healthy();
    const bool moving = !wheels_at_rest(sim);
    if (!(healthy && moving) && retried_since_check) {
      if (recover_until_us == 0) recover_until_us = now + kSoakRecoverUs;
      if (now < recover_until_us) continue;  // the retries have not had their time yet
    }
    if (healthy && moving && now > check_at_us) {
      const double waited_s = static_cast<double>(now - check_at_us) * 1e-6;
      if (waited_s > out.worst_recovery_s) out.worst_recovery_s = waited_s;
    }
    check_at_us = 0;
    recover_until_us = 0;
    retried_since_check = false;
    ++out.quiet_checks;
    bool loads = true;
    bool current = true;
    if (config.state_dir != nullptr && rig.runtime.saver.saved() > 0) {
      char error[256] = "";
      loads = g_store.load(g_loaded, error, sizeof error) == fw::LoadResult::kLoaded;
      if (!loads) ++out.state_loads_failed;
      // Nothing lost: the newest copy is the last state submitted (every save since the
      // fault ended went through).
      current = loads && g_loaded == rig.state;
      if (loads && !current) ++out.state_not_current;
      if (current && out.quiet_checks % kCorruptEvery == 0) {
        // A damaged newest copy: the other one, the previous submission, must load.
        ++out.corruptions;
        if (flip_middle_byte(g_store.loaded_path()) &&
            g_store.load(g_loaded, error, sizeof error) == fw::LoadResult::kLoaded &&
            g_store.load_warning()[0] != '\0' && g_loaded.cycle + 1 == rig.state.cycle) {
          ++out.corruptions_recovered;
        }
      }
    }
    if (healthy && moving && loads && current) {
      ++out.ended_safe;
    } else {
      if (out.ended_unsafe == 0) {
        fw::TextBuffer<200> what;
        what.appendf("t_s=%.1f moving=%d state_loads=%d state_current=%d storage=%d",
                     static_cast<double>(now) * 1e-6, moving ? 1 : 0, loads ? 1 : 0,
                     current ? 1 : 0, rig.runtime.console->storage_healthy() ? 1 : 0);
        for (std::size_t i = 0; i < rig.runtime.executive.task_count(); ++i) {
          if (const char* why = rig.runtime.executive.task_health(i); why != nullptr) {
            what.appendf(" %s: %s", rig.runtime.executive.spec(i).name, why);
          }
        }
        std::snprintf(out.first_unsafe, sizeof out.first_unsafe, "%s", what.c_str());
      }
      ++out.ended_unsafe;
    }
  }
  if (config.loop_ended != nullptr) config.loop_ended(config.context);
  out.sim_s = static_cast<double>(hal.clock.now_us()) * 1e-6;
  out.faults_started = faults.started();
  out.faults_ended = faults.ended();
  out.collisions = sim.collisions();
  out.saves = rig.runtime.saver.saved();
  out.save_failures = rig.runtime.saver.failures();
  const fw::FrameStats& f = rig.runtime.executive.frame_stats();
  out.frame_overruns = f.overruns;
  out.missed_frames = f.missed_frames;
  out.worst_jitter_us = f.jitter_worst_us;
  for (std::size_t i = 0; i < rig.runtime.executive.task_count(); ++i) {
    const std::uint32_t w = rig.runtime.executive.task_stats(i).worst_us;
    if (w > out.worst_task_us) out.worst_task_us = w;
  }
  out.console_dropped_bytes = rig.runtime.console->dropped_bytes();
  out.watchdog_expirations = sim.watchdog_expirations();
  out.ran = true;
  g_rig.reset();
  return true;
}

}  // namespace boticelli::boards::sim
