// Tests of the LookProcessor: the parts of a view and the look's lists (on synthetic frames:
// the sequencing and the lists, not the stereo's accuracy), and fix_in_world.
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <memory>

#include <Eigen/Core>

#include "algo/core/angles.h"
#include "algo/core/geometry.h"
#include "algo/image/low_res_frame.h"
#include "algo/stereo/stereo_processor.h"
#include "firmware/common/board_config.h"
#include "firmware/mission/look/look_processor.h"
#include "firmware/mission/look/look_scan.h"
#include "firmware/mission/params/mission_params.h"

#include "CppUTest/TestHarness.h"

using boticelli::core::kPi;
using boticelli::firmware::BoardConfig;
using boticelli::image::LowResFrame;
using boticelli::stereo::PairPose;
using boticelli::stereo::TargetFix;
using namespace boticelli::firmware::mission;

namespace {

// Frames at the rig's processing resolution (160 x 120), static: each is about 460 KB.
LowResFrame g_plain;   // an even, neutral grey: the floor cue learns it as the floor
LowResFrame g_first;   // a texture of blobs
LowResFrame g_second;  // the same texture moved down: the pair's second frame

void fill_plain(LowResFrame& f) {
  f.width = 160;
  f.height = 120;
  for (std::size_t i = 0; i < std::size_t{160} * 120; ++i) {
    f.luma[i] = 110.0F;
    f.chroma_u[i] = 128;
    f.chroma_v[i] = 128;
  }
}

// Smooth blobs, moved down the image by `shift_px` rows: not a real scene, but the stereo finds
// features to track in it (4 rows: some of them within the reading limits, some beyond).
void fill_texture(LowResFrame& f, float shift_px) {
  fill_plain(f);
  for (std::uint32_t v = 0; v < f.height; ++v) {
    for (std::uint32_t u = 0; u < f.width; ++u) {
      const float x = static_cast<float>(u);
      const float y = static_cast<float>(v) - shift_px;
      const float t = std::sin(0.31F * x + 0.7F * std::sin(0.05F * y)) *
                      std::cos(0.23F * y + 0.9F * std::sin(0.07F * x));
      f.luma[f.index(u, v)] = 128.0F + 90.0F * t;
    }
  }
}

PairPose pose_at(float pan_rad, float first_tilt_rad, float second_tilt_rad) {
  PairPose p;
  p.pan_rad = pan_rad;
  p.first_tilt_rad = first_tilt_rad;
  p.second_tilt_rad = second_tilt_rad;
  return p;
}

}  // namespace

TEST_GROUP(LookProcessor) {
  const MissionParams params = make_mission_params(BoardConfig{});
  std::unique_ptr<LookProcessor> look;
  TargetFixes fixes;

  void setup() override {
    look = std::make_unique<LookProcessor>(params.rig, params.stereo, true);
    fill_plain(g_plain);
    fill_texture(g_first, 0.0F);
    fill_texture(g_second, 4.0F);
  }
  void teardown() override {
    look.reset();
  }

  // A view of the scan: both frames, where the PTU stood, pair or not, aimed or not.
  static GrabbedView view(const LowResFrame& first, const LowResFrame& second, const PairPose& pose,
                          bool pair, bool aimed = false) {
    return {first, second, pose, pair, 0, aimed};
  }
};

TEST(LookProcessor, APairsStereoPartTracksFeaturesIntoTheLooksListAndAnUnpairedViewsNone) {
  const float phi = params.rig.tilt_step_rad;
  // The same two frames as a single frame's view: no stereo.
  const GrabbedView single = view(g_first, g_second, pose_at(0.0F, -0.3F, -0.3F - phi), false);
  CHECK_FALSE(look->process(ViewPart::kStereo, single, fixes));
  CHECK_EQUAL(0U, look->last_features());
  CHECK_EQUAL(0U, look->readings().features.size());
  // As a pair they give features, appended to the look's list.
  const GrabbedView pair = view(g_first, g_second, pose_at(0.0F, -0.3F, -0.3F - phi), true);
  CHECK_FALSE(look->process(ViewPart::kStereo, pair, fixes));
  const std::size_t first = look->readings().features.size();
  CHECK(look->last_features() > 0U);
  CHECK(first > 0U);
  CHECK_FALSE(look->process(ViewPart::kStereo, pair, fixes));
  CHECK(look->readings().features.size() > first);
}

TEST(LookProcessor, AnUnpairedViewsTargetPartLeavesNoFixAndTheViewGoesOnToTheFloor) {
  const GrabbedView single = view(g_first, g_first, pose_at(0.5F, -0.3F, -0.3F), false);
  fixes.pair.found = true;  // whatever a view before left
  fixes.across.found = true;
  CHECK_FALSE(look->process(ViewPart::kTarget, single, fixes));
  CHECK_FALSE(fixes.pair.found);
  CHECK_FALSE(fixes.across.found);
}

TEST(LookProcessor, TheAimedPairEndsAfterItsTargetPart) {
  const float phi = params.rig.tilt_step_rad;
  const GrabbedView aimed = view(g_first, g_second, pose_at(0.2F, 0.1F, 0.1F - phi), true, true);
  CHECK_FALSE(look->process(ViewPart::kStereo, aimed, fixes));
  CHECK_TRUE(look->process(ViewPart::kTarget, aimed, fixes));
  // A scan's pair goes on to the floor cue.
  const GrabbedView scanned = view(g_first, g_second, pose_at(0.2F, 0.1F, 0.1F - phi), true);
  CHECK_FALSE(look->process(ViewPart::kTarget, scanned, fixes));
}

TEST(LookProcessor, ALowPairHasFourPartsALevelPairAndASingleFrameThree) {
  const float phi = params.rig.tilt_step_rad;
  // A low pair: its second frame (below -0.3 rad) sees nearer floor, a part of its own.
  const GrabbedView low = view(g_plain, g_plain, pose_at(0.0F, -0.25F, -0.25F - phi), true);
  CHECK(low.pose.second_tilt_rad < -0.3F);
  CHECK_FALSE(look->process(ViewPart::kFloorFirst, low, fixes));
  CHECK_TRUE(look->process(ViewPart::kFloorSecond, low, fixes));
  // A level pair ends after its first frame's floor part.
  const GrabbedView level = view(g_plain, g_plain, pose_at(0.0F, 0.0F, -phi), true);
  CHECK_TRUE(look->process(ViewPart::kFloorFirst, level, fixes));
  // A single frame has no second frame, however low.
  const GrabbedView single = view(g_plain, g_plain, pose_at(0.0F, -0.8F, -0.8F), false);
  CHECK_TRUE(look->process(ViewPart::kFloorFirst, single, fixes));
}

TEST(LookProcessor, TheFloorCueFillsTheLooksListsAndBeginLookEmptiesThem) {
  // Two views of plain floor far enough apart in pan confirm the floor; its walks are free.
  const GrabbedView left = view(g_plain, g_plain, pose_at(0.0F, -0.5F, -0.5F), false);
  const GrabbedView right = view(g_plain, g_plain, pose_at(1.2F, -0.5F, -0.5F), false);
  CHECK_TRUE(look->process(ViewPart::kFloorFirst, left, fixes));
  CHECK_TRUE(look->process(ViewPart::kFloorFirst, right, fixes));
  const float phi = params.rig.tilt_step_rad;
  const GrabbedView pair = view(g_first, g_second, pose_at(0.0F, -0.3F, -0.3F - phi), true);
  CHECK_FALSE(look->process(ViewPart::kStereo, pair, fixes));
  const LookReadings& r = look->readings();
  CHECK(r.features.size() > 0U);
  CHECK(r.floor_free.size() > 0U);
  CHECK_EQUAL(r.floor_free.size(), r.floor_free_near.size());
  look->begin_look();
  CHECK_EQUAL(0U, r.features.size());
  CHECK_EQUAL(0U, r.floor_obstacles.size());
  CHECK_EQUAL(0U, r.floor_free.size());
  CHECK_EQUAL(0U, r.floor_free_near.size());
  CHECK_EQUAL(0U, r.floor_blocked.size());
  // The floor learnt stays for the next look (reset() forgets it): one view is walked at once.
  CHECK_TRUE(look->process(ViewPart::kFloorFirst, left, fixes));
  CHECK(r.floor_free.size() > 0U);
  look->reset();
  CHECK_EQUAL(0U, r.floor_free.size());
  CHECK_TRUE(look->process(ViewPart::kFloorFirst, left, fixes));
  CHECK_EQUAL(0U, r.floor_free.size());  // kept until a second direction confirms the floor
}

TEST(LookProcessor, EndLookDropsTheFeaturesOutsideTheReadingLimits) {
  const float phi = params.rig.tilt_step_rad;
  const GrabbedView pair = view(g_first, g_second, pose_at(0.0F, -0.3F, -0.3F - phi), true);
  CHECK_FALSE(look->process(ViewPart::kStereo, pair, fixes));
  const std::size_t before = look->readings().features.size();
  look->end_look(params.limits);
  for (const boticelli::evidence::Reading& f : look->readings().features) {
    CHECK(params.limits.within(f));
  }
  // Some of the synthetic pair's features lie beyond the limits, some within.
  CHECK(look->readings().features.size() > 0U);
  CHECK(look->readings().features.size() < before);
}

TEST(LookProcessor, AFixInTheWorldTurnsThePtuFramePointWithTheLookPoseAndAddsThePtuHeight) {
  TargetFix fix;
  fix.found = true;
  fix.point_ptu_m = Eigen::Vector3f(2.0F, 0.5F, 0.3F);  // 2 m ahead, 0.5 m left, 0.3 m up
  // Robot at (1, -1) facing +y: ahead is +y, left is -x.
  const Eigen::Vector3f w = fix_in_world({1.0F, -1.0F, kPi<float> / 2.0F}, fix, 0.6F);
  DOUBLES_EQUAL(0.5, w.x(), 1e-5);
  DOUBLES_EQUAL(1.0, w.y(), 1e-5);
  DOUBLES_EQUAL(0.9, w.z(), 1e-5);
}

// A resumed mission's learnt bias is the stereo's from the start, held to the self-calibration's
// bound; nothing when the self-calibration is off, or when the saved value is not a number.
TEST(LookProcessor, ARestoredStereoBiasIsUsedHeldToItsBoundAndOnlyWithTheSelfCalibrationOn) {
  const float limit = params.stereo.self_calibration_max_bias_per_m;
  look->restore_inverse_range_bias(0.0473F);
  DOUBLES_EQUAL(0.0473, look->stereo().inverse_range_bias(), 1e-7);
  look->restore_inverse_range_bias(-3.0F * limit);
  DOUBLES_EQUAL(-limit, look->stereo().inverse_range_bias(), 1e-7);
  look->restore_inverse_range_bias(std::numeric_limits<float>::quiet_NaN());
  DOUBLES_EQUAL(0.0, look->stereo().inverse_range_bias(), 0.0);
  boticelli::stereo::StereoParams off = params.stereo;
  off.self_calibration = false;
  LookProcessor plain(params.rig, off, true);
  plain.restore_inverse_range_bias(0.0473F);
  DOUBLES_EQUAL(0.0, plain.stereo().inverse_range_bias(), 0.0);
}
