// Safety: the e-stop latch — button, bumper or console stop the base at once and keep it stopped
// until cleared.
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
  // stops the base when the latch is engaged and the base is not yet stopped.
  void poll();
  // Engages the latch and stops the base now (console `estop`).
  void engage(StopCause cause);
  // Releases the latch and resumes the base; nullptr on success, else why not (an input
  // still active, the base refusing). Nothing changes on failure.
  const char* clear();

  bool engaged() const { return cause_ != StopCause::kNone; }
  StopCause cause() const { return cause_; }
  std::uint64_t engagements() const { return engagements_; }
  // Bumper contacts seen (each transition to contact counts once): the run's collisions.
  std::uint64_t collisions() const { return collisions_; }

 private:
  hal::DigitalIn& estop_;
  hal::DigitalIn& bumper_;
  hal::Base& base_;
  StopCause cause_ = StopCause::kNone;
  std::uint64_t engagements_ = 0;
  std::uint64_t collisions_ = 0;
  bool bumper_was_active_ = false;
};

}  // namespace boticelli::firmware
