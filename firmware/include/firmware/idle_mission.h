// IdleMission: what runs in the mission's place until the Look-Think-Drive mission lands — a
// checkpoint cycle.
#pragma once

#include <cstdint>

#include "firmware/executive.h"
#include "firmware/mission_state.h"
#include "firmware/mission_view.h"
#include "firmware/state_saver.h"
#include "hal/base.h"
#include "hal/clock.h"
#include "hal/pan_tilt.h"

namespace boticelli::firmware {

// A "cycle" here is one checkpoint period of board time (simulated time on the sim board):
// the background slot records the odometry pose and a mission-log line in the state and,
// with --state, hands it to the StateSaver (saved atomically by its writer thread). It never moves
// the robot. The mission replaces this class with the same two interfaces (MissionView for the
// console, BackgroundWork for the executive).
class IdleMission final : public MissionView, public BackgroundWork {
 public:
  IdleMission(hal::Base& base, hal::PanTilt& ptu, hal::Clock& clock, MissionState& state,
              StateSaver* saver, std::uint32_t cycle_period_us)
      : base_(base),
        ptu_(ptu),
        clock_(clock),
        state_(state),
        saver_(saver),
        period_us_(cycle_period_us) {}

  // Anchors the first cycle one period after now.
  void start(std::uint64_t now_us) { next_cycle_us_ = now_us + period_us_; }
  StepResult step(SliceBudget& budget) override;

  const char* state_name() const override { return "idle"; }
  core::Pose2 pose() const override;
  float pan_rad() const override { return ptu_.state().pan_rad; }
  std::uint64_t cycles() const override { return state_.cycle; }
  std::string_view model_text() const override { return state_.model_text(); }
  MapCounts map_counts() const override;

  std::uint64_t cycles_this_run() const { return cycles_this_run_; }
  // Shutdown: hands over a state still waiting for the writer and waits until it is saved.
  void finish_saving();

 private:
  hal::Base& base_;
  hal::PanTilt& ptu_;
  hal::Clock& clock_;
  MissionState& state_;
  StateSaver* saver_;
  std::uint32_t period_us_;
  std::uint64_t next_cycle_us_ = 0;
  std::uint64_t cycles_this_run_ = 0;
  bool submit_pending_ = false;  // the last cycle's state still waits for the writer
};

}  // namespace boticelli::firmware
