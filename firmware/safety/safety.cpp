// Safety: e-stop latch logic (see safety.h).
#include "firmware/safety/safety.h"

namespace boticelli::firmware {

const char* stop_cause_name(StopCause cause) {
  switch (cause) {
    case StopCause::kNone:
      return "none";
    case StopCause::kButton:
      return "button";
    case StopCause::kBumper:
      return "bumper";
    case StopCause::kConsole:
      return "console";
  }
  return "unknown";
}

void Safety::engage(StopCause cause) {
  if (cause_ == StopCause::kNone) {
    cause_ = cause;
    ++engagements_;
  }
  base_.stop();
}

void Safety::poll() {
  // Evaluate both calls: the edge flag must be consumed even when the level is active.
  const bool button_edge = estop_.activated_since_last_poll();
  const bool button = estop_.read() || button_edge;
  const bool bumper_edge = bumper_.activated_since_last_poll();
  const bool bumper = bumper_.read() || bumper_edge;
  if ((bumper && !bumper_was_active_) || (bumper_edge && bumper_was_active_)) ++collisions_;
  bumper_was_active_ = bumper;
  if (button) {
    engage(StopCause::kButton);
  } else if (bumper) {
    engage(StopCause::kBumper);
  } else if (holds() && base_.health() != hal::BaseHealth::kStopped) {
    base_.stop();  // something resumed the base behind the latch's back
  }
}

const char* Safety::clear() {
  if (estop_.read()) return "e-stop button still pressed";
  if (bumper_.read()) return "bumper still in contact";
  if (!engaged()) return nullptr;
  cause_ = StopCause::kNone;
  awaiting_resume_ = true;  // the base stays stopped: a reset restarts nothing
  return nullptr;
}

const char* Safety::resume() {
  if (engaged()) return "e-stop latched: clear-estop first";
  if (!awaiting_resume_) return nullptr;
  if (!base_.resume()) return "base cannot resume";
  awaiting_resume_ = false;
  return nullptr;
}

const char* awaited_command(const Safety& safety, bool background_paused) {
  if (safety.engaged()) return "clear-estop";
  if (safety.awaiting_resume() || background_paused) return "resume";
  return "none";
}

}  // namespace boticelli::firmware
