// IdleMission: the checkpoint cycle that stands in for the mission (see idle_mission.h).
#include "firmware/idle_mission.h"

#include <cstdio>

#include "firmware/text_buffer.h"

namespace boticelli::firmware {

core::Pose2 IdleMission::pose() const {
  const hal::Odometry o = base_.odometry();
  return {static_cast<float>(o.x_m), static_cast<float>(o.y_m), static_cast<float>(o.yaw_rad)};
}

MapCounts IdleMission::map_counts() const {
  MapCounts m;
  m.obstacle_points = static_cast<std::uint32_t>(state_.obstacles.size());
  m.exploration_points = static_cast<std::uint32_t>(state_.exploration.size());
  return m;
}

StepResult IdleMission::step(SliceBudget& budget) {
  if (submit_pending_ && saver_->submit(state_)) submit_pending_ = false;
  if (clock_.now_us() < next_cycle_us_ || !budget.next_unit()) return StepResult::kMore;
  next_cycle_us_ += period_us_;
  ++state_.cycle;
  ++cycles_this_run_;
  state_.pose = pose();
  TextBuffer<MissionLogEntry::kMaxTextBytes + 1> line;
  line.appendf("idle checkpoint x_m=%.3f y_m=%.3f yaw_rad=%.3f",
               static_cast<double>(state_.pose.x_m), static_cast<double>(state_.pose.y_m),
               static_cast<double>(state_.pose.yaw_rad));
  state_.add_log(state_.cycle, line.view());
  if (saver_ != nullptr) submit_pending_ = !saver_->submit(state_);
  return StepResult::kDone;
}

void IdleMission::finish_saving() {
  if (saver_ == nullptr) return;
  while (submit_pending_) submit_pending_ = !saver_->submit(state_);
  saver_->flush();
}

}  // namespace boticelli::firmware
