// MissionState helpers: model text, bounded mission log, comparison (see mission_state.h).
#include "firmware/state/mission_state.h"

#include <cstring>

namespace boticelli::firmware {

const char* mission_end_name(MissionEnd end) {
  switch (end) {
    case MissionEnd::kRunning:
      return "running";
    case MissionEnd::kFound:
      return "found";
    case MissionEnd::kNotFound:
      return "not_found";
    case MissionEnd::kAborted:
      return "aborted";
  }
  return "running";
}

namespace {
// Copies `text` into `out` (NUL-terminated), cut to fit, bytes outside printable ASCII as '?'.
template <std::size_t N>
void copy_printable(std::string_view text, std::array<char, N>& out) {
  const std::size_t n = text.size() < N - 1 ? text.size() : N - 1;
  for (std::size_t i = 0; i < n; ++i) {
    const char c = text[i];
    out[i] = (c >= 0x20 && c <= 0x7E) ? c : '?';
  }
  out[n] = '\0';
}
}  // namespace

void MissionState::set_end(MissionEnd how, std::string_view why) {
  end = how;
  copy_printable(why, end_reason);
}

bool MissionState::set_model(std::string_view text) {
  if (text.size() > kMaxModelBytes || text.find('\0') != std::string_view::npos) return false;
  std::memcpy(model.data(), text.data(), text.size());
  model_bytes = text.size();
  return true;
}

void MissionState::add_log(std::uint64_t at_cycle, std::string_view text) {
  if (log.full()) {
    for (std::size_t i = 1; i < log.size(); ++i) log[i - 1] = log[i];
    log.pop_back();
    ++log_dropped;
  }
  MissionLogEntry e;
  e.cycle = at_cycle;
  copy_printable(text, e.text);
  (void)log.push_back(e);
}

void MissionState::clear() {
  cycle = 0;
  seed = 1;
  end = MissionEnd::kRunning;
  end_reason[0] = '\0';
  pose = {};
  pose_time_ms = 0;
  wheels_known = false;
  wheel_left_m = wheel_right_m = 0.0;
  stereo_bias_per_m = 0.0F;
  has_goal = false;
  goal = {};
  goal_height_m = 0.0F;
  obstacles.clear();
  exploration.clear();
  grid_cell_m = 0.0F;
  grid.clear();
  model_bytes = 0;
  log.clear();
  log_dropped = 0;
}

namespace {
bool same_points(const core::FixedVectorBase<core::Point2>& a,
                 const core::FixedVectorBase<core::Point2>& b) {
  if (a.size() != b.size()) return false;
  for (std::size_t i = 0; i < a.size(); ++i) {
    if (a[i].x_m != b[i].x_m || a[i].y_m != b[i].y_m) return false;
  }
  return true;
}
}  // namespace

bool operator==(const MissionState& a, const MissionState& b) {
  if (a.end != b.end || a.end_reason_text() != b.end_reason_text()) return false;
  if (a.cycle != b.cycle || a.seed != b.seed || a.pose.x_m != b.pose.x_m ||
      a.pose.y_m != b.pose.y_m || a.pose.yaw_rad != b.pose.yaw_rad ||
      a.pose_time_ms != b.pose_time_ms || a.has_goal != b.has_goal ||
      a.wheels_known != b.wheels_known || a.stereo_bias_per_m != b.stereo_bias_per_m) {
    return false;
  }
  if (a.wheels_known && (a.wheel_left_m != b.wheel_left_m || a.wheel_right_m != b.wheel_right_m)) {
    return false;
  }
  if (a.has_goal && (a.goal.x_m != b.goal.x_m || a.goal.y_m != b.goal.y_m ||
                     a.goal_height_m != b.goal_height_m)) {
    return false;
  }
  if (!same_points(a.obstacles, b.obstacles) || !same_points(a.exploration, b.exploration)) {
    return false;
  }
  if (a.grid_cell_m != b.grid_cell_m || a.grid.size() != b.grid.size()) return false;
  for (std::size_t i = 0; i < a.grid.size(); ++i) {
    if (a.grid[i].tx != b.grid[i].tx || a.grid[i].ty != b.grid[i].ty ||
        a.grid[i].cells != b.grid[i].cells) {
      return false;
    }
  }
  if (a.model_text() != b.model_text() || a.log.size() != b.log.size()) return false;
  for (std::size_t i = 0; i < a.log.size(); ++i) {
    if (a.log[i].cycle != b.log[i].cycle || a.log[i].view() != b.log[i].view()) return false;
  }
  return true;
}

}  // namespace boticelli::firmware
