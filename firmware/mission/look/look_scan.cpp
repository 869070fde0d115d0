// LookScan: the PTU scan of one look (see look_scan.h).
#include "firmware/mission/look/look_scan.h"

#include <algorithm>
#include <cmath>

#include "algo/image/low_res_frame.h"

namespace boticelli::firmware::mission {

AimedPair aim_pair_at(const Eigen::Vector3f& target_m, float ptu_height_m, float tilt_step_rad,
                      float max_range_m, const hal::PanTiltLimits& limits) {
  AimedPair aimed;
  const float d = std::hypot(target_m.x(), target_m.y());
  const float pan = std::atan2(target_m.y(), target_m.x());
  if (d > max_range_m || pan < limits.pan_min_rad || pan > limits.pan_max_rad) return aimed;
  const float elevation = std::atan2(target_m.z() - ptu_height_m, d);
  aimed.pan_rad = pan;
  aimed.tilt_rad = std::clamp(elevation + 0.5F * tilt_step_rad, limits.tilt_min_rad + tilt_step_rad,
                              limits.tilt_max_rad);
  aimed.aimed = true;
  return aimed;
}

float tilt_approach_rad(float from_rad, float to_rad, float approach_rad, float max_rad) {
  if (approach_rad <= 0.0F || from_rad > to_rad) return to_rad;
  return std::max(to_rad, std::min(to_rad + approach_rad, max_rad));
}

void LookScan::begin(std::uint64_t now_us, const AimedPair& aimed, bool only_aimed) {
  aimed_ = aimed;
  view_ = only_aimed && aimed.aimed ? scan_views() : 0;
  second_frame_ = false;
  approached_ = false;
  step_ = Step::kMove;
  view_ready_ = false;
  deadline_us_ = now_us + params_.ptu_timeout_us;
}

void LookScan::resume() {
  if (step_ != Step::kProcess) {
    step_ = Step::kMove;
    approached_ = false;  // the interrupted move may have stopped anywhere
  }
}

void LookScan::view_angles(const hal::PanTiltLimits& limits) {
  if (view_ >= scan_views()) {
    view_pan_rad_ = aimed_.pan_rad;
    view_tilt_rad_ = aimed_.tilt_rad;
    view_pair_ = true;
    return;
  }
  const LookView v = scan_view(params_, limits, view_);
  view_pan_rad_ = v.pan_rad;
  view_tilt_rad_ = v.tilt_rad;
  view_pair_ = v.pair;
}

ScanEvent LookScan::control(std::uint64_t now_us, hal::PanTilt& ptu) {
  const hal::PanTiltState state = ptu.state();
  if (state.fault) return ScanEvent::kPtuFault;
  switch (step_) {
    case Step::kMove: {
      const hal::PanTiltLimits limits = ptu.limits();
      view_angles(limits);
      const float tilt =
          second_frame_ ? view_tilt_rad_ - params_.rig.tilt_step_rad : view_tilt_rad_;
      if (view_pair_ && !second_frame_ && !approached_) {
        approached_ = true;
        const float above =
            tilt_approach_rad(state.tilt_rad, tilt, params_.ptu_approach_rad, limits.tilt_max_rad);
        if (above != tilt) {
          if (!ptu.move_to(view_pan_rad_, above)) return ScanEvent::kPtuRefused;
          deadline_us_ = now_us + params_.ptu_timeout_us;
          step_ = Step::kApproach;
          return ScanEvent::kBusy;
        }
      }
      if (!ptu.move_to(view_pan_rad_, tilt)) return ScanEvent::kPtuRefused;
      deadline_us_ = now_us + params_.ptu_timeout_us;
      step_ = Step::kSettle;
      settle_until_us_ = 0;
      return ScanEvent::kBusy;
    }
    case Step::kApproach:
      if (state.moving) {
        return now_us > deadline_us_ ? ScanEvent::kPtuTimeout : ScanEvent::kBusy;
      }
      step_ = Step::kMove;
      return ScanEvent::kBusy;
    case Step::kSettle:
      if (state.moving) {
        return now_us > deadline_us_ ? ScanEvent::kPtuTimeout : ScanEvent::kBusy;
      }
      if (settle_until_us_ == 0) settle_until_us_ = now_us + params_.settle_us;
      if (now_us < settle_until_us_) return ScanEvent::kBusy;
      frame_ready_ = false;
      want_frame_ = true;
      deadline_us_ = now_us + params_.frame_timeout_us;
      step_ = Step::kGrab;
      return ScanEvent::kBusy;
    case Step::kGrab:
      if (!frame_ready_) return now_us > deadline_us_ ? ScanEvent::kNoFrame : ScanEvent::kBusy;
      want_frame_ = false;
      ++frames_grabbed_;
      if (!second_frame_) {
        pair_pose_.pan_rad = state.pan_rad;
        pair_pose_.first_tilt_rad = state.tilt_rad;
      } else {
        pair_pose_.second_tilt_rad = state.tilt_rad;
      }
      if (view_pair_ && !second_frame_) {
        second_frame_ = true;
        step_ = Step::kMove;
        return ScanEvent::kBusy;
      }
      view_ready_ = true;
      step_ = Step::kProcess;
      return ScanEvent::kBusy;
    case Step::kProcess:
      if (view_ready_) return ScanEvent::kBusy;  // the background has not taken the view yet
      second_frame_ = false;
      approached_ = false;
      if (++view_ < view_count()) {
        step_ = Step::kMove;
        return ScanEvent::kBusy;
      }
      // Look complete: park the camera level.
      (void)ptu.move_to(0.0F, 0.0F);
      return ScanEvent::kDone;
  }
  return ScanEvent::kBusy;
}

void LookScan::on_frame(const hal::Frame& frame) {
  if (!want_frame_ || frame_ready_ || frame.timestamp_us < settle_until_us_) return;
  image::LowResFrame& into = second_frame_ ? second_ : first_;
  if (!image::downsample_yuyv(frame.data, frame.width_px, frame.height_px, frame.stride_bytes,
                              params_.rig.downsample_factor, into)) {
    return;
  }
  frame_ready_ = true;
}

}  // namespace boticelli::firmware::mission
