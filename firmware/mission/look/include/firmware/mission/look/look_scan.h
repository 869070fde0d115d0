// LookScan: the look's PTU scan (thesis §6.2.1): move, settle, grab each view's frame or
// stereo pair, and hand the view to the background; the mission task drives it every frame.
#pragma once

#include <cstddef>
#include <cstdint>

#include <Eigen/Core>

#include "algo/image/low_res_frame.h"
#include "algo/stereo/stereo_processor.h"
#include "firmware/mission/params/mission_params.h"
#include "hal/camera.h"
#include "hal/pan_tilt.h"

namespace boticelli::firmware::mission {

// What one frame of the scan came to.
enum class ScanEvent : std::uint8_t {
  kBusy,        // moving, settling, grabbing, or waiting for the background to take a view
  kDone,        // every view processed; the camera parked level
  kPtuFault,    // the PTU reports a fault
  kPtuRefused,  // the PTU refused a move
  kPtuTimeout,  // a move did not complete within ptu_timeout_us
  kNoFrame,     // no usable frame within frame_timeout_us
};

// A stereo pair aimed at the target after the scan (its pan and the pair's first tilt) [rad].
struct AimedPair {
  bool aimed = false;
  float pan_rad = 0.0F;
  float tilt_rad = 0.0F;
};

// The pair aimed at a target at `target_m` (robot frame, its height above the floor) from a
// PTU at `ptu_height_m`: its pan, and a first tilt that puts the target midway between the
// pair's two tilts (tilt_step_rad apart), held so that both stay within `limits` (the first at
// least tilt_min + Φ, as the second is Φ below it). Not aimed beyond max_range_m or outside
// the pan range.
[[nodiscard]] AimedPair aim_pair_at(const Eigen::Vector3f& target_m, float ptu_height_m,
                                    float tilt_step_rad, float max_range_m,
                                    const hal::PanTiltLimits& limits);

// Where the PTU goes first to reach a stereo pair's first tilt `to_rad` from `from_rad` moving
// down, so that its gear play is taken up as for the pair's second frame: `to_rad` itself when
// the move already goes down, else at least `approach_rad` above it within `max_rad` (the
// tilt limit; a view at the limit is reached as it can be).
[[nodiscard]] float tilt_approach_rad(float from_rad, float to_rad, float approach_rad,
                                      float max_rad);

// The view the background processes: both frames, where the PTU stood for each, whether it is
// a pair, and its number in the look (the aimed pair comes after the scan's views).
struct GrabbedView {
  const image::LowResFrame& first;
  const image::LowResFrame& second;
  stereo::PairPose pose;
  bool pair;
  std::size_t index;
  bool aimed;
};

class LookScan {
 public:
  explicit LookScan(const MissionParams& params) : params_(params) {}
  LookScan(const LookScan&) = delete;
  LookScan& operator=(const LookScan&) = delete;

  // A new look from its first view; the aimed pair, if any, comes last. `only_aimed` (with an
  // aimed pair): the aimed pair alone, a glance to check that the target is there.
  void begin(std::uint64_t now_us, const AimedPair& aimed, bool only_aimed = false);
  // The mission task's part of the look, every frame.
  ScanEvent control(std::uint64_t now_us, hal::PanTilt& ptu);
  // The camera task: keeps a settled frame when a view wants one.
  void on_frame(const hal::Frame& frame);
  [[nodiscard]] bool wants_frames() const { return want_frame_; }
  // No more frames wanted (the mission is held or ended).
  void stop_frames() { want_frame_ = false; }
  // Frames taken so far (each one means the PTU reached its view and the camera delivered).
  [[nodiscard]] std::uint64_t frames_grabbed() const { return frames_grabbed_; }
  // After a hold: an interrupted move is issued again and waited for.
  void resume();

  // The background's side: a view is ready until view_processed().
  [[nodiscard]] bool view_ready() const { return view_ready_; }
  [[nodiscard]] GrabbedView view() const {
    return {first_, second_, pair_pose_, view_pair_, view_, view_ >= scan_views()};
  }
  void view_processed() { view_ready_ = false; }

  // The scan's views (pans × rows), then the aimed pair when there is one.
  [[nodiscard]] std::size_t scan_views() const { return params_.pan_positions * params_.row_count; }
  [[nodiscard]] std::size_t view_count() const { return scan_views() + (aimed_.aimed ? 1U : 0U); }

 private:
  // kApproach: the PTU goes above a pair's first tilt first (MissionParams::ptu_approach_rad).
  enum class Step : std::uint8_t { kMove, kApproach, kSettle, kGrab, kProcess };
  void view_angles(const hal::PanTiltLimits& limits);

  const MissionParams& params_;
  AimedPair aimed_{};
  std::size_t view_ = 0;
  Step step_ = Step::kMove;
  bool second_frame_ = false;  // grabbing the pair's second frame
  bool approached_ = false;    // the pair's first tilt is approached from above (or need not be)
  float view_pan_rad_ = 0.0F;
  float view_tilt_rad_ = 0.0F;
  bool view_pair_ = false;
  stereo::PairPose pair_pose_{};
  std::uint64_t deadline_us_ = 0;
  std::uint64_t settle_until_us_ = 0;
  bool want_frame_ = false;
  bool frame_ready_ = false;
  std::uint64_t frames_grabbed_ = 0;
  bool view_ready_ = false;  // both frames in; the background's turn
  image::LowResFrame first_{};
  image::LowResFrame second_{};
};

}  // namespace boticelli::firmware::mission
