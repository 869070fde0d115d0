// LookProcessor: stereo, target and floor cue per view part (see look_processor.h).
#include "firmware/mission/look/look_processor.h"

#include <algorithm>
#include <cmath>

namespace boticelli::firmware::mission {

void LookReadings::clear() {
  features.clear();
  floor_obstacles.clear();
  floor_free.clear();
  floor_free_near.clear();
  floor_blocked.clear();
}

LookProcessor::LookProcessor(const stereo::RigParams& rig, const stereo::StereoParams& stereo,
                             bool keep_blocked_walks)
    : rig_(rig),
      stereo_(rig_, stereo),
      floor_cue_(rig_),
      range_check_(rig_),
      keep_blocked_(keep_blocked_walks) {}

void LookProcessor::begin_look() {
  readings_.clear();
  floor_cue_.begin_look();
  range_check_.begin_look();
  last_sighting_ = {};
}

void LookProcessor::reset() {
  floor_cue_.reset();
  begin_look();
}

void LookProcessor::floor(const image::LowResFrame& frame, float pan_rad, float tilt_rad) {
  (void)floor_cue_.learn(frame, pan_rad, tilt_rad);
  (void)floor_cue_.process(frame, pan_rad, tilt_rad, readings_.floor_obstacles,
                           readings_.floor_free, &readings_.floor_free_near,
                           keep_blocked_ ? &readings_.floor_blocked : nullptr);
}

bool LookProcessor::process(ViewPart part, const GrabbedView& view, TargetFixes& fixes) {
  switch (part) {
    case ViewPart::kStereo:
      if (view.pair) {
        (void)stereo_.process(view.first, view.second, view.pose, readings_.features);
        last_features_ = static_cast<std::uint32_t>(stereo_.points().size());
      }
      return false;
    case ViewPart::kTarget:
      fixes = {};
      if (view.pair) {
        fixes.pair = stereo_.locate_target(view.first, view.second, view.pose);
        if (fixes.pair.first.found) {
          const stereo::TargetSighting here{fixes.pair.first, view.pose.pan_rad,
                                            view.pose.first_tilt_rad};
          fixes.across = stereo_.locate_target_across(last_sighting_, here);
          last_sighting_ = here;
        }
      }
      // The aimed pair looks up at the target, not at the floor.
      return view.aimed;
    case ViewPart::kFloorFirst:
      // The floor cue: learn from the frames that see the floor close in front, then walk
      // the columns; a low pair's second frame sees nearer floor than its first.
      floor(view.first, view.pose.pan_rad, view.pose.first_tilt_rad);
      if (view.pair) {
        (void)range_check_.add_view(floor_cue_, view.pose.pan_rad, view.pose.first_tilt_rad,
                                    stereo_.points().data(), stereo_.points().size());
      }
      return !(view.pair && view.pose.second_tilt_rad < -0.3F);
    case ViewPart::kFloorSecond:
      floor(view.second, view.pose.pan_rad, view.pose.second_tilt_rad);
      return true;
  }
  return true;
}

void LookProcessor::end_look(const evidence::ReadingLimits& limits) {
  self_calibrate();
  (void)evidence::filter_readings(readings_.features, limits);
  // On a floor the cue knows to be textured, the stereo's floor-level readings are mostly the
  // floor's texture; on a plain floor they are the bases of walls and boxes, kept as the
  // thesis fits them.
  if (floor_cue_.model().valid && floor_cue_.model().textured) {
    (void)evidence::floor_readings(readings_.features, limits);
  }
}

void LookProcessor::restore_inverse_range_bias(float bias_per_m) {
  const stereo::StereoParams& p = stereo_.params();
  const float limit = p.self_calibration_max_bias_per_m;
  stereo_.set_inverse_range_bias(p.self_calibration && std::isfinite(bias_per_m)
                                     ? std::clamp(bias_per_m, -limit, limit)
                                     : 0.0F);
}

void LookProcessor::self_calibrate() {
  float residual = 0.0F;
  std::size_t n = 0;
  if (!range_check_.inverse_bias(residual, n)) return;
  stereo_.set_inverse_range_bias(
      stereo::updated_inverse_bias(stereo_.inverse_range_bias(), residual, n, stereo_.params()));
}

Eigen::Vector3f fix_in_world(const core::Pose2& look_pose, const stereo::TargetFix& fix,
                             float ptu_height_m) {
  const core::Point2 w = core::to_world(look_pose, {fix.point_ptu_m.x(), fix.point_ptu_m.y()});
  return {w.x_m, w.y_m, fix.point_ptu_m.z() + ptu_height_m};
}

}  // namespace boticelli::firmware::mission
