// LookProcessor: one look's views turned into readings (thesis ch. 3): stereo features, target
// fixes and the floor cue, a unit of work per part of a view. The mission, the look bench and
// the look regression test all run a look through this one pipeline.
#pragma once

#include <cstddef>
#include <cstdint>

#include "algo/core/fixed_vector.h"
#include "algo/evidence/reading.h"
#include "algo/evidence/reading_limits.h"
#include "algo/stereo/floor_cue.h"
#include "algo/stereo/range_check.h"
#include "algo/stereo/rig.h"
#include "algo/stereo/stereo_processor.h"
#include "firmware/mission/look/look_scan.h"

namespace boticelli::firmware::mission {

// Readings of one look (robot frame): stereo features and the floor cue's output.
inline constexpr std::size_t kMaxLookFeatures = 16384;
inline constexpr std::size_t kMaxLookFloorObstacles = 12288;
inline constexpr std::size_t kMaxLookFloorFree = 8192;
// Walks blocked at their bottom row: at most one per column walked, 80 columns a frame.
inline constexpr std::size_t kMaxLookFloorBlocked = 4096;

struct LookReadings {
  core::FixedVector<evidence::Reading, kMaxLookFeatures> features;
  core::FixedVector<evidence::Reading, kMaxLookFloorObstacles> floor_obstacles;
  core::FixedVector<evidence::Reading, kMaxLookFloorFree> floor_free;
  core::FixedVector<float, kMaxLookFloorFree> floor_free_near;  // each walk's near end [m]
  core::FixedVector<evidence::Reading, kMaxLookFloorBlocked> floor_blocked;
  void clear();
};

// The target as one view's stereo pair located it, and across pans (the vertex in this view's
// first frame and in the look's last one at another pan: a longer baseline than the tilt's).
struct TargetFixes {
  stereo::TargetFix pair;
  stereo::TargetFix across;
};

// The parts of a view, one background unit each, in this order.
enum class ViewPart : std::uint8_t {
  kStereo,       // features tracked and triangulated (pairs only)
  kTarget,       // the target detector on both frames (pairs only); the aimed pair ends here
  kFloorFirst,   // the floor cue learns from and walks the first frame
  kFloorSecond,  // ... and a low pair's second frame, which sees nearer floor
};

class LookProcessor {
 public:
  // keep_blocked_walks: whether walks blocked at their bottom row are kept (only when the
  // Think stage closes their rays, LocalModelParams::close_blocked_rays).
  LookProcessor(const stereo::RigParams& rig, const stereo::StereoParams& stereo,
                bool keep_blocked_walks);
  LookProcessor(const LookProcessor&) = delete;
  LookProcessor& operator=(const LookProcessor&) = delete;

  // A new look: its lists emptied, the floor cue's frames from the last look (seen from
  // elsewhere) forgotten, no sighting carried over to pair across pans.
  void begin_look();
  // A new mission: begin_look() and nothing learnt about the floor either. The stereo's
  // self-calibration is the rig's and is kept.
  void reset();
  // The stereo's self-calibration a resumed mission learnt before (MissionState): the
  // inverse-range bias in use from now on, held to ±self_calibration_max_bias_per_m; 0 when
  // the self-calibration is off or the value is not finite.
  void restore_inverse_range_bias(float bias_per_m);
  // One part of a view; true when the view is done. kTarget fills `fixes` (else untouched).
  bool process(ViewPart part, const GrabbedView& view, TargetFixes& fixes);
  // The look is complete: the stereo's self-calibration takes the look's range check
  // (StereoParams::self_calibration: the next looks' tilt pairs have the bias removed), then
  // drops the features outside the reading limits and, on a floor the floor cue knows to be
  // textured, makes those of the floor itself free (evidence::floor_readings): the Think
  // stage's input.
  void end_look(const evidence::ReadingLimits& limits);
  // A recorded look replayed (the look regression tests): begin_look(), and the caller fills
  // the lists returned in place of process(); end_look() then as for a look taken.
  LookReadings& begin_replay() {
    begin_look();
    return readings_;
  }

  [[nodiscard]] const LookReadings& readings() const { return readings_; }
  // The stereo points of the last pair processed (PTU frame).
  [[nodiscard]] const stereo::StereoProcessor& stereo() const { return stereo_; }
  [[nodiscard]] const stereo::RigModel& rig() const { return rig_; }
  // Features tracked in the last pair.
  [[nodiscard]] std::uint32_t last_features() const { return last_features_; }
  // The look's calibration self-check so far: stereo ranges against the floor cue's at the
  // bases of obstacles (each pair's first frame).
  [[nodiscard]] stereo::RangeCheck& range_check() { return range_check_; }

 private:
  void floor(const image::LowResFrame& frame, float pan_rad, float tilt_rad);
  void self_calibrate();

  stereo::RigModel rig_;
  stereo::StereoProcessor stereo_;
  stereo::FloorCue floor_cue_;
  stereo::RangeCheck range_check_;
  bool keep_blocked_;
  LookReadings readings_;
  stereo::TargetSighting last_sighting_{};  // this look's latest first frame with the target
  std::uint32_t last_features_ = 0;
};

// A fix's point in the world frame of the look's pose: PTU frame → robot → world; the PTU
// centre is on the robot's axis, ptu_height_m above the floor [m].
Eigen::Vector3f fix_in_world(const core::Pose2& look_pose, const stereo::TargetFix& fix,
                             float ptu_height_m);

}  // namespace boticelli::firmware::mission
