// Safety: the e-stop latch — button, bumper or console stop the base at once and keep it stopped
// until the operator's two deliberate acts: `clear-estop` (clear(): the reset, only with every
// input released) and then `resume` (resume(): the restart). Nothing else releases it: a
// released button or a bumper that lets go leaves the latch engaged, and the reset alone
// restarts nothing (ISO 13850).
#pragma once

#include <cstdint>

#include "hal/base.h"
#include "hal/digital_io.h"

namespace boticelli::firmware {

enum class StopCause : std::uint8_t { kNone, kButton, kBumper, kConsole };

const char* stop_cause_name(StopCause cause);

class Safety {
 public:
  Safety(hal::DigitalIn& estop, hal::DigitalIn& bumper, hal::Base& base)
      : estop_(estop), bumper_(bumper), base_(base) {}
  Safety(const Safety&) = delete;
  Safety& operator=(const Safety&) = delete;

  // The e-stop task's body, first in every frame: reads the inputs (edges and levels) and
  // stops the base when the latch holds (engaged, or cleared and waiting for resume) and the
  // base is not yet stopped.
  void poll();
  // Engages the latch and stops the base now (console `estop`).
  void engage(StopCause cause);
  // The reset (console `clear-estop`): releases an engaged latch, the base still stopped,
  // until resume(). nullptr on success (also when nothing is engaged), else why not (an
  // input still active). Nothing changes on failure.
  const char* clear();
  // The restart (console `resume`): after a reset, resumes the base. nullptr on success
  // (also when nothing waits for it), else why not (the latch still engaged, the base
  // refusing). Nothing changes on failure.
  const char* resume();

  bool engaged() const { return cause_ != StopCause::kNone; }
  StopCause cause() const { return cause_; }
  // Cleared, the base still stopped until resume().
  bool awaiting_resume() const { return awaiting_resume_; }
  // Motion not allowed: engaged or waiting for resume (what holds the mission).
  bool holds() const { return engaged() || awaiting_resume_; }
  std::uint64_t engagements() const { return engagements_; }
  // Bumper contacts seen (each transition to contact counts once): the run's collisions.
  std::uint64_t collisions() const { return collisions_; }

 private:
  hal::DigitalIn& estop_;
  hal::DigitalIn& bumper_;
  hal::Base& base_;
  StopCause cause_ = StopCause::kNone;
  bool awaiting_resume_ = false;
  std::uint64_t engagements_ = 0;
  std::uint64_t collisions_ = 0;
  bool bumper_was_active_ = false;
};

// What the operator must type before the robot moves again: "clear-estop" while the latch is
// engaged, "resume" after the reset or while the background is paused, else "none" (console
// `status` and telemetry).
const char* awaited_command(const Safety& safety, bool background_paused);

}  // namespace boticelli::firmware
