// FaultScenario: one injected (device, fault type) pair on the sim board with the firmware's
// device tasks, e-stop latch, console and state saver running around a stand-in for the
// mission that keeps the base turning and the PTU scanning — what the firmware does within
// each frame of the fault, measured. Tests assert on it; boticelli-bench's `faults` suite
// writes docs/reliability.md's table from it.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>

#include "hal/sim/fault_plan.h"

namespace boticelli::boards::sim {

class SimBoard;

// What the firmware is expected to do about a pair (docs/reliability.md, "Expected").
struct FaultExpectation {
  // Motion safety in doubt: the base is stopped within one 10 ms frame of the fault's onset
  // and stays stopped while it lasts (the main loop's stall: within the ODrives' 0.2 s
  // watchdog, as nothing of the firmware runs).
  bool stops_base = false;
  // Console text naming the device and why (a LOG line, or the reply to `status`).
  const char* console_says = "";
  // After the fault: every task and the storage healthy again, the stand-in moving again (a
  // base that stopped by itself restarted by the base task's retry). False where the
  // firmware does not restart on its own (the bumper: the mission ends aborted for good).
  bool recovers = true;
  // What the whole mission does with the fault for kMissionFaultS in its first look (the
  // bench's mission column), and whether it then ends aborted (else it carries on: device
  // faults are held and retried, docs/reliability.md "Fault policy").
  const char* mission = "";
  bool mission_aborts = false;
  // Latched (the e-stop): after the fault the stand-in stays stopped until the operator's
  // `clear-estop` (typed after_s after the fault's end), and still after it until `resume`
  // (kResetToResumeUs later); `recovers` then speaks of kResetToResumeUs after the resume. The
  // whole mission likewise waits for both (the bench types them, kMissionResetAfterS after the
  // fault's end).
  bool operator_reset = false;
  // The whole mission holds for the device and carries on when it is back: its log says
  // `held: ...` and `devices back after ...` (the fault policy).
  bool mission_holds = false;
  // How the base stops (with stops_base): the axes idled, the wheels coasting at
  // BaseParams::coast_decel_m_s2 (the fault leaves no closed loop to brake with), else braked
  // in closed loop at brake_decel_m_s2.
  bool coasts = false;
  // Time the firmware needs to see the fault at all before it can stop (the driver's 1 s
  // check of a wheel against its setpoint) [µs]; the stop is due within a frame after it.
  std::uint32_t detect_us = 0;
  // The fault cannot be seen while the base stands (a jammed wheel, a frozen encoder): the
  // base task's retry restarts it into the fault, and each time it must stop again within
  // detect_us (instead of staying stopped).
  bool restarts_into_it = false;
  // A fault a start meets (the watchdog device busy when it is opened): injected from the
  // board's start instead of fault_start_s; the base is to keep moving through it.
  bool at_start = false;
};
inline constexpr std::uint64_t kResetToResumeUs = 500000;
// The fault in the whole-mission runs: from 5 s for 5 s of simulated time (longer than the
// mission's 3 s frame timeout, shorter than its 8 s PTU move timeout).
inline constexpr double kMissionFaultStartS = 5.0;
inline constexpr double kMissionFaultS = 5.0;
inline constexpr double kMissionResetAfterS = 2.0;
const FaultExpectation& expectation(hal::sim::FaultDevice device, hal::sim::FaultType type);

struct FaultScenarioConfig {
  const char* world_file = nullptr;  // the world (thesis room when nullptr)
  const char* state_dir = nullptr;   // state saves every second into this directory (or none)
  std::uint64_t seed = 1;
  double fault_start_s = 1.0;  // after the base is ready and turning
  double fault_s = 3.0;        // the fault's duration (health reports need 2 s of stall)
  double after_s = 1.5;        // watched after it ended
  float camera_fps = 10.0F;
  // Called once everything is set up and before the first frame, and after the last frame
  // (tests count allocations in between).
  void (*loop_started)(void* context) = nullptr;
  void (*loop_ended)(void* context) = nullptr;
  void* context = nullptr;
};

struct FaultScenarioResult {
  bool ran = false;
  char error[256] = "";
  std::uint64_t frames = 0;
  // The base: moving just before the onset, and how long after it the wheels were at rest
  // (-1: not within the fault), and whether they stayed at rest until it ended.
  bool moving_before = false;
  double stop_latency_ms = -1.0;  // until the base stopped commanding motion
  // From the fault's onset until the wheels were at rest: the ground the faster wheel
  // covered (true, from the simulator) [m] and the time [ms] (-1: not at rest within the
  // fault), and the bound it is held to: v²/2a at the onset's wheel speed v and the
  // deceleration a of the stop (braked or coasting), plus the travel until the stop was due
  // (one frame; the ODrives' 0.2 s watchdog for a stalled main loop) [m].
  double stop_distance_m = -1.0;
  double stop_time_ms = -1.0;
  double stop_distance_bound_m = 0.0;
  double onset_wheel_speed_m_s = 0.0;
  bool stayed_stopped = false;
  bool moving_after = false;  // turning again by the end of the run
  // With an operator reset: at rest from the fault's end until `clear-estop`, and from
  // `clear-estop` until `resume`.
  bool held_until_reset = false;
  bool held_until_resume = false;
  // The console: the LOG lines of the run (truncated to the buffer), health afterwards.
  std::array<char, 16384> console{};
  bool says_expected = false;  // console_says appeared
  bool unhealthy_during = false;
  bool healthy_after = false;
  // The rest of the firmware's state at the end.
  std::uint64_t camera_frames_during = 0;  // frames the stand-in took while the fault lasted
  std::uint64_t camera_frames_after = 0;
  double worst_frame_lag_ms = 0.0;  // frame age when taken
  std::uint64_t ptu_moves_after = 0;
  std::uint64_t frame_overruns = 0;
  std::uint64_t missed_frames = 0;
  std::uint32_t watchdog_expirations = 0;
  std::uint32_t collisions = 0;  // the simulator's own, from the world
  std::uint64_t saves = 0;
  std::uint64_t save_failures = 0;
  bool state_loadable = true;  // the state file loads at the end (when there is one)
  // ... and holds the last state the stand-in submitted (nothing lost once saves work again).
  bool state_current = true;
  // Met the expectation in every respect it names.
  bool passed = false;
};

// A long run under a plan of many faults (generate_fault_plan): the same rig, judged after
// each fault has ended and nothing else is active for 1.5 s. An operator resets the e-stop
// latch after each e-stop fault.
struct FaultSoakResult {
  bool ran = false;
  char error[256] = "";
  double sim_s = 0.0;
  std::uint64_t frames = 0;
  std::uint32_t faults_started = 0;
  std::uint32_t faults_ended = 0;
  std::uint32_t quiet_checks = 0;  // moments with no fault active, 1.5 s after one ended
  // After a fault that is not ridden out (hal::sim::fault_rides_out: a device held and
  // retried, the base restarted) a check that finds something not yet healthy or moving
  // waits for the retries, up to kSoakRecoverUs, and passes once they have worked; the
  // longest such wait [s] (0 when every check passed at once).
  double worst_recovery_s = 0.0;
  std::uint32_t ended_safe = 0;    // ... where everything was healthy and moving again
  std::uint32_t ended_unsafe = 0;  // ... where something was not
  char first_unsafe[200] = "";     // what, the first time
  // Frames moving while the e-stop or bumper line was active, or after it before the operator's
  // reset (`clear-estop` and `resume`, typed 0.5 s after the line's fault ended).
  std::uint64_t stop_violations = 0;
  char first_stop_violation[200] = "";  // when, and the faults then active, the first time
  std::uint32_t operator_resets = 0;
  std::uint32_t collisions = 0;
  std::uint64_t saves = 0;
  std::uint64_t save_failures = 0;
  std::uint32_t state_loads_failed = 0;  // the state file did not load at a quiet check
  // The state file loaded at a quiet check but did not hold the last submitted state.
  std::uint32_t state_not_current = 0;
  // Every kCorruptEvery-th quiet check flips a byte in the newest copy: the store must then
  // load the other copy (the previous submission, with a warning), and the next save
  // replaces the damaged one (the next quiet check finds the newest state again).
  std::uint32_t corruptions = 0;
  std::uint32_t corruptions_recovered = 0;
  std::uint64_t frame_overruns = 0;
  std::uint64_t missed_frames = 0;
  std::uint32_t worst_jitter_us = 0;
  std::uint32_t worst_task_us = 0;
  std::uint64_t console_dropped_bytes = 0;
  std::uint32_t watchdog_expirations = 0;
};
inline constexpr std::uint32_t kCorruptEvery = 8;
// The base task's retry backs off to 8 s after quick re-stops; a check waits that and 2 s.
inline constexpr std::uint64_t kSoakRecoverUs = 10000000;
bool run_fault_soak(SimBoard& board, const hal::sim::FaultPlan& plan, double run_s,
                    const FaultScenarioConfig& config, FaultSoakResult& out);

// Runs one pair on `board` (init()ed here with the config's world and seed). Allocates only
// before loop_started.
bool run_fault_scenario(SimBoard& board, hal::sim::FaultDevice device, hal::sim::FaultType type,
                        const FaultScenarioConfig& config, FaultScenarioResult& out);

}  // namespace boticelli::boards::sim
