// Floor-appearance cue on frames of the sim renderer: obstacle bases where the geometry puts them.
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <initializer_list>
#include <limits>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include <Eigen/Core>

#include "algo/core/fixed_vector.h"
#include "algo/evidence/reading.h"
#include "algo/image/low_res_frame.h"
#include "algo/stereo/floor_cue.h"
#include "algo/stereo/range_check.h"
#include "algo/stereo/stereo_processor.h"
#include "algo/stereo/rig.h"
#include "board_config.h"
#include "hal/sim/renderer.h"
#include "hal/sim/sim_world.h"
#include "hal/sim/textures.h"
#include "hal/sim/world.h"

#include "CppUTest/TestHarness.h"
#include "alloc_guard.h"

using boticelli::core::FixedVector;
using boticelli::evidence::Reading;
using boticelli::image::LowResFrame;
using boticelli::stereo::FloorColumn;
using boticelli::stereo::FloorCue;
using boticelli::stereo::FloorCueParams;
using boticelli::stereo::FloorCueResult;
using boticelli::stereo::FloorLearn;
using boticelli::stereo::RigModel;
namespace sim = boticelli::hal::sim;
namespace board = boticelli::boards::sim;

namespace {

constexpr float kLookTilt = -0.5F;  // the look's lower tilt row [rad]
constexpr float kBaseTol = 0.1F;    // base distance tolerance [m] (with 10 % of the distance)

// The world files' common part: a plain floor (the example colour of WORLDS.md), the
// example's directional light, the robot at the origin facing +x, the target behind it.
std::string world_with(const std::string& models, const std::string& floor_pattern = "") {
  return "<sdf version=\"1.6\" xmlns:boticelli=\"urn:boticelli:sdf\">\n<world name=\"t\">\n"
         "<scene><ambient>0.45 0.45 0.45 1</ambient></scene>\n"
         "<light name=\"sun\" type=\"directional\"><direction>-0.3 0.2 -1</direction>"
         "<diffuse>0.6 0.6 0.6 1</diffuse></light>\n"
         "<include><uri>model://boticelli</uri><pose>0 0 0 0 0 0</pose></include>\n"
         "<model name=\"floor\"><link name=\"l\"><visual name=\"v\"><geometry><plane>"
         "<normal>0 0 1</normal><size>20 20</size></plane></geometry>"
         "<material><diffuse>0.55 0.5 0.45 1</diffuse></material>" +
         floor_pattern +
         "</visual></link></model>\n"
         "<model name=\"target\"><pose>-6 0 1 0 0 0</pose><link name=\"l\"><visual name=\"v\">"
         "<geometry><box><size>0.01 0.3 0.3</size></box></geometry>"
         "<boticelli:pattern>paper</boticelli:pattern>"
         "<boticelli:target face=\"+x\" size=\"0.2\"/></visual></link></model>\n" +
         models + "</world>\n</sdf>\n";
}

// A plain box: centre x y z and size sx sy sz [m], colour "r g b".
std::string plain_box(const char* name, const char* pose, const char* size,
                      const char* colour = "0.7 0.7 0.7") {
  return std::string("<model name=\"") + name + "\"><pose>" + pose +
         " 0 0 0</pose><link name=\"l\"><visual name=\"v\"><geometry><box><size>" + size +
         "</size></box></geometry><material><diffuse>" + colour +
         " 1</diffuse></material></visual></link></model>\n";
}

std::string table_at(float x, float y) {
  std::string s;
  char pose[64];
  std::snprintf(pose, sizeof pose, "%.3f %.3f 0.69", static_cast<double>(x),
                static_cast<double>(y));
  s += plain_box("table_top", pose, "1.0 0.8 0.02", "0.6 0.45 0.3");
  const float dx[4] = {-0.45F, 0.45F, -0.45F, 0.45F};
  const float dy[4] = {-0.35F, -0.35F, 0.35F, 0.35F};
  for (int i = 0; i < 4; ++i) {
    std::snprintf(pose, sizeof pose, "%.3f %.3f 0.34", static_cast<double>(x + dx[i]),
                  static_cast<double>(y + dy[i]));
    char name[16];
    std::snprintf(name, sizeof name, "leg%d", i);
    s += plain_box(name, pose, "0.05 0.05 0.68", "0.6 0.45 0.3");
  }
  return s;
}

// One world with its renderer, as the sim board builds them.
struct Scene {
  sim::World world;
  sim::TextureBank textures;
  sim::SimWorld sim;
  std::optional<sim::Renderer> renderer;  // allocates: built per test, dropped in teardown
};

// A rug: the floor wears 0.12 m camouflage patches (tests/worlds/patterned_floor.sdf).
const std::string kRug =
    "<boticelli:pattern scale=\"0.12\" seed=\"95\">camouflage</boticelli:pattern>";

Scene g_scene;  // large (textures): static
RigModel g_rig(board::make_rig_params(board::make_config()));
std::vector<std::uint8_t> g_yuyv(640U * 480U * 2U);
LowResFrame g_frame;
LowResFrame g_frame2;
char g_error[256];

void load(const std::string& models, const std::string& floor_pattern = "") {
  const std::string xml = world_with(models, floor_pattern);
  CHECK_TEXT(sim::parse_world(xml.c_str(), xml.size(), "floor_cue.sdf", g_scene.world, g_error,
                              sizeof g_error),
             g_error);
  CHECK_TEXT(g_scene.textures.build(g_scene.world, g_error, sizeof g_error), g_error);
  const board::SimSettings settings = board::make_settings(board::make_config(), 3);
  CHECK_TEXT(g_scene.sim.init(g_scene.world, g_rig, settings.physics, g_error, sizeof g_error),
             g_error);
  g_scene.renderer.emplace();
  CHECK_TEXT(g_scene.renderer->init(g_scene.world, g_scene.textures, g_rig.camera(),
                                    settings.render, g_error, sizeof g_error),
             g_error);
}

sim::RigidTransform camera_in_world(float pan, float tilt) {
  return g_scene.sim.camera_pose(boticelli::core::Pose2{0.0F, 0.0F, 0.0F}, pan, tilt);
}

void render(float pan, float tilt, std::uint32_t frame_index, LowResFrame& out) {
  g_scene.renderer->render(camera_in_world(pan, tilt), frame_index, g_yuyv.data(), 640U * 2U,
                           nullptr);
  CHECK(boticelli::image::downsample_yuyv(g_yuyv.data(), 640, 480, 640 * 2, 4, out));
}

Eigen::Vector3f floor_point_of(const Reading& r) {
  const float rho = std::sqrt(r.r_m * r.r_m - r.h_m * r.h_m);
  return {rho * std::cos(r.alpha_rad), rho * std::sin(r.alpha_rad), 0.0F};  // world, on the floor
}

// Distance along the floor from below the camera to the nearest obstacle within one
// low-resolution pixel (1/F rad; the cue stops at an edge that near) either side of the direction
// of `floor_target`, for horizontal rays `height` above the floor (+inf if none) [m].
float first_obstacle_m(float pan, float tilt, const Eigen::Vector3f& floor_target, float height,
                       float spread_rad = 1.0F / 150.0F) {
  const Eigen::Vector3f c = camera_in_world(pan, tilt).translation_m;
  const Eigen::Vector3f origin(c.x(), c.y(), height);
  const float heading = std::atan2(floor_target.y() - c.y(), floor_target.x() - c.x());
  float nearest = std::numeric_limits<float>::infinity();
  for (const float offset : {-spread_rad, 0.0F, spread_rad}) {
    const Eigen::Vector3f d(std::cos(heading + offset), std::sin(heading + offset), 0.0F);
    std::size_t surface = 0;
    float t = 0.0F;
    if (sim::cast_ray(g_scene.world, origin, d, surface, t)) {
      nearest = std::min(nearest, t);
    }
  }
  return nearest;
}

// Does an obstacle's vertical edge lie within `spread_rad` either side of the direction of
// `floor_target` (the rays there and either side do not all meet one face within 0.1 m)?
bool grazes_edge(float pan, float tilt, const Eigen::Vector3f& floor_target,
                 float spread_rad = 1.5F / 150.0F) {
  const float left = first_obstacle_m(pan, tilt, floor_target, 0.02F, 0.0F);
  float lo = left;
  float hi = left;
  for (const float side : {-1.0F, 1.0F}) {
    const Eigen::Vector3f c = camera_in_world(pan, tilt).translation_m;
    const float heading = std::atan2(floor_target.y() - c.y(), floor_target.x() - c.x());
    const Eigen::Vector3f d(std::cos(heading + side * spread_rad),
                            std::sin(heading + side * spread_rad), 0.0F);
    std::size_t surface = 0;
    float t = std::numeric_limits<float>::infinity();
    if (!sim::cast_ray(g_scene.world, Eigen::Vector3f(c.x(), c.y(), 0.02F), d, surface, t)) {
      t = std::numeric_limits<float>::infinity();
    }
    lo = std::min(lo, t);
    hi = std::max(hi, t);
  }
  return std::isinf(hi) != std::isinf(lo) || hi - lo > 0.1F;
}

float along_floor_m(float pan, float tilt, const Eigen::Vector3f& floor_point) {
  const Eigen::Vector3f c = camera_in_world(pan, tilt).translation_m;
  return std::hypot(floor_point.x() - c.x(), floor_point.y() - c.y());
}

struct Outputs {
  FixedVector<Reading, 1024> obstacles;
  FixedVector<Reading, 256> free;
  FloorCueResult result;
};

// Every obstacle base within tolerance of the truth along its line of sight; returns how
// many bases were checked. Every free reading short of the first obstacle, and visible.
// On a textured floor (`textured`), a walk whose own line passes beside the obstacle (it
// meets it only within the half pixel either side, not where the walk looks), or along its
// edge (grazes_edge), may go on past its base: the rug's colours let it, and only a plain stretch
// on the walk itself ends it. Such a walk must still not end nearer than the obstacle. A rug's
// largest patches (the darkest tone's blotches run on for half a metre) can end a walk where
// nothing stands: at most 8 of a frame's 80 walks end so, with no obstacle within 1.5 px of the
// walk or short of the first one (docs/mapping.md, "Textured floors").
std::size_t check_against_truth(const FloorCue& cue, const Outputs& out, float pan, float tilt,
                                bool textured = false) {
  const std::size_t per_base = cue.params().obstacle_height_count;
  CHECK_EQUAL(out.result.boundaries * per_base, out.obstacles.size());
  float worst_far = -1.0F;
  float worst_near = -1.0F;
  std::size_t phantoms = 0;
  for (std::size_t i = 0; i < out.obstacles.size(); i += per_base) {
    const Eigen::Vector3f base = floor_point_of(out.obstacles[i]);
    const float estimate = along_floor_m(pan, tilt, base);
    // Nothing within half a pixel of the walk may be nearer than its base; something
    // within one and a half pixels (the cue stops beside an edge) must be there.
    const float truth = first_obstacle_m(pan, tilt, base, 0.02F, 0.5F / 150.0F);
    const float wide = first_obstacle_m(pan, tilt, base, 0.02F, 1.5F / 150.0F);
    // Farther than the truth: at most the smaller of 0.1 m and 10 %; nearer: the larger.
    const float far_tol = std::min(kBaseTol, 0.1F * truth);
    const float near_tol = std::max(kBaseTol, 0.1F * wide);
    if (std::getenv("FLOOR_DEBUG") != nullptr) {
      std::printf("\n   base %zu u=%u est %.3f truth %.3f centre %.3f m=%.2f", i / per_base,
                  static_cast<unsigned>(i / per_base), static_cast<double>(estimate),
                  static_cast<double>(truth),
                  static_cast<double>(first_obstacle_m(pan, tilt, base, 0.02F, 0.0F)),
                  static_cast<double>(out.obstacles[i].m));
    }
    if (textured && (std::isinf(wide) || estimate < wide - std::max(kBaseTol, 0.1F * wide))) {
      ++phantoms;  // nothing stands there: no obstacle near the walk, or only farther on
      continue;
    }
    const bool beside =
        textured && !(first_obstacle_m(pan, tilt, base, 0.02F, 0.0F) < wide + 0.05F);
    if (!beside) worst_far = std::max(worst_far, estimate - truth);
    worst_near = std::max(worst_near, wide - estimate);
    if (!((beside || estimate <= truth + far_tol) && estimate >= wide - near_tol)) {
      char text[160];
      std::snprintf(text, sizeof text,
                    "base %zu at %.3f m along the floor, truth %.3f m (%.3f m within 1.5 px)",
                    i / per_base, static_cast<double>(estimate), static_cast<double>(truth),
                    static_cast<double>(wide));
      FAIL(text);
    }
    // A clear boundary (the walk's own line meets the obstacle, not only a pixel beside
    // it) is strong evidence.
    if (first_obstacle_m(pan, tilt, base, 0.02F, 0.0F) < wide + 0.05F) {
      CHECK(out.obstacles[i].m >= 0.6F);
    }
  }
  CHECK_TEXT(phantoms <= 8U, std::to_string(phantoms).c_str());
  const Eigen::Vector3f eye = camera_in_world(pan, tilt).translation_m;
  for (const Reading& f : out.free) {
    CHECK_EQUAL(0.0F, f.m);
    DOUBLES_EQUAL(-g_rig.params().ptu_height_m, f.h_m, 1e-4);
    const Eigen::Vector3f p = floor_point_of(f);
    const float along = along_floor_m(pan, tilt, p);
    // On a textured floor a walk along an obstacle's edge may pass it (see above).
    if (textured && grazes_edge(pan, tilt, p)) continue;  // where the world decides, not the cue
    CHECK(along <= first_obstacle_m(pan, tilt, p, 0.02F, 0.0F) + 0.01F);
    CHECK(along <= first_obstacle_m(pan, tilt, p, 0.3F, 0.0F) + 0.01F);
    // The line of sight from the camera to the free point reaches it.
    std::size_t surface = 0;
    float t = 0.0F;
    const Eigen::Vector3f d = p - eye;
    CHECK(sim::cast_ray(g_scene.world, eye, d, surface, t));
    CHECK(t >= 0.99F);
  }
  if (out.obstacles.size() > 0) {
    std::printf("\n  tilt %+.3f: %zu bases, worst farther %+.3f m, worst nearer %+.3f m\n",
                static_cast<double>(tilt), out.obstacles.size() / per_base,
                static_cast<double>(worst_far), static_cast<double>(worst_near));
  }
  return out.obstacles.size() / per_base - phantoms;
}

// Walks whose vertical plane meets an obstacle standing on the floor where the frame sees
// its base (in the image, nearer than max range, beyond the bottom row) must end at a
// boundary; returns how many did. On a textured floor (`textured`) a plain thing is found by
// a stretch of one colour longer than the model's max_run_m, so only one whose base is that
// much short of max range can be, and only where the walk does not run along its edge.
std::size_t check_detected(const FloorCue& cue, float pan, float tilt, bool textured = false) {
  const boticelli::stereo::CameraPose pose = g_rig.camera_pose(pan, tilt);
  const boticelli::stereo::CameraIntrinsics& camera = g_rig.low_res_camera();
  const Eigen::Vector3f c = camera_in_world(pan, tilt).translation_m;
  std::size_t detected = 0;
  for (std::size_t i = 0; i < cue.column_count(); ++i) {
    const FloorColumn& col = cue.column(i);
    const Eigen::Vector3f d(std::cos(col.azimuth_rad), std::sin(col.azimuth_rad), 0.0F);
    std::size_t surface = 0;
    float t = 0.0F;
    bool in_view = false;
    if (sim::cast_ray(g_scene.world, Eigen::Vector3f(c.x(), c.y(), 0.02F), d, surface, t)) {
      const Eigen::Vector3f base(c.x() + t * d.x(), c.y() + t * d.y(), 0.0F);
      const float rho = std::hypot(base.x(), base.y());
      Eigen::Vector2f px;
      const Eigen::Vector3f base_ptu =
          base - Eigen::Vector3f(0.0F, 0.0F, g_rig.params().ptu_height_m);
      const float reach = textured ? cue.model().max_run_m : 0.0F;
      in_view = rho > col.near_rho_m + 0.1F && rho < cue.params().max_range_m - 0.15F - reach &&
                !(textured && grazes_edge(pan, tilt, base)) &&
                RigModel::project_ptu(pose, camera, base_ptu, px) && px.x() >= 1.0F &&
                px.y() >= 1.0F && px.x() <= static_cast<float>(camera.width_px) - 2.0F &&
                px.y() <= static_cast<float>(camera.height_px) - 2.0F;
    }
    if (std::getenv("FLOOR_DEBUG") != nullptr) {
      std::printf("\n   col u=%u end=%d base_rho %.3f free_rho %.3f truth %.3f in view %d",
                  col.u_px, static_cast<int>(col.end), static_cast<double>(col.base_rho_m),
                  static_cast<double>(col.free_rho_m), static_cast<double>(t), in_view ? 1 : 0);
    }
    if (in_view) {
      CHECK_TEXT(col.end == FloorColumn::End::kBoundary, "an obstacle in view was missed");
      ++detected;
    }
  }
  return detected;
}

}  // namespace

// The walks' tests trust the first region they learn from (the consensus of two directions
// has its own tests below).
FloorCueParams trusting() {
  FloorCueParams p;
  p.confirm_separation_rad = 0.0F;
  return p;
}

// The walks' tests' parameters on synthetic frames, drawn without vignetting.
FloorCueParams flat_trusting() {
  FloorCueParams p = trusting();
  p.vignetting = 0.0F;
  return p;
}

TEST_GROUP(FloorCue) {
  FloorCue cue{g_rig, trusting()};
  Outputs out;

  void teardown() override {
    g_scene.renderer.reset();
  }

  void run(float pan, float tilt, std::uint32_t frame_index) {
    render(pan, tilt, frame_index, g_frame);
    out.obstacles.clear();
    out.free.clear();
    out.result = cue.process(g_frame, pan, tilt, out.obstacles, out.free);
  }
};

TEST(FloorCue, OpenFloorGivesNoObstaclesAndFreeFloorOutToMaxRangeInEveryColumn) {
  load("");
  render(0.0F, kLookTilt, 1, g_frame);
  CHECK(FloorLearn::kLearned == cue.learn(g_frame, 0.0F, kLookTilt));
  for (const float tilt : {kLookTilt, 0.0F}) {
    run(0.7F, tilt, 2);
    CHECK(out.result.model_valid);
    CHECK_EQUAL(80U, out.result.columns);
    CHECK_EQUAL(0U, out.obstacles.size());
    CHECK_EQUAL(out.result.columns, out.free.size());
    for (std::size_t i = 0; i < cue.column_count(); ++i) {
      CHECK(cue.column(i).end == FloorColumn::End::kMaxRange);
      // The farthest floor pixel within max range is at most one pixel's step short of it.
      CHECK(cue.column(i).free_rho_m > cue.params().max_range_m - 0.2F);
      CHECK(cue.column(i).free_rho_m <= cue.params().max_range_m);
    }
    check_against_truth(cue, out, 0.7F, tilt);
  }
}

TEST(FloorCue, PlainBoxesAreFoundAtTheirBaseAndFreeFloorStopsThere) {
  // Two plain 0.5 m boxes: a grey one with its front at 1.2 m on the left, one of the
  // floor's own colour with its front at 2.4 m on the right (only its shading differs).
  load(plain_box("near", "1.4 0.5 0.25", "0.4 0.6 0.5") +
       plain_box("far", "2.6 -0.6 0.25", "0.4 0.8 0.5", "0.55 0.5 0.45"));
  render(0.0F, kLookTilt, 1, g_frame);
  CHECK(FloorLearn::kLearned == cue.learn(g_frame, 0.0F, kLookTilt));
  run(0.0F, kLookTilt, 1);
  CHECK(check_against_truth(cue, out, 0.0F, kLookTilt) >= 10);
  CHECK(check_detected(cue, 0.0F, kLookTilt) >= 10);
  run(0.0F, 0.0F, 2);
  CHECK(check_against_truth(cue, out, 0.0F, 0.0F) >= 5);
  CHECK(check_detected(cue, 0.0F, 0.0F) >= 5);
}

TEST(FloorCue, ABoundarysEvidenceRisesFromWeakToClearWithItsContrast) {
  // The boxes of the test above from the lower tilt. With the defaults the clearest
  // boundaries reach evidence_clear; asking for a contrast no boundary has
  // (clear_contrast = 1000 tolerances) leaves every one near evidence_weak.
  load(plain_box("near", "1.4 0.5 0.25", "0.4 0.6 0.5") +
       plain_box("far", "2.6 -0.6 0.25", "0.4 0.8 0.5", "0.55 0.5 0.45"));
  render(0.0F, kLookTilt, 1, g_frame);
  FloorCueParams p = trusting();
  p.clear_contrast = 1000.0F;
  static FloorCue dim{g_rig, p};  // large (kept frames): not on the stack
  dim.reset();
  for (FloorCue* c : {&cue, &dim}) {
    CHECK(FloorLearn::kLearned == c->learn(g_frame, 0.0F, kLookTilt));
    out.obstacles.clear();
    out.free.clear();
    out.result = c->process(g_frame, 0.0F, kLookTilt, out.obstacles, out.free);
    CHECK(out.result.boundaries >= 10);
    float least = 1.0F;
    float most = 0.0F;
    for (std::size_t i = 0; i < c->column_count(); ++i) {
      if (c->column(i).end != FloorColumn::End::kBoundary) continue;
      least = std::min(least, c->column(i).evidence);
      most = std::max(most, c->column(i).evidence);
    }
    CHECK(least >= p.evidence_weak);
    CHECK(most <= p.evidence_clear);
    if (c == &cue) {
      DOUBLES_EQUAL(p.evidence_clear, most, 1e-6);
    } else {
      CHECK(most < p.evidence_weak + 0.05F);
    }
  }
}

TEST(FloorCue, ARegionOfFewerPixelsThanTheMinimumIsNotLearned) {
  FloorCueParams p = trusting();
  p.reference_min_pixels = 100000;  // more than the low-resolution frame has
  static FloorCue strict{g_rig, p};
  strict.reset();
  load("");
  render(0.0F, kLookTilt, 1, g_frame);
  CHECK(FloorLearn::kNoRegion == strict.learn(g_frame, 0.0F, kLookTilt));
  CHECK_FALSE(strict.model().valid);
  // The same frame with the default minimum is learned.
  CHECK(FloorLearn::kLearned == cue.learn(g_frame, 0.0F, kLookTilt));
}

TEST(FloorCue, AFeaturelessWallIsFoundInEveryColumn) {
  load(plain_box("wall", "2.0 0 0.75", "0.1 8 1.5", "0.8 0.8 0.75"));
  render(0.0F, kLookTilt, 1, g_frame);
  CHECK(FloorLearn::kLearned == cue.learn(g_frame, 0.0F, kLookTilt));
  run(0.3F, kLookTilt, 3);
  CHECK_EQUAL(out.result.columns, out.result.boundaries);
  CHECK_EQUAL(out.result.columns, check_against_truth(cue, out, 0.3F, kLookTilt));
  CHECK_EQUAL(out.result.columns, out.free.size());
}

TEST(FloorCue, TableLegsAreFoundAndTheFloorUnderTheTableIsOnlyFreeAtFloorHeight) {
  load(table_at(1.8F, 0.0F));
  render(0.0F, kLookTilt, 1, g_frame);
  CHECK(FloorLearn::kLearned == cue.learn(g_frame, 0.0F, kLookTilt));
  run(0.0F, kLookTilt, 4);
  CHECK(check_detected(cue, 0.0F, kLookTilt) >= 4);
  CHECK(check_against_truth(cue, out, 0.0F, kLookTilt) >= 4);
}

TEST(FloorCue, AnObstacleInTheReferenceRegionDoesNotPoisonTheFloorModel) {
  load(plain_box("front", "0.85 0.15 0.25", "0.3 0.4 0.5"));
  // A fresh cue refuses a region with the box in part of it.
  render(0.0F, kLookTilt, 1, g_frame);
  CHECK(FloorLearn::kNotUniform == cue.learn(g_frame, 0.0F, kLookTilt));
  CHECK_FALSE(cue.model().valid);
  // Learnt elsewhere (the box out of view), the model is not updated from the box in front.
  render(1.2F, kLookTilt, 2, g_frame2);
  CHECK(FloorLearn::kLearned == cue.learn(g_frame2, 1.2F, kLookTilt));
  const boticelli::stereo::FloorModel before = cue.model();
  CHECK(FloorLearn::kInconsistent == cue.learn(g_frame, 0.0F, kLookTilt));
  for (std::size_t c = 0; c < 3; ++c) {
    CHECK_EQUAL(before.median[c], cue.model().median[c]);
    CHECK_EQUAL(before.tolerance[c], cue.model().tolerance[c]);
  }
  // And with the kept model the box in front is found.
  run(0.0F, kLookTilt, 1);
  CHECK(check_detected(cue, 0.0F, kLookTilt) >= 5);
  CHECK(check_against_truth(cue, out, 0.0F, kLookTilt) >= 5);
}

// A camouflage wall (the shipped rooms' dark cloth) 0.55 m in front fills the far part of the
// reference region: two surfaces, one of them busy. Their mixture's spread is so wide that a
// model of it (luma median 47 ± 77) calls wall and floor alike floor, so it passed its own
// consistency test; no plain floor spreads so much, so the region is refused.
TEST(FloorCue, ARegionHalfWallHalfFloorIsNotLearned) {
  std::string wall = plain_box("wall", "0.6 0 0.75", "0.1 8 1.5", "0.36 0.4 0.26");
  wall.insert(wall.find("</visual>"),
              "<boticelli:pattern scale=\"0.08\" seed=\"1\">camouflage</boticelli:pattern>");
  load(wall);
  render(0.0F, kLookTilt, 1, g_frame);
  CHECK(FloorLearn::kNotUniform == cue.learn(g_frame, 0.0F, kLookTilt));
  CHECK_FALSE(cue.model().valid);
}

// Every free reading comes with where its walk began; the level view's walks begin beyond
// the floor the low view sees first (its bottom row looks farther out).
TEST(FloorCue, EachFreeReadingComesWithTheNearEndOfItsWalk) {
  load("");
  render(0.0F, kLookTilt, 1, g_frame);
  CHECK(FloorLearn::kLearned == cue.learn(g_frame, 0.0F, kLookTilt));
  FixedVector<float, 256> near_m;
  for (const float tilt : {kLookTilt, 0.0F}) {
    render(0.7F, tilt, 2, g_frame);
    out.obstacles.clear();
    out.free.clear();
    near_m.clear();
    out.result = cue.process(g_frame, 0.7F, tilt, out.obstacles, out.free, &near_m);
    CHECK(out.free.size() > 0);
    CHECK_EQUAL(out.free.size(), near_m.size());
    for (std::size_t i = 0; i < out.free.size(); ++i) {
      CHECK(near_m[i] > 0.0F);
      CHECK(near_m[i] < boticelli::evidence::horizontal_m(out.free[i]));
      if (tilt < 0.0F) {
        CHECK(near_m[i] < 0.8F);
      } else {
        CHECK(near_m[i] > 1.0F);
      }
    }
  }
}

// Beside a plain box that fills the reference region of the view facing it, the box is
// uniform and would be learned as the floor; then every region of the real floor is refused
// as inconsistent and the box's colour is "floor" for the rest of the look. By default the
// first model waits for a region from another direction (≥ 1 rad away) that agrees.
TEST(FloorCue, APlainBoxFillingTheFirstRegionIsNotLearnedAsTheFloor) {
  load(plain_box("crate", "0.75 0 0.3", "0.5 0.8 0.6", "0.5 0.4 0.3"));
  static FloorCue fresh{g_rig};  // large (kept frames): not on the stack
  fresh.reset();
  // Trusting the first region learns the box (it is uniform): the case this guards.
  render(0.0F, kLookTilt, 1, g_frame);
  CHECK(FloorLearn::kLearned == cue.learn(g_frame, 0.0F, kLookTilt));
  CHECK(cue.model().median[0] < 100.0F);  // the box's face, not the floor's ≈ 129
  // The default cue waits; a region 0.4 rad on (still the box's side) does not confirm.
  CHECK(FloorLearn::kPending == fresh.learn(g_frame, 0.0F, kLookTilt));
  CHECK_FALSE(fresh.model().valid);
  // The floor, away from the box, replaces the pending box (they disagree) and waits too.
  render(1.6F, kLookTilt, 2, g_frame2);
  CHECK(FloorLearn::kPending == fresh.learn(g_frame2, 1.6F, kLookTilt));
  CHECK_FALSE(fresh.model().valid);
  // Another direction of floor, far enough from the first floor view, confirms it.
  render(-1.6F, kLookTilt, 3, g_frame2);
  CHECK(FloorLearn::kLearned == fresh.learn(g_frame2, -1.6F, kLookTilt));
  CHECK(fresh.model().median[0] > 110.0F);
  // With that model no walk in front goes past the box's front face (0.5 m); with the box's
  // model they went on over it to the floor behind.
  out.obstacles.clear();
  out.free.clear();
  out.result = fresh.process(g_frame, 0.0F, kLookTilt, out.obstacles, out.free);
  CHECK(out.result.model_valid);
  for (const Reading& f : out.free) {
    const Eigen::Vector3f p = floor_point_of(f);
    if (std::fabs(p.y()) < 0.4F) CHECK(p.x() < 0.5F);
  }
  out.free.clear();
  out.obstacles.clear();
  (void)cue.process(g_frame, 0.0F, kLookTilt, out.obstacles, out.free);
  bool past_box = false;
  for (const Reading& f : out.free) {
    const Eigen::Vector3f p = floor_point_of(f);
    past_box = past_box || (std::fabs(p.y()) < 0.4F && p.x() > 1.0F);
  }
  CHECK_TEXT(past_box,
             "the box's model no longer lets walks past the box (the guarded case changed)");
}

TEST(FloorCue, TwoAgreeingRegionsTooCloseInPanDoNotConfirmTheFloor) {
  load("");
  static FloorCue fresh{g_rig};
  fresh.reset();
  // Pans away from 0, so that each waiting region's own pan is what is compared.
  render(2.0F, kLookTilt, 1, g_frame);
  CHECK(FloorLearn::kPending == fresh.learn(g_frame, 2.0F, kLookTilt));
  render(2.5F, kLookTilt, 2, g_frame);
  CHECK(FloorLearn::kPending == fresh.learn(g_frame, 2.5F, kLookTilt));
  CHECK_FALSE(fresh.model().valid);
  render(3.2F, kLookTilt, 3, g_frame);
  CHECK(FloorLearn::kLearned == fresh.learn(g_frame, 3.2F, kLookTilt));
  CHECK(fresh.model().valid);
}

// While the first model waits, a view's frames are kept and walked once it comes: the views
// before it lose nothing.
TEST(FloorCue, FramesSeenBeforeTheModelIsConfirmedAreWalkedWhenItIs) {
  load("");
  static FloorCue fresh{g_rig};
  fresh.reset();
  render(0.0F, kLookTilt, 1, g_frame);
  CHECK(FloorLearn::kPending == fresh.learn(g_frame, 0.0F, kLookTilt));
  out.obstacles.clear();
  out.free.clear();
  FloorCueResult r = fresh.process(g_frame, 0.0F, kLookTilt, out.obstacles, out.free);
  CHECK(r.deferred);
  CHECK_FALSE(r.model_valid);
  CHECK_EQUAL(0U, out.free.size());
  render(1.2F, kLookTilt, 2, g_frame2);
  CHECK(FloorLearn::kLearned == fresh.learn(g_frame2, 1.2F, kLookTilt));
  FixedVector<Reading, 512> free;
  r = fresh.process(g_frame2, 1.2F, kLookTilt, out.obstacles, free);
  CHECK_EQUAL(1U, r.deferred_walked);
  CHECK_EQUAL(160U, free.size());  // 80 walks of each frame, all out to max range
  std::size_t ahead = 0;  // walks of the kept frame (pan 0): within 0.5 rad of straight ahead
  for (const Reading& f : free) {
    ahead += std::fabs(std::remainder(f.alpha_rad, 6.2831853F)) < 0.5F ? 1U : 0U;
  }
  CHECK(ahead >= 70U);
}

TEST(FloorCue, LearningAtLevelTiltFindsNoReferenceRegion) {
  load("");
  render(0.0F, 0.0F, 1, g_frame);
  CHECK(FloorLearn::kNoRegion == cue.learn(g_frame, 0.0F, 0.0F));
  CHECK_FALSE(cue.model().valid);
  run(0.0F, 0.0F, 1);
  CHECK_FALSE(out.result.model_valid);
  CHECK_EQUAL(0U, out.obstacles.size() + out.free.size());
}

TEST(FloorCue, ProcessingNeverWritesPastTheOutputsAndDoesNotAllocate) {
  load(plain_box("wall", "2.0 0 0.75", "0.1 8 1.5", "0.8 0.8 0.75"));
  render(0.0F, kLookTilt, 1, g_frame);
  CHECK(FloorLearn::kLearned == cue.learn(g_frame, 0.0F, kLookTilt));
  FixedVector<Reading, 7> obstacles;
  FixedVector<Reading, 5> free;
  FloorCueResult r;
  FixedVector<float, 3> near_m;
  CHECK_NO_ALLOCATION(r = cue.process(g_frame, 0.0F, kLookTilt, obstacles, free, &near_m));
  CHECK(r.truncated);
  CHECK_EQUAL(3U, free.size());  // in step with the near ends, the shorter list
  CHECK_EQUAL(3U, near_m.size());
  obstacles.clear();
  free.clear();
  CHECK_NO_ALLOCATION(r = cue.process(g_frame, 0.0F, kLookTilt, obstacles, free));
  CHECK(r.truncated);
  CHECK_EQUAL(7U, obstacles.size());
  CHECK_EQUAL(5U, free.size());
  CHECK_EQUAL(7U, r.obstacle_readings);
  CHECK_EQUAL(5U, r.free_readings);
  CHECK_NO_ALLOCATION(static_cast<void>(cue.learn(g_frame, 0.0F, kLookTilt)));
}

TEST(FloorCue, CoverageOfTheLookTiltsAndTheirStereoPartners) {
  // Prints what each tilt of the look sees of the floor (centre column); the numbers the
  // report quotes. The checks are the geometry's plain facts.
  for (const float tilt : {0.0F, -0.134390352F, -0.5F, -0.634390352F, -0.55F, -0.6F}) {
    float near_m = 0.0F;
    float far_m = 0.0F;
    CHECK(cue.floor_coverage(tilt, near_m, far_m));
    std::printf("\n  tilt %+.3f rad: floor from %.2f m to %.2f m", static_cast<double>(tilt),
                static_cast<double>(near_m), static_cast<double>(far_m));
    CHECK(near_m < far_m);
  }
  float near0 = 0.0F;
  float far0 = 0.0F;
  CHECK(cue.floor_coverage(0.0F, near0, far0));
  CHECK(std::isinf(far0));  // level: the top rows see the horizon
  // The outputs are the tilt's alone, whatever they held before the call.
  float near_m = 0.0F;
  float far_m = 0.0F;
  CHECK(cue.floor_coverage(-0.5F, near_m, far_m));
  float near_junk = -1.0F;
  float far_junk = 1000.0F;
  CHECK(cue.floor_coverage(-0.5F, near_junk, far_junk));
  DOUBLES_EQUAL(near_m, near_junk, 0.0);
  DOUBLES_EQUAL(far_m, far_junk, 0.0);
}

// A cluttered place can show unlike regions in turn before two agree: the floor at one pan,
// a plain box at the next, the floor again beyond it. With one waiting region the box's
// took the first floor's place and the third region, unlike the box, waited again; the
// cue keeps several, and the floor's two regions confirm each other across the box.
TEST(FloorCue, TheFloorIsConfirmedAcrossAnUnlikeRegionSeenBetweenItsTwo) {
  load(plain_box("crate", "0.75 0 0.3", "0.5 0.8 0.6", "0.5 0.4 0.3"));
  static FloorCue fresh{g_rig};
  fresh.reset();
  render(-1.6F, kLookTilt, 1, g_frame);
  CHECK(FloorLearn::kPending == fresh.learn(g_frame, -1.6F, kLookTilt));
  render(0.0F, kLookTilt, 2, g_frame);
  CHECK(FloorLearn::kPending == fresh.learn(g_frame, 0.0F, kLookTilt));  // the crate's face
  render(1.6F, kLookTilt, 3, g_frame);
  CHECK(FloorLearn::kLearned == fresh.learn(g_frame, 1.6F, kLookTilt));
  CHECK(fresh.model().median[0] > 110.0F);  // the floor's, not the crate's
}

// A walk whose bottom row is not floor says nothing of where the obstacle stands, but that
// it stands nearer than the bottom row's floor point: each such walk is reported there, the
// walks whose bottom row is floor are not.
TEST(FloorCue, AWalkBlockedAtItsBottomRowIsReportedAtThatRowsFloorPoint) {
  // The crate's front face at 0.5 m, nearer than the low view's bottom row (about 0.75 m).
  load(plain_box("crate", "0.75 0 0.3", "0.5 0.8 0.6", "0.5 0.4 0.3"));
  render(1.6F, kLookTilt, 1, g_frame);
  CHECK(FloorLearn::kLearned == cue.learn(g_frame, 1.6F, kLookTilt));
  render(0.0F, kLookTilt, 2, g_frame);
  FixedVector<Reading, 128> blocked;
  out.obstacles.clear();
  out.free.clear();
  CHECK_NO_ALLOCATION(out.result = cue.process(g_frame, 0.0F, kLookTilt, out.obstacles, out.free,
                                               nullptr, &blocked));
  CHECK_EQUAL(blocked.size(), out.result.blocked_readings);
  std::size_t blocked_columns = 0;
  std::size_t in_front = 0;
  std::size_t k = 0;
  for (std::size_t i = 0; i < cue.column_count(); ++i) {
    const FloorColumn& c = cue.column(i);
    if (c.end != FloorColumn::End::kBlockedAtBottom) continue;
    ++blocked_columns;
    const Reading& r = blocked[k++];
    DOUBLES_EQUAL(c.near_rho_m, std::sqrt(r.r_m * r.r_m - r.h_m * r.h_m), 1e-3);
    DOUBLES_EQUAL(-g_rig.params().ptu_height_m, r.h_m, 1e-3);  // on the floor
    const Eigen::Vector3f p = floor_point_of(r);
    in_front += std::fabs(p.y()) < 0.4F ? 1U : 0U;  // behind the crate's face
  }
  CHECK_EQUAL(blocked_columns, blocked.size());
  CHECK(blocked.size() >= 20U);           // the crate spans most of the view's bottom row
  CHECK_EQUAL(blocked.size(), in_front);  // and only it blocks a walk at the bottom
}

// The lowest row's two frames a view, kept while the first model waits: a cluttered place
// may confirm it only at its twelfth view, and the frames before it are all walked.
TEST(FloorCue, TwentyFourFramesSeenBeforeTheModelAreKeptAndWalked) {
  load("");
  static FloorCue fresh{g_rig};
  fresh.reset();
  render(0.0F, kLookTilt, 1, g_frame);
  std::size_t kept = 0;
  for (int i = 0; i < 24; ++i) {
    out.obstacles.clear();
    out.free.clear();
    const FloorCueResult r = fresh.process(g_frame, 0.0F, kLookTilt, out.obstacles, out.free);
    CHECK_FALSE(r.deferred_dropped);
    kept += r.deferred ? 1U : 0U;
  }
  CHECK_EQUAL(24U, kept);
  CHECK(FloorLearn::kPending == fresh.learn(g_frame, 0.0F, kLookTilt));
  render(1.2F, kLookTilt, 2, g_frame2);
  CHECK(FloorLearn::kLearned == fresh.learn(g_frame2, 1.2F, kLookTilt));
  std::size_t walked = 0;
  for (int i = 0; i < 30; ++i) {
    FixedVector<Reading, 512> free;
    out.obstacles.clear();
    walked += fresh.process(g_frame2, 1.2F, kLookTilt, out.obstacles, free).deferred_walked;
  }
  CHECK_EQUAL(24U, walked);
}

// Textured floors: a rug's patches in four tones give the plain floor's test no one colour,
// and the floor cue learns the rug's colours instead, from two directions that agree.
TEST(FloorCue, ARugIsLearnedFromTwoDirectionsAndIsFreeOutToMaxRange) {
  load("", kRug);
  static FloorCue fresh{g_rig};
  fresh.reset();
  render(0.0F, kLookTilt, 1, g_frame);
  CHECK(FloorLearn::kPending == fresh.learn(g_frame, 0.0F, kLookTilt));
  render(1.6F, kLookTilt, 2, g_frame);
  CHECK(FloorLearn::kLearned == fresh.learn(g_frame, 1.6F, kLookTilt));
  CHECK(fresh.model().textured);
  for (const float tilt : {kLookTilt, 0.0F}) {
    render(0.7F, tilt, 4, g_frame);
    out.obstacles.clear();
    out.free.clear();
    out.result = fresh.process(g_frame, 0.7F, tilt, out.obstacles, out.free);
    CHECK_EQUAL(80U, out.result.columns);
    // Nothing stands on the rug: at most 8 of the 80 walks end short of max range (at the
    // rug's largest patches, as check_against_truth allows).
    std::size_t short_walks = 0;
    for (std::size_t i = 0; i < fresh.column_count(); ++i) {
      short_walks += fresh.column(i).end == FloorColumn::End::kMaxRange ? 0U : 1U;
    }
    CHECK_TEXT(short_walks <= 8U, std::to_string(short_walks).c_str());
    CHECK(out.free.size() >= 72U);
  }
}

// The rug's own colours, plain: the patterned room's box (its face wears one of the rug's
// tones) and a grey one. A plain thing is found where one colour runs on for longer than the
// rug's patches, at its base.
TEST(FloorCue, PlainBoxesOnARugAreFoundAtTheirBase) {
  FloorCueParams bases = trusting();
  bases.texture_obstacles = true;
  static FloorCue rug{g_rig, bases};
  rug.reset();
  const auto walk = [&](float pan, float tilt, std::uint32_t frame_index) {
    render(pan, tilt, frame_index, g_frame);
    out.obstacles.clear();
    out.free.clear();
    out.result = rug.process(g_frame, pan, tilt, out.obstacles, out.free);
  };
  load(plain_box("near", "1.4 0.5 0.25", "0.4 0.6 0.5", "0.6 0.55 0.5") +
           plain_box("far", "2.6 -0.6 0.25", "0.4 0.8 0.5"),
       kRug);
  render(0.0F, kLookTilt, 1, g_frame);
  CHECK(FloorLearn::kLearned == rug.learn(g_frame, 0.0F, kLookTilt));
  CHECK(rug.model().textured);
  walk(0.0F, kLookTilt, 1);
  CHECK(check_against_truth(rug, out, 0.0F, kLookTilt, true) >= 10);
  CHECK(check_detected(rug, 0.0F, kLookTilt, true) >= 10);
  // Level, the floor is seen from 1.7 m: the far box's face (2.4 m) runs out at max range
  // (3 m) before it is longer than the rug's patches; the walks that find it find its base.
  walk(0.0F, 0.0F, 2);
  CHECK(check_against_truth(rug, out, 0.0F, 0.0F, true) >= 5);
}

// By default (texture_obstacles off) a plain stretch on a textured floor only ends the floor
// seen free: the boxes above stop the walks as before, and no obstacle reading is made.
TEST(FloorCue, OnARugAPlainStretchEndsTheFreeFloorWithoutAnObstacleByDefault) {
  load(plain_box("near", "1.4 0.5 0.25", "0.4 0.6 0.5", "0.6 0.55 0.5") +
           plain_box("far", "2.6 -0.6 0.25", "0.4 0.8 0.5"),
       kRug);
  render(0.0F, kLookTilt, 1, g_frame);
  CHECK(FloorLearn::kLearned == cue.learn(g_frame, 0.0F, kLookTilt));
  run(0.0F, kLookTilt, 1);
  CHECK_EQUAL(0U, out.obstacles.size());
  CHECK_EQUAL(0U, out.result.boundaries);
  CHECK(check_detected(cue, 0.0F, kLookTilt, true) >= 10);
  CHECK_EQUAL(0U, check_against_truth(cue, out, 0.0F, kLookTilt, true));  // the free floor
}

// A red patterned mat 3 cm high covers the far half of the first region on a rug: its near
// and far halves do not hold each other's colours, so it is not one texture and waits for
// nothing. Two regions of rug alone from directions far enough apart confirm the rug, and the
// mat is then not floor.
TEST(FloorCue, ARegionHalfMatHalfRugIsNotLearnedAndTheMatIsNotFloor) {
  std::string mat = plain_box("mat", "1.0 0 0.015", "0.7 2.0 0.03", "0.8 0.2 0.2");
  mat.insert(mat.find("</visual>"),
             "<boticelli:pattern scale=\"0.12\" seed=\"7\">camouflage</boticelli:pattern>");
  load(mat, kRug);
  static FloorCue fresh{g_rig};
  fresh.reset();
  render(0.0F, kLookTilt, 1, g_frame);
  CHECK(FloorLearn::kNotUniform == fresh.learn(g_frame, 0.0F, kLookTilt));
  render(1.8F, kLookTilt, 2, g_frame);
  CHECK(FloorLearn::kPending == fresh.learn(g_frame, 1.8F, kLookTilt));
  CHECK_FALSE(fresh.model().valid);
  render(3.4F, kLookTilt, 3, g_frame);
  CHECK(FloorLearn::kLearned == fresh.learn(g_frame, 3.4F, kLookTilt));
  // No walk towards the mat sees free floor beyond its near edge (x = 0.65 m).
  render(0.0F, kLookTilt, 4, g_frame);
  out.obstacles.clear();
  out.free.clear();
  out.result = fresh.process(g_frame, 0.0F, kLookTilt, out.obstacles, out.free);
  std::size_t towards = 0;
  for (const Reading& f : out.free) {
    const Eigen::Vector3f p = floor_point_of(f);
    if (std::fabs(p.y()) < 0.9F) {
      ++towards;
      CHECK(p.x() < 0.75F);
    }
  }
  CHECK(towards >= 20U);
}

// A synthetic frame of the rig's low resolution: 4 x 4 px patches cycling through the given
// grey levels (no vignetting).
void fill_patches(LowResFrame& frame, std::initializer_list<float> greys) {
  const boticelli::stereo::CameraIntrinsics& camera = g_rig.low_res_camera();
  frame.width = camera.width_px;
  frame.height = camera.height_px;
  const std::vector<float> tones(greys);
  for (std::uint32_t v = 0; v < frame.height; ++v) {
    for (std::uint32_t u = 0; u < frame.width; ++u) {
      frame.luma[frame.index(u, v)] = tones[(u / 4 + v / 4) % tones.size()];
      frame.chroma_u[frame.index(u, v)] = 128;
      frame.chroma_v[frame.index(u, v)] = 128;
    }
  }
}

// Textures agree both ways: a waiting region of four tones holds all of a later region of three
// of them, but not the reverse, so the two do not confirm a floor (which would call the fourth
// tone floor too); two regions of the three tones do.
TEST(FloorCue, TexturesAgreeOnlyWhenEachHoldsTheOthersColours) {
  FloorCueParams flat;
  flat.vignetting = 0.0F;
  static FloorCue fresh{g_rig, flat};
  fresh.reset();
  fill_patches(g_frame, {40.0F, 100.0F, 160.0F, 220.0F});
  CHECK(FloorLearn::kPending == fresh.learn(g_frame, 0.0F, kLookTilt));
  fill_patches(g_frame2, {40.0F, 100.0F, 160.0F});
  CHECK(FloorLearn::kPending == fresh.learn(g_frame2, 1.8F, kLookTilt));
  CHECK_FALSE(fresh.model().valid);
  CHECK(FloorLearn::kLearned == fresh.learn(g_frame2, 3.4F, kLookTilt));
  CHECK(fresh.model().textured);
  float contrast = 0.0F;
  CHECK(fresh.looks_like_floor(g_frame2, 0, g_frame2.height - 1, contrast));
  fill_patches(g_frame, {220.0F});
  CHECK_FALSE(fresh.looks_like_floor(g_frame, 0, g_frame.height - 1, contrast));
}

// One texture: a region whose near part holds a tone its far part lacks (a mat in front of
// the robot on a rug) is not learned, and neither is the reverse; the same patches all
// through it are.
TEST(FloorCue, ARegionIsOneTextureOnlyIfItsNearAndFarHalvesHoldEachOthersColours) {
  const FloorCueParams flat = flat_trusting();
  static FloorCue fresh{g_rig, flat};
  const boticelli::stereo::CameraPose pose = g_rig.camera_pose(0.0F, kLookTilt);
  const boticelli::stereo::CameraIntrinsics& camera = g_rig.low_res_camera();
  // Patches of near_tones where a pixel sees the floor nearer than 0.7 m (the region's
  // middle), of far_tones beyond.
  const auto two_parts = [&](std::initializer_list<float> near_tones,
                             std::initializer_list<float> far_tones) {
    fill_patches(g_frame2, far_tones);
    fill_patches(g_frame, near_tones);
    for (std::uint32_t v = 0; v < g_frame.height; ++v) {
      for (std::uint32_t u = 0; u < g_frame.width; ++u) {
        const Eigen::Vector3f ray = RigModel::ray_ptu(
            pose, camera, Eigen::Vector2f(static_cast<float>(u), static_cast<float>(v)));
        const float t = (-g_rig.params().ptu_height_m - pose.centre_m.z()) / ray.z();
        const Eigen::Vector3f p = pose.centre_m + t * ray;
        if (!(ray.z() < 0.0F) || std::hypot(p.x(), p.y()) >= 0.7F) {
          g_frame.luma[g_frame.index(u, v)] = g_frame2.luma[g_frame2.index(u, v)];
        }
      }
    }
    fresh.reset();
    return fresh.learn(g_frame, 0.0F, kLookTilt);
  };
  CHECK(FloorLearn::kNotUniform ==
        two_parts({40.0F, 100.0F, 160.0F, 220.0F}, {40.0F, 100.0F, 160.0F}));
  CHECK(FloorLearn::kNotUniform ==
        two_parts({40.0F, 100.0F, 160.0F}, {40.0F, 100.0F, 160.0F, 220.0F}));
  CHECK(FloorLearn::kLearned ==
        two_parts({40.0F, 100.0F, 160.0F, 220.0F}, {40.0F, 100.0F, 160.0F, 220.0F}));
}

// Along a walk, one colour is one within the change tolerances of the last sample and within
// twice them of the stretch's first: a blurred, distant texture drifts a little from row to
// row and is not one plain stretch; a frame all of one of the floor's colours is.
TEST(FloorCue, ADriftingShadeIsNotOnePlainStretchButOneShadeIs) {
  const FloorCueParams flat = flat_trusting();
  static FloorCue fresh{g_rig, flat};
  fresh.reset();
  fill_patches(g_frame, {24.0F, 40.0F, 56.0F, 72.0F, 88.0F, 104.0F, 120.0F, 136.0F, 152.0F, 168.0F,
                         184.0F, 200.0F, 216.0F, 232.0F});
  CHECK(FloorLearn::kLearned == fresh.learn(g_frame, 0.0F, kLookTilt));
  CHECK(fresh.model().textured);
  // Six grey levels a row, darker upwards, from 230 down to 30 and again: every walk sees
  // floor colours all the way.
  fill_patches(g_frame2, {0.0F});
  for (std::uint32_t v = 0; v < g_frame2.height; ++v) {
    for (std::uint32_t u = 0; u < g_frame2.width; ++u) {
      g_frame2.luma[g_frame2.index(u, v)] =
          230.0F - static_cast<float>((6 * (g_frame2.height - 1 - v)) % 200);
    }
  }
  out.obstacles.clear();
  out.free.clear();
  out.result = fresh.process(g_frame2, 0.0F, kLookTilt, out.obstacles, out.free);
  CHECK_EQUAL(0U, out.result.boundaries);
  CHECK_EQUAL(out.result.columns, out.free.size());
  // One shade of the floor's over the whole frame: every walk is blocked from its bottom row.
  fill_patches(g_frame2, {136.0F});
  out.obstacles.clear();
  out.free.clear();
  out.result = fresh.process(g_frame2, 0.0F, kLookTilt, out.obstacles, out.free);
  CHECK_EQUAL(0U, out.free.size());
  for (std::size_t i = 0; i < fresh.column_count(); ++i) {
    CHECK(fresh.column(i).end == FloorColumn::End::kBlockedAtBottom);
  }
}

// A plain floor's model from two agreeing regions lies between them in every channel, and an
// update moves every channel by the learning rate; a textured model's histogram stays a
// distribution (its masses sum to one) when two regions confirm it.
TEST(FloorCue, ModelsAreBlendedInEveryChannelAndTexturesStayDistributions) {
  FloorCueParams flat;
  flat.vignetting = 0.0F;
  static FloorCue fresh{g_rig, flat};
  fresh.reset();
  const auto plain = [](LowResFrame& frame, float y, int cb, int cr) {
    fill_patches(frame, {y});
    for (std::size_t i = 0; i < std::size_t{frame.width} * frame.height; ++i) {
      frame.chroma_u[i] = static_cast<std::uint8_t>(128 + cb);
      frame.chroma_v[i] = static_cast<std::uint8_t>(128 + cr);
    }
  };
  plain(g_frame, 120.0F, 4, -4);
  CHECK(FloorLearn::kPending == fresh.learn(g_frame, 0.0F, kLookTilt));
  plain(g_frame, 124.0F, 6, -2);
  CHECK(FloorLearn::kLearned == fresh.learn(g_frame, 1.8F, kLookTilt));
  CHECK_FALSE(fresh.model().textured);
  DOUBLES_EQUAL(122.0, fresh.model().median[0], 1e-4);
  DOUBLES_EQUAL(5.0, fresh.model().median[1], 1e-4);
  DOUBLES_EQUAL(-3.0, fresh.model().median[2], 1e-4);
  plain(g_frame, 126.0F, 7, 0);
  CHECK(FloorLearn::kUpdated == fresh.learn(g_frame, 3.4F, kLookTilt));
  DOUBLES_EQUAL(124.0, fresh.model().median[0], 1e-4);  // half way: learn_rate 0.5
  DOUBLES_EQUAL(6.0, fresh.model().median[1], 1e-4);
  DOUBLES_EQUAL(-1.5, fresh.model().median[2], 1e-4);

  fresh.reset();
  fill_patches(g_frame, {40.0F, 100.0F, 160.0F, 220.0F});
  CHECK(FloorLearn::kPending == fresh.learn(g_frame, 0.0F, kLookTilt));
  fill_patches(g_frame, {40.0F, 100.0F, 160.0F, 220.0F});
  CHECK(FloorLearn::kLearned == fresh.learn(g_frame, 1.8F, kLookTilt));
  CHECK(fresh.model().textured);
  double total = 0.0;
  for (const float m : fresh.model().mass) total += static_cast<double>(m);
  DOUBLES_EQUAL(1.0, total, 1e-3);
}

// Without textures (FloorCueParams::textured = false) a rug is never learned: the plain-floor
// cue alone, which says nothing on it.
TEST(FloorCue, WithoutTexturesARugIsNotLearned) {
  load("", kRug);
  FloorCueParams plain = trusting();
  plain.textured = false;
  static FloorCue fresh{g_rig, plain};
  fresh.reset();
  render(0.0F, kLookTilt, 1, g_frame);
  CHECK(FloorLearn::kNotUniform == fresh.learn(g_frame, 0.0F, kLookTilt));
  CHECK_FALSE(fresh.model().valid);
  static FloorCue textured{g_rig, trusting()};
  textured.reset();
  CHECK(FloorLearn::kLearned == textured.learn(g_frame, 0.0F, kLookTilt));
}

// A synthetic frame of the rig's low resolution, each pixel's (Y, Cb − 128, Cr − 128) given
// by colour(u, v).
template <typename Colour>
void paint(LowResFrame& frame, Colour colour) {
  const boticelli::stereo::CameraIntrinsics& camera = g_rig.low_res_camera();
  frame.width = camera.width_px;
  frame.height = camera.height_px;
  for (std::uint32_t v = 0; v < frame.height; ++v) {
    for (std::uint32_t u = 0; u < frame.width; ++u) {
      const std::array<float, 3> c = colour(u, v);
      frame.luma[frame.index(u, v)] = c[0];
      frame.chroma_u[frame.index(u, v)] = static_cast<std::uint8_t>(128.0F + c[1]);
      frame.chroma_v[frame.index(u, v)] = static_cast<std::uint8_t>(128.0F + c[2]);
    }
  }
}

// A plain floor of luma 120 with a wall of 220 across the image from its 45th row up.
void paint_wall(LowResFrame& frame) {
  paint(frame, [](std::uint32_t, std::uint32_t v) {
    return std::array<float, 3>{v < 45 ? 220.0F : 120.0F, 0.0F, 0.0F};
  });
}

// `cue` (trusting its first region) reset and learned on a plain floor of luma 120 filling
// g_frame; g_frame2 that floor with a wall across it (paint_wall).
void learned_on_flat_floor(FloorCue& cue) {
  cue.reset();
  fill_patches(g_frame, {120.0F});
  CHECK(FloorLearn::kLearned == cue.learn(g_frame, 0.0F, kLookTilt));
  paint_wall(g_frame2);
}

// Where pixel (u, v) of the low-resolution image sees the floor, in the PTU frame; false at or
// above the horizon.
bool floor_seen_at(const boticelli::stereo::CameraPose& pose, float u, float v,
                   Eigen::Vector3f& point) {
  const Eigen::Vector3f ray =
      RigModel::ray_ptu(pose, g_rig.low_res_camera(), Eigen::Vector2f(u, v));
  if (!(ray.z() < 0.0F)) return false;
  const float t = (-g_rig.params().ptu_height_m - pose.centre_m.z()) / ray.z();
  point = pose.centre_m + t * ray;
  return true;
}

// A textured model's share of a bin is the mass of that bin and of every bin next to it in
// all three channels (3 × 3 × 3 bins, fewer at the histogram's edges), checked bin by bin
// against a histogram whose colours reach both ends of every channel.
TEST(FloorCue, ATexturedFloorsShareOfABinIsTheMassOfItAndOfEveryBinNextToIt) {
  const FloorCueParams flat = flat_trusting();
  static FloorCue fresh{g_rig, flat};
  fresh.reset();
  constexpr std::array<std::array<float, 3>, 5> kColours{{{40.0F, -30.0F, 31.0F},
                                                          {100.0F, -20.0F, 10.0F},
                                                          {160.0F, 0.0F, -20.0F},
                                                          {220.0F, 10.0F, -30.0F},
                                                          {60.0F, 31.0F, 0.0F}}};
  paint(g_frame, [&](std::uint32_t u, std::uint32_t v) { return kColours[(u / 4 + v / 4) % 5]; });
  CHECK(FloorLearn::kLearned == fresh.learn(g_frame, 0.0F, kLookTilt));
  const boticelli::stereo::FloorModel& model = fresh.model();
  CHECK(model.textured);
  constexpr long kL = boticelli::stereo::kFloorLumaBins;
  constexpr long kC = boticelli::stereo::kFloorChromaBins;
  const auto at = [](long y, long u, long v) {
    return static_cast<std::size_t>((y * kC + u) * kC + v);
  };
  std::size_t with_mass = 0;
  std::size_t shared = 0;
  for (long y = 0; y < kL; ++y) {
    for (long u = 0; u < kC; ++u) {
      for (long v = 0; v < kC; ++v) {
        with_mass += model.mass[at(y, u, v)] > 0.0F ? 1U : 0U;
        double sum = 0.0;
        for (long dy = -1; dy <= 1; ++dy) {
          for (long du = -1; du <= 1; ++du) {
            for (long dv = -1; dv <= 1; ++dv) {
              if (y + dy < 0 || y + dy >= kL || u + du < 0 || u + du >= kC || v + dv < 0 ||
                  v + dv >= kC) {
                continue;
              }
              sum += static_cast<double>(model.mass[at(y + dy, u + du, v + dv)]);
            }
          }
        }
        shared += sum > 0.0 ? 1U : 0U;
        DOUBLES_EQUAL(sum, static_cast<double>(model.share[at(y, u, v)]), 1e-6);
      }
    }
  }
  CHECK_EQUAL(5U, with_mass);  // one bin per colour
  CHECK(shared > 5U * 8U);     // corner bins reach 8 bins, others up to 27
  // Each colour's bin: Y by 16 levels; Cb and Cr offsets by 8 from −32, clamped to 0..7.
  for (const auto& colour : kColours) {
    const auto chroma = [](float c) {
      return std::clamp(static_cast<long>((c + 32.0F) / 8.0F), 0L, 7L);
    };
    const float mass =
        model.mass[at(static_cast<long>(colour[0]) / 16, chroma(colour[1]), chroma(colour[2]))];
    CHECK(mass > 0.1F);  // a fifth of the region each, up to its edges
  }
}

namespace {

// g_frame a plain floor of `ycbcr` (luma, and Cb and Cr as offsets from 128) at the image's
// centre, dimmed towards black (luma 16, neutral chroma) by the fall-off 1 − vignetting · r²
// (r = 1 at the corners).
void paint_vignetted(float vignetting, const std::array<float, 3>& ycbcr) {
  const boticelli::stereo::CameraIntrinsics& camera = g_rig.low_res_camera();
  const float cx = 0.5F * static_cast<float>(camera.width_px - 1);
  const float cy = 0.5F * static_cast<float>(camera.height_px - 1);
  paint(g_frame, [&](std::uint32_t u, std::uint32_t v) {
    const float dx = static_cast<float>(u) - cx;
    const float dy = static_cast<float>(v) - cy;
    const float fall = 1.0F - vignetting * (dx * dx + dy * dy) / (cx * cx + cy * cy);
    return std::array<float, 3>{16.0F + (ycbcr[0] - 16.0F) * fall, ycbcr[1] * fall,
                                ycbcr[2] * fall};
  });
}

// The low-resolution image's four corner pixels (u, v).
std::array<std::pair<std::uint32_t, std::uint32_t>, 4> image_corners() {
  const boticelli::stereo::CameraIntrinsics& camera = g_rig.low_res_camera();
  const std::uint32_t right = camera.width_px - 1;
  const std::uint32_t bottom = camera.height_px - 1;
  return {{{0U, 0U}, {right, 0U}, {0U, bottom}, {right, bottom}}};
}

}  // namespace

// Vignetting is undone about the image's centre: a plain floor rendered with the configured
// fall-off (1 − vignetting · r², r = 1 at the corners) looks the same in every corner as in
// the middle.
TEST(FloorCue, VignettingIsUndoneAboutTheImageCentre) {
  FloorCueParams p = trusting();
  p.vignetting = 0.3F;
  static FloorCue fresh{g_rig, p};
  fresh.reset();
  const boticelli::stereo::CameraIntrinsics& camera = g_rig.low_res_camera();
  paint_vignetted(p.vignetting, {203.0F, 0.0F, 0.0F});
  CHECK(FloorLearn::kLearned == fresh.learn(g_frame, 0.0F, kLookTilt));
  CHECK_FALSE(fresh.model().textured);
  DOUBLES_EQUAL(203.0, fresh.model().median[0], 1.0);
  float middle = 0.0F;
  CHECK(fresh.looks_like_floor(g_frame, camera.width_px / 2, camera.height_px / 2, middle));
  for (const auto& [u, v] : image_corners()) {
    float contrast = 0.0F;
    CHECK(fresh.looks_like_floor(g_frame, u, v, contrast));
    DOUBLES_EQUAL(middle, contrast, 0.02);
  }
}

// An update by a region exactly like the model leaves it as it was: the histogram and the
// longest run move by the learning rate towards the region's, which are the same.
TEST(FloorCue, UpdatingATexturedFloorWithARegionLikeItLeavesItAsItWas) {
  const FloorCueParams flat = flat_trusting();
  static FloorCue fresh{g_rig, flat};
  fresh.reset();
  fill_patches(g_frame, {40.0F, 100.0F, 160.0F, 220.0F});
  CHECK(FloorLearn::kLearned == fresh.learn(g_frame, 0.0F, kLookTilt));
  CHECK(fresh.model().textured);
  const boticelli::stereo::FloorModel before = fresh.model();
  CHECK(before.max_run_m > 0.0F);
  CHECK(FloorLearn::kUpdated == fresh.learn(g_frame, 0.0F, kLookTilt));
  DOUBLES_EQUAL(before.max_run_m, fresh.model().max_run_m, 1e-6);
  for (std::size_t b = 0; b < boticelli::stereo::kFloorBins; ++b) {
    DOUBLES_EQUAL(before.mass[b], fresh.model().mass[b], 1e-6);
    DOUBLES_EQUAL(before.share[b], fresh.model().share[b], 1e-6);
  }
}

namespace {

// The longest stretch of floor [m] that columns first..last of a row of the reference region
// (all of them within it) see at `tilt`.
float longest_band_m(const FloorCueParams& p, std::uint32_t first, std::uint32_t last) {
  const boticelli::stereo::CameraPose pose = g_rig.camera_pose(0.0F, kLookTilt);
  float longest = 0.0F;
  for (std::uint32_t v = 0; v < g_rig.low_res_camera().height_px; ++v) {
    Eigen::Vector3f a;
    Eigen::Vector3f b;
    if (!floor_seen_at(pose, static_cast<float>(first), static_cast<float>(v), a) ||
        !floor_seen_at(pose, static_cast<float>(last), static_cast<float>(v), b)) {
      continue;
    }
    const float rho_a = std::hypot(a.x(), a.y());
    const float rho_b = std::hypot(b.x(), b.y());
    if (std::min(rho_a, rho_b) < p.reference_min_m || std::max(rho_a, rho_b) > p.reference_max_m) {
      continue;
    }
    longest = std::max(longest, (b - a).norm());
  }
  return longest;
}

// A textured model's longest run against a band of one tone over columns first..last: the
// band's stretch on the floor is longer than the stripes' runs (a pixel's step, under 0.02 m),
// and the model's run lies between half of it and all of it, each times texture_run_factor.
void check_max_run_against_band(const FloorCue& cue, const FloorCueParams& p, std::uint32_t first,
                                std::uint32_t last) {
  const float longest = longest_band_m(p, first, last);
  CHECK(longest > 0.08F);
  const float max_run = cue.model().max_run_m;
  CHECK(max_run >= p.texture_run_factor * 0.5F * longest);
  CHECK(max_run <= p.texture_run_factor * (longest + 0.01F));
}

}  // namespace

// The longest run of one colour a textured floor shows is texture_run_factor times the 95th
// percentile of the region's runs weighted by their length: a region of 2 px stripes with a
// band of one tone over a quarter of its width has its percentile within the band's runs.
TEST(FloorCue, ATexturesLongestRunIsThe95thPercentileOfItsRunsByLength) {
  FloorCueParams p = trusting();
  p.vignetting = 0.0F;
  p.texture_run_min_m = 0.0F;  // no clamp: the percentile itself
  p.texture_run_max_m = 10.0F;
  static FloorCue fresh{g_rig, p};
  fresh.reset();
  const boticelli::stereo::CameraIntrinsics& camera = g_rig.low_res_camera();
  const std::uint32_t band = camera.width_px * 3 / 4;  // the band: columns band..width − 1
  paint(g_frame, [&](std::uint32_t u, std::uint32_t) {
    const float y = u >= band ? 180.0F : ((u / 2) % 2 == 0 ? 60.0F : 120.0F);
    return std::array<float, 3>{y, 0.0F, 0.0F};
  });
  CHECK(FloorLearn::kLearned == fresh.learn(g_frame, 0.0F, kLookTilt));
  CHECK(fresh.model().textured);
  check_max_run_against_band(fresh, p, band, camera.width_px - 1);
}

// A walk samples the two pixels either side of it, also at the image's right edge: a thing
// two pixels wide along the right edge ends the last column's walk.
TEST(FloorCue, AThingAlongTheImagesRightEdgeEndsTheLastColumnsWalk) {
  FloorCueParams p = trusting();
  p.vignetting = 0.0F;
  p.column_step = 1;
  static FloorCue fresh{g_rig, p};
  fresh.reset();
  const std::uint32_t width = g_rig.low_res_camera().width_px;
  paint(g_frame, [&](std::uint32_t u, std::uint32_t) {
    return std::array<float, 3>{u + 2 >= width ? 220.0F : 120.0F, 0.0F, 0.0F};
  });
  CHECK(FloorLearn::kLearned == fresh.learn(g_frame, 0.0F, kLookTilt));
  out.obstacles.clear();
  out.free.clear();
  out.result = fresh.process(g_frame, 0.0F, kLookTilt, out.obstacles, out.free);
  CHECK_EQUAL(width, fresh.column_count());
  const FloorColumn& last = fresh.column(width - 1);
  CHECK_EQUAL(width - 1, last.u_px);
  CHECK(last.end == FloorColumn::End::kBoundary || last.end == FloorColumn::End::kBlockedAtBottom);
  CHECK(fresh.column(width / 2).end == FloorColumn::End::kMaxRange);
}

// A boundary's base lies half a step (in elevation along the walk) beyond the last floor
// sample, which is the free reading: between it and the first sample that is not floor.
TEST(FloorCue, ABoundarysBaseIsHalfAStepBeyondTheLastFloorSample) {
  FloorCueParams p = trusting();
  p.vignetting = 0.0F;
  static FloorCue fresh{g_rig, p};
  fresh.reset();
  const boticelli::stereo::CameraIntrinsics& camera = g_rig.low_res_camera();
  // A wall across the image from its 45th row up; floor below.
  paint_wall(g_frame);
  CHECK(FloorLearn::kLearned == fresh.learn(g_frame, 0.0F, kLookTilt));
  out.obstacles.clear();
  out.free.clear();
  out.result = fresh.process(g_frame, 0.0F, kLookTilt, out.obstacles, out.free);
  const boticelli::stereo::CameraPose pose = g_rig.camera_pose(0.0F, kLookTilt);
  const Eigen::Vector3f c = pose.centre_m;
  const float drop = c.z() + g_rig.params().ptu_height_m;  // the camera above the floor [m]
  // The elevation [rad] of the line of sight along the walk's azimuth to the floor at ρ.
  const auto elevation_of = [&](float azimuth, float rho) {
    const float along = c.x() * std::cos(azimuth) + c.y() * std::sin(azimuth);
    const float s = -along + std::sqrt(along * along - c.x() * c.x() - c.y() * c.y() + rho * rho);
    return -std::atan(drop / s);
  };
  const float step = 1.0F / camera.focal_px;
  std::size_t checked = 0;
  for (std::size_t i = 0; i < fresh.column_count(); ++i) {
    const FloorColumn& col = fresh.column(i);
    if (col.end != FloorColumn::End::kBoundary || col.free_rho_m <= 0.0F) continue;
    const float apart = elevation_of(col.azimuth_rad, col.base_rho_m) -
                        elevation_of(col.azimuth_rad, col.free_rho_m);
    DOUBLES_EQUAL(0.5F * step, apart, 0.05F * step);
    ++checked;
  }
  CHECK(checked >= 60U);
}

// A textured floor's luma change (its model's luma tolerance) is half the median step between
// row neighbours that differ by more than the luma minimum: stripes of 20 and 230 step by 210.
TEST(FloorCue, ATexturesLumaChangeIsHalfTheMedianStepBetweenNeighbours) {
  const FloorCueParams flat = flat_trusting();
  static FloorCue fresh{g_rig, flat};
  fresh.reset();
  paint(g_frame, [](std::uint32_t u, std::uint32_t) {
    return std::array<float, 3>{(u / 2) % 2 == 0 ? 20.0F : 230.0F, 0.0F, 0.0F};
  });
  CHECK(FloorLearn::kLearned == fresh.learn(g_frame, 0.0F, kLookTilt));
  CHECK(fresh.model().textured);
  DOUBLES_EQUAL(105.0, fresh.model().tolerance[0], 1e-4);
  DOUBLES_EQUAL(flat.min_tolerance_chroma, fresh.model().tolerance[1], 1e-6);
  DOUBLES_EQUAL(flat.min_tolerance_chroma, fresh.model().tolerance[2], 1e-6);
}

// Between weak and clear, a boundary's evidence follows its contrast linearly: a wall 1.75
// tolerances from the floor (half way from 1 to clear_contrast = 2.5) has evidence half way
// from evidence_weak to evidence_clear.
TEST(FloorCue, ABoundaryHalfWayToClearContrastHasEvidenceHalfWayToClear) {
  FloorCueParams p = trusting();
  p.vignetting = 0.0F;
  static FloorCue fresh{g_rig, p};
  fresh.reset();
  paint(g_frame, [&](std::uint32_t, std::uint32_t v) {
    return std::array<float, 3>{v < 45 ? 120.0F + 1.75F * p.min_tolerance_luma : 120.0F, 0.0F,
                                0.0F};
  });
  CHECK(FloorLearn::kLearned == fresh.learn(g_frame, 0.0F, kLookTilt));
  DOUBLES_EQUAL(p.min_tolerance_luma, fresh.model().tolerance[0], 1e-6);
  out.obstacles.clear();
  out.free.clear();
  out.result = fresh.process(g_frame, 0.0F, kLookTilt, out.obstacles, out.free);
  CHECK(out.result.boundaries >= 60U);
  for (std::size_t i = 0; i < fresh.column_count(); ++i) {
    if (fresh.column(i).end != FloorColumn::End::kBoundary) continue;
    DOUBLES_EQUAL(0.5F * (p.evidence_weak + p.evidence_clear), fresh.column(i).evidence, 1e-4);
  }
  for (const Reading& r : out.obstacles) {
    DOUBLES_EQUAL(0.5F * (p.evidence_weak + p.evidence_clear), r.m, 1e-4);
  }
}

// Tiles of two colours, one of them on at least half the floor: the median absolute deviation
// is 0 (half the pixels have the median), so the region's median and spread say one colour,
// though much of it is the other. It is learned as a texture, and all of it is floor.
TEST(FloorCue, AFloorOfTwoColoursOneOnHalfOfItIsLearnedAsATexture) {
  const FloorCueParams flat = flat_trusting();
  static FloorCue fresh{g_rig, flat};
  for (const auto& tones : {std::initializer_list<float>{60.0F, 200.0F},
                            std::initializer_list<float>{60.0F, 60.0F, 200.0F}}) {
    fresh.reset();
    fill_patches(g_frame, tones);
    CHECK(FloorLearn::kLearned == fresh.learn(g_frame, 0.0F, kLookTilt));
    CHECK(fresh.model().textured);
    out.obstacles.clear();
    out.free.clear();
    out.result = fresh.process(g_frame, 0.0F, kLookTilt, out.obstacles, out.free);
    CHECK_EQUAL(0U, out.result.boundaries);
    CHECK_EQUAL(out.result.columns, out.free.size());
  }
}

// The coverage is the image's centre column's: its bottom row's floor point is the near end,
// its top row's the far end.
TEST(FloorCue, CoverageIsWhatTheCentreColumnsBottomAndTopRowsSeeOfTheFloor) {
  const boticelli::stereo::CameraIntrinsics& camera = g_rig.low_res_camera();
  const boticelli::stereo::CameraPose pose = g_rig.camera_pose(0.0F, -0.6F);
  float near_m = 0.0F;
  float far_m = 0.0F;
  CHECK(cue.floor_coverage(-0.6F, near_m, far_m));
  Eigen::Vector3f bottom;
  Eigen::Vector3f top;
  const auto u = static_cast<float>(camera.width_px / 2);
  CHECK(floor_seen_at(pose, u, static_cast<float>(camera.height_px - 1), bottom));
  CHECK(floor_seen_at(pose, u, 0.0F, top));
  DOUBLES_EQUAL(std::hypot(bottom.x(), bottom.y()), near_m, 1e-4);
  DOUBLES_EQUAL(std::hypot(top.x(), top.y()), far_m, 1e-3);
}

// A region that differs from the known floor by more than its tolerances (here 1.5 of them in
// luma) is not the floor: it does not update the model.
TEST(FloorCue, ARegionOneAndAHalfTolerancesFromTheKnownFloorIsInconsistent) {
  const FloorCueParams flat = flat_trusting();
  static FloorCue fresh{g_rig, flat};
  learned_on_flat_floor(fresh);
  fill_patches(g_frame, {120.0F + 1.5F * flat.min_tolerance_luma});
  CHECK(FloorLearn::kInconsistent == fresh.learn(g_frame, 0.0F, kLookTilt));
  DOUBLES_EQUAL(120.0, fresh.model().median[0], 1e-6);
  fill_patches(g_frame, {120.0F + 0.5F * flat.min_tolerance_luma});
  CHECK(FloorLearn::kUpdated == fresh.learn(g_frame, 0.0F, kLookTilt));
}

namespace {

// `params` with regions 1 rad apart confirming each other.
FloorCueParams confirming_across_1_rad(FloorCueParams params) {
  params.confirm_separation_rad = 1.0F;
  return params;
}

// `params` trusting its first region, with updates moving the model a quarter of the way.
FloorCueParams updating_by_a_quarter(FloorCueParams params) {
  params.confirm_separation_rad = 0.0F;
  params.learn_rate = 0.25F;
  return params;
}

// g_frame learned alone by `one`, g_frame2 alone by `other`, and both by `both` from pans
// 1.8 rad apart: pending after the first and learned after the second if `both` waits for a
// second direction, else learned from the first and updated by the second.
void learn_apart_and_together(FloorCue& one, FloorCue& other, FloorCue& both) {
  one.reset();
  other.reset();
  both.reset();
  CHECK(FloorLearn::kLearned == one.learn(g_frame, 0.0F, kLookTilt));
  CHECK(FloorLearn::kLearned == other.learn(g_frame2, 0.0F, kLookTilt));
  const bool confirms = both.params().confirm_separation_rad > 0.0F;
  CHECK((confirms ? FloorLearn::kPending : FloorLearn::kLearned) ==
        both.learn(g_frame, 0.0F, kLookTilt));
  CHECK((confirms ? FloorLearn::kLearned : FloorLearn::kUpdated) ==
        both.learn(g_frame2, 1.8F, kLookTilt));
}

}  // namespace

namespace {

// Two textured regions of the same colours in different proportions learned apart by cues
// trusting their first region, and both by `both` (learn_apart_and_together): its model is
// textured, and its histogram, bin by bin, and the bins' shares lie the fraction `w` of the
// way from the first region's to the second's.
void check_textured_model_between(FloorCue& both, float w) {
  fill_patches(g_frame, {40.0F, 100.0F, 160.0F, 220.0F});
  fill_patches(g_frame2, {40.0F, 40.0F, 100.0F, 160.0F, 220.0F});
  static FloorCue one{g_rig, flat_trusting()};
  static FloorCue other{g_rig, flat_trusting()};
  learn_apart_and_together(one, other, both);
  CHECK(both.model().textured);
  const auto between = [w](float from, float to) { return from + w * (to - from); };
  double apart = 0.0;
  for (std::size_t b = 0; b < boticelli::stereo::kFloorBins; ++b) {
    apart += std::fabs(static_cast<double>(other.model().mass[b] - one.model().mass[b]));
    DOUBLES_EQUAL(between(one.model().mass[b], other.model().mass[b]), both.model().mass[b], 1e-6);
    DOUBLES_EQUAL(between(one.model().share[b], other.model().share[b]), both.model().share[b],
                  1e-5);
  }
  CHECK(apart > 0.1);  // the two regions' histograms differ
}

}  // namespace

// Two textured regions of the same colours in different proportions confirm a model whose
// histogram is their average, bin by bin.
TEST(FloorCue, TwoTexturedRegionsConfirmAModelWithTheAverageOfTheirHistograms) {
  static FloorCue both{g_rig, confirming_across_1_rad(flat_trusting())};
  check_textured_model_between(both, 0.5F);
}

// A plain floor's update moves its tolerances by the learning rate too: a region of the
// model's own colour and spread leaves them as they were.
TEST(FloorCue, AnUpdateByARegionLikeThePlainFloorKeepsItsTolerances) {
  static FloorCue fresh{g_rig, flat_trusting()};
  learned_on_flat_floor(fresh);
  const std::array<float, 3> tolerance = fresh.model().tolerance;
  CHECK(FloorLearn::kUpdated == fresh.learn(g_frame, 0.0F, kLookTilt));
  for (std::size_t c = 0; c < 3; ++c) {
    DOUBLES_EQUAL(tolerance[c], fresh.model().tolerance[c], 1e-6);
  }
}

// Every process() call's columns are its own: a walk to max range says nothing of a base seen
// by the same column in the frame before.
TEST(FloorCue, AColumnKeepsNothingFromTheFrameBefore) {
  static FloorCue fresh{g_rig, flat_trusting()};
  learned_on_flat_floor(fresh);
  out.obstacles.clear();
  out.free.clear();
  out.result = fresh.process(g_frame2, 0.0F, kLookTilt, out.obstacles, out.free);
  CHECK(out.result.boundaries >= 60U);
  out.result = fresh.process(g_frame, 0.0F, kLookTilt, out.obstacles, out.free);
  CHECK_EQUAL(0U, out.result.boundaries);
  for (std::size_t i = 0; i < fresh.column_count(); ++i) {
    CHECK(fresh.column(i).end == FloorColumn::End::kMaxRange);
    DOUBLES_EQUAL(0.0, fresh.column(i).base_rho_m, 0.0);
    DOUBLES_EQUAL(0.0, fresh.column(i).evidence, 0.0);
  }
}

// Along a walk on a textured floor, two shades exactly the luma change apart are one colour
// (the tolerance holds its bound): rows alternating between them are one plain stretch, which
// ends the free floor within the floor's longest run.
TEST(FloorCue, ShadesExactlyTheLumaChangeApartAreOneColourAlongAWalk) {
  const FloorCueParams flat = flat_trusting();
  static FloorCue fresh{g_rig, flat};
  fresh.reset();
  fill_patches(g_frame, {40.0F, 60.0F, 80.0F, 100.0F, 120.0F, 140.0F});
  CHECK(FloorLearn::kLearned == fresh.learn(g_frame, 0.0F, kLookTilt));
  CHECK(fresh.model().textured);
  const float change = fresh.model().tolerance[0];
  DOUBLES_EQUAL(10.0, change, 1e-6);  // half the 20-level steps between the patches
  paint(g_frame2, [&](std::uint32_t, std::uint32_t v) {
    return std::array<float, 3>{v % 2 == 0 ? 96.0F : 96.0F + change, 0.0F, 0.0F};
  });
  out.obstacles.clear();
  out.free.clear();
  out.result = fresh.process(g_frame2, 0.0F, kLookTilt, out.obstacles, out.free);
  CHECK_EQUAL(0U, out.result.obstacle_readings);
  for (std::size_t i = 0; i < fresh.column_count(); ++i) {
    CHECK(fresh.column(i).end != FloorColumn::End::kMaxRange);
  }
}

// The calibration self-check on rendered pairs: where the floor cue finds an obstacle's base,
// the stereo's points low on it are as far along the walk's plane, the ratio's median is 1;
// frames drawn through a lens whose focal length is longer than configured scale the stereo's
// distances and not the floor's, and the median shows it. The look's inverse-range bias
// removed from the stereo (its self-calibration), the same look agrees with the floor again,
// for a focal length off and for a tilt step off. Prints the medians.
TEST(FloorCue, TheRangeCheckFindsStereoAndFloorAgreeingAndAFocalLengthOffDisagreeing) {
  // Walls and a box wearing camouflage (the shipped worlds' walls do): texture for the stereo.
  const auto textured = [](const char* name, const char* pose, const char* size, int seed) {
    return std::string("<model name=\"") + name + "\"><pose>" + pose +
           " 0 0 0</pose><link name=\"l\"><visual name=\"v\"><geometry><box><size>" + size +
           "</size></box></geometry><material><diffuse>0.7 0.7 0.65 1</diffuse></material>"
           "<boticelli:pattern scale=\"0.1\" seed=\"" +
           std::to_string(seed) + "\">camouflage</boticelli:pattern></visual></link></model>\n";
  };
  load(textured("wall", "2.4 0 0.6", "0.1 8 1.2", 3) +
       textured("left", "0 2.2 0.6", "8 0.1 1.2", 4) +
       textured("right", "0 -2.0 0.6", "8 0.1 1.2", 5) +
       textured("box", "1.2 0.9 0.25", "0.4 0.4 0.5", 6));
  static FixedVector<Reading, 4096> readings;
  static boticelli::stereo::StereoProcessor stereo_processor{
      g_rig, boticelli::firmware::mission::make_mission_params(board::make_config()).stereo};
  static boticelli::stereo::RangeCheck check{g_rig};
  // The frames drawn through the true camera (its focal length scaled, k1 moved) and with the
  // second frame's tilt off by `phi_error`; the stereo and the floor cue use g_rig's.
  // With `bias`, also the look's inverse-range bias (RangeCheck::inverse_bias).
  const auto look_ratio = [&](float focal_scale, float k1_error, float phi_error,
                              float* bias = nullptr) {
    boticelli::stereo::CameraIntrinsics truth = g_rig.camera();
    truth.focal_px *= focal_scale;
    truth.k1 += k1_error;
    const board::SimSettings settings = board::make_settings(board::make_config(), 3);
    sim::Renderer renderer;  // local: its buffers are freed with the lambda's call
    CHECK_TEXT(renderer.init(g_scene.world, g_scene.textures, truth, settings.render, g_error,
                             sizeof g_error),
               g_error);
    static FloorCue fresh{g_rig, trusting()};
    fresh.reset();
    check.begin_look();
    std::uint32_t frame_index = 1;
    const auto draw = [&](float pan, float tilt, LowResFrame& into) {
      renderer.render(camera_in_world(pan, tilt), frame_index++, g_yuyv.data(), 640U * 2U, nullptr);
      CHECK(boticelli::image::downsample_yuyv(g_yuyv.data(), 640, 480, 640 * 2, 4, into));
    };
    const float phi = g_rig.params().tilt_step_rad;
    for (const float pan : {-1.2F, -0.6F, 0.0F, 0.6F, 1.2F}) {
      boticelli::stereo::PairPose pose{pan, kLookTilt, kLookTilt - phi};
      draw(pan, kLookTilt, g_frame);
      draw(pan, kLookTilt - phi - phi_error, g_frame2);
      readings.clear();
      (void)stereo_processor.process(g_frame, g_frame2, pose, readings);
      (void)fresh.learn(g_frame, pan, kLookTilt);
      out.obstacles.clear();
      out.free.clear();
      (void)fresh.process(g_frame, pan, kLookTilt, out.obstacles, out.free);
      (void)check.add_view(fresh, pan, kLookTilt, stereo_processor.points().data(),
                           stereo_processor.points().size());
    }
    float ratio = 0.0F;
    std::size_t n = 0;
    CHECK(check.median(ratio, n));
    std::printf(
        "\n  focal x%.3f, k1 %+.2f, phi %+.4f rad: stereo / floor distance at bases %.3f "
        "(%zu ratios)",
        static_cast<double>(focal_scale), static_cast<double>(k1_error),
        static_cast<double>(phi_error), static_cast<double>(ratio), n);
    CHECK(n >= 5U);
    if (bias != nullptr) CHECK(check.inverse_bias(*bias, n));
    return ratio;
  };
  float bias_long = 0.0F;
  float bias_short = 0.0F;
  float bias_step = 0.0F;
  stereo_processor.set_inverse_range_bias(0.0F);
  DOUBLES_EQUAL(1.0, look_ratio(1.0F, 0.0F, 0.0F), 0.02);
  CHECK(look_ratio(1.01F, 0.0F, 0.0F, &bias_long) < 0.97F);         // focal length 1 % long
  CHECK(look_ratio(0.99F, 0.0F, 0.0F, &bias_short) > 1.03F);        // 1 % short
  CHECK(std::fabs(look_ratio(1.0F, -0.15F, 0.0F) - 1.0F) > 0.03F);  // a lens nobody calibrated
  CHECK(std::fabs(look_ratio(1.0F, 0.0F, 0.0035F, &bias_step) - 1.0F) > 0.03F);  // step 0.2° off
  // Self-calibration: the bias the look measured removed, the look is drawn and read again.
  // The bias each error leaves is that error's own (bias_as_focal_scale, …_tilt_step_error_rad).
  const auto calibrated_ratio = [&](float focal_scale, float phi_error, float bias) {
    if (phi_error == 0.0F) {
      DOUBLES_EQUAL(focal_scale, boticelli::stereo::bias_as_focal_scale(bias, g_rig.params()),
                    0.004);
    } else {
      DOUBLES_EQUAL(phi_error, boticelli::stereo::bias_as_tilt_step_error_rad(bias, g_rig.params()),
                    0.0005);
    }
    stereo_processor.set_inverse_range_bias(bias);
    const float ratio = look_ratio(focal_scale, 0.0F, phi_error);
    std::printf(" after removing %.4f /m", static_cast<double>(bias));
    stereo_processor.set_inverse_range_bias(0.0F);
    return ratio;
  };
  DOUBLES_EQUAL(1.0, calibrated_ratio(1.01F, 0.0F, bias_long), 0.01);
  DOUBLES_EQUAL(1.0, calibrated_ratio(0.99F, 0.0F, bias_short), 0.01);
  DOUBLES_EQUAL(1.0, calibrated_ratio(1.0F, 0.0035F, bias_step), 0.01);
}

// One walk of a learned flat floor up to a painted wall, the column in the middle of the frame
// (the cue is left with the frame processed into `out`, for RangeCheck::add_view): the optical
// centre's position on the floor c, the walk's direction a, the base's distance along it from
// c, and the floor's height, PTU frame.
struct WalkToAWall {
  boticelli::stereo::CameraPose pose;
  Eigen::Vector2f c = Eigen::Vector2f::Zero();
  Eigen::Vector2f a = Eigen::Vector2f::Zero();
  float s_base_m = 0.0F;
  float floor_z_m = 0.0F;
};
WalkToAWall walk_to_a_wall(FloorCue& cue, Outputs& out) {
  cue.reset();
  paint_wall(g_frame);
  CHECK(FloorLearn::kLearned == cue.learn(g_frame, 0.0F, kLookTilt));
  out.obstacles.clear();
  out.free.clear();
  out.result = cue.process(g_frame, 0.0F, kLookTilt, out.obstacles, out.free);
  const FloorColumn& col = cue.column(cue.column_count() / 2);
  CHECK(col.end == FloorColumn::End::kBoundary);
  WalkToAWall w;
  w.pose = g_rig.camera_pose(0.0F, kLookTilt);
  w.c = Eigen::Vector2f(w.pose.centre_m.x(), w.pose.centre_m.y());
  w.a = Eigen::Vector2f(std::cos(col.azimuth_rad), std::sin(col.azimuth_rad));
  const float along = w.c.dot(w.a);
  w.s_base_m =
      -along + std::sqrt(along * along - w.c.squaredNorm() + col.base_rho_m * col.base_rho_m);
  w.floor_z_m = -g_rig.params().ptu_height_m;
  return w;
}

// The range check taking the plane of the walk_to_a_wall column alone (the next is 2 px away).
boticelli::stereo::RangeCheckParams one_plane() {
  boticelli::stereo::RangeCheckParams p;
  p.lateral_m = 0.001F;
  p.lateral_per_m = 0.0F;
  return p;
}

// The inverse-range bias of the check's pairs: points low on an obstacle, each on the camera's
// line of sight to a point of the base's vertical plane but read with 1/r̂ = 1/r + b, give b
// back exactly (the ratio along the plane is r̂/r on a ray from the optical centre).
TEST(FloorCue, TheRangeChecksInverseBiasIsWhatAStereoBiasAddsToEveryInverseRange) {
  static FloorCue fresh{g_rig, flat_trusting()};
  const WalkToAWall w = walk_to_a_wall(fresh, out);
  const auto read = [&](float height, float bias_per_m) {
    const Eigen::Vector2f xy = w.c + w.s_base_m * w.a;
    const Eigen::Vector3f truth(xy.x(), xy.y(), w.floor_z_m + height);
    const Eigen::Vector3f ray = truth - w.pose.centre_m;
    const float r = ray.norm();
    boticelli::stereo::StereoPoint p;
    p.point_ptu_m = w.pose.centre_m + ray * (1.0F / (1.0F / r + bias_per_m)) / r;
    return p;
  };
  constexpr float kBias = 0.12F;  // about a focal length 1 % long [1/m]
  const std::array<boticelli::stereo::StereoPoint, 5> points{read(0.05F, kBias), read(0.15F, kBias),
                                                             read(0.25F, kBias), read(0.1F, 0.3F),
                                                             read(0.2F, -0.05F)};
  boticelli::stereo::RangeCheck check{g_rig, one_plane()};
  check.begin_look();
  CHECK_EQUAL(5U, check.add_view(fresh, 0.0F, kLookTilt, points.data(), points.size()));
  float bias = 0.0F;
  std::size_t n = 0;
  CHECK(check.inverse_bias(bias, n));
  CHECK_EQUAL(5U, n);
  DOUBLES_EQUAL(kBias, bias, 1e-4);
  float ratio = 0.0F;
  CHECK(check.median(ratio, n));
  CHECK(ratio < 0.9F);  // read nearer than the base
  check.begin_look();
  CHECK_FALSE(check.inverse_bias(bias, n));
}

// The self-calibration's step: the look's residual added to the bias in use, from enough pairs,
// within its bound, and none as small as a calibrated rig's; nothing when it is off.
TEST(FloorCue, TheSelfCalibrationAddsALooksResidualFromEnoughPairsWithinItsBound) {
  boticelli::stereo::StereoParams p;
  p.self_calibration_min_pairs = 30;
  p.self_calibration_max_bias_per_m = 0.5F;
  p.self_calibration_min_bias_per_m = 0.025F;
  using boticelli::stereo::updated_inverse_bias;
  DOUBLES_EQUAL(0.15, updated_inverse_bias(0.1F, 0.05F, 30, p), 1e-6);
  DOUBLES_EQUAL(0.05, updated_inverse_bias(0.1F, -0.05F, 500, p), 1e-6);
  DOUBLES_EQUAL(0.1, updated_inverse_bias(0.1F, 0.05F, 29, p), 1e-6);  // too few pairs
  DOUBLES_EQUAL(0.5, updated_inverse_bias(0.4F, 0.3F, 30, p), 1e-6);   // held to the bound
  DOUBLES_EQUAL(-0.5, updated_inverse_bias(-0.4F, -0.3F, 30, p), 1e-6);
  DOUBLES_EQUAL(0.0, updated_inverse_bias(0.0F, 0.024F, 30, p), 1e-6);  // a calibrated rig's
  DOUBLES_EQUAL(0.0, updated_inverse_bias(0.05F, -0.03F, 30, p), 1e-6);
  DOUBLES_EQUAL(-0.025, updated_inverse_bias(0.0F, -0.025F, 30, p), 1e-6);
  p.self_calibration = false;
  DOUBLES_EQUAL(0.1, updated_inverse_bias(0.1F, 0.05F, 500, p), 1e-6);
}

// The range check's rules on one walk: only points low on the obstacle (3 cm to 0.5 m above the
// floor), in the walk's plane, and within [0.6, 1.6] of the base's distance count, and the
// look's figure is their median.
TEST(FloorCue, TheRangeCheckCountsLowPointsInTheWalksPlaneAndTakesTheirMedian) {
  static FloorCue fresh{g_rig, flat_trusting()};
  const WalkToAWall w = walk_to_a_wall(fresh, out);
  // Points along the column's plane at given shares of the base's distance along it.
  const Eigen::Vector2f side(-w.a.y(), w.a.x());
  const auto at = [&](float share, float height, float aside) {
    boticelli::stereo::StereoPoint p;
    const Eigen::Vector2f xy = w.c + share * w.s_base_m * w.a + aside * side;
    p.point_ptu_m = Eigen::Vector3f(xy.x(), xy.y(), w.floor_z_m + height);
    return p;
  };
  const std::array<boticelli::stereo::StereoPoint, 9> points{
      at(0.8F, 0.2F, 0.0F),   at(0.95F, 0.1F, 0.0F), at(1.0F, 0.3F, 0.0F),
      at(1.05F, 0.45F, 0.0F), at(1.3F, 0.2F, 0.0F),  // counted: median 1.0
      at(1.0F, 0.8F, 0.0F),                          // too high on the obstacle
      at(1.0F, 0.01F, 0.0F),                         // on the floor
      at(1.0F, 0.2F, 0.3F),                          // beside the walk's plane
      at(2.0F, 0.2F, 0.0F)};                         // another object, far behind
  boticelli::stereo::RangeCheck check{g_rig, one_plane()};
  check.begin_look();
  CHECK_EQUAL(5U, check.add_view(fresh, 0.0F, kLookTilt, points.data(), points.size()));
  float ratio = 0.0F;
  std::size_t n = 0;
  CHECK(check.median(ratio, n));
  CHECK_EQUAL(5U, n);
  DOUBLES_EQUAL(1.0, ratio, 1e-4);
  check.begin_look();
  CHECK_FALSE(check.median(ratio, n));
  CHECK_EQUAL(0U, n);
}

// The floor test's public query says no without a model (nothing is floor before it is known)
// and for a pixel outside the frame; with a model, a pixel of the floor's colour is floor.
TEST(FloorCue, WithoutAModelOrOutsideTheFrameNoPixelLooksLikeFloor) {
  const FloorCueParams flat = flat_trusting();
  static FloorCue fresh{g_rig, flat};
  fresh.reset();
  fill_patches(g_frame, {120.0F});
  float contrast = 0.0F;
  CHECK_FALSE(fresh.looks_like_floor(g_frame, g_frame.width / 2, g_frame.height / 2, contrast));
  CHECK(FloorLearn::kLearned == fresh.learn(g_frame, 0.0F, kLookTilt));
  CHECK(fresh.looks_like_floor(g_frame, g_frame.width / 2, g_frame.height / 2, contrast));
  CHECK_FALSE(fresh.looks_like_floor(g_frame, g_frame.width, g_frame.height / 2, contrast));
  CHECK_FALSE(fresh.looks_like_floor(g_frame, g_frame.width / 2, g_frame.height, contrast));
}

namespace {

// Two plain floors of unlike spreads: luma 120 ± 2 and Cb 0 in g_frame, luma 126 ± 4 and
// Cb 0 ± 1 in g_frame2 (−1, 0 and +1 times the spread on a third of the pixels each: robust
// spreads of 2 and 4, and of 0 and 1, levels).
void paint_unlike_spreads() {
  const auto spread = [](LowResFrame& frame, float y, float dy, float dcb) {
    paint(frame, [=](std::uint32_t u, std::uint32_t v) {
      const auto k = static_cast<float>((u + v) % 3) - 1.0F;  // −1, 0, +1 in thirds
      return std::array<float, 3>{y + k * dy, k * dcb, 0.0F};
    });
  };
  spread(g_frame, 120.0F, 2.0F, 0.0F);
  spread(g_frame2, 126.0F, 4.0F, 1.0F);
}

// The two plain floors of unlike spreads learned apart by cues trusting their first region,
// and both by `both` (learn_apart_and_together): its model is plain, and its median and
// tolerance in every channel lie the fraction `w` of the way from the first floor's to the
// second's.
void check_plain_model_between(FloorCue& both, float w) {
  paint_unlike_spreads();
  static FloorCue one{g_rig, flat_trusting()};
  static FloorCue other{g_rig, flat_trusting()};
  learn_apart_and_together(one, other, both);
  CHECK_FALSE(both.model().textured);
  CHECK(other.model().tolerance[0] > one.model().tolerance[0] + 5.0F);  // the spreads differ
  CHECK(other.model().tolerance[1] > one.model().tolerance[1] + 0.5F);
  const auto between = [w](float from, float to) { return from + w * (to - from); };
  for (std::size_t c = 0; c < 3; ++c) {
    DOUBLES_EQUAL(between(one.model().median[c], other.model().median[c]), both.model().median[c],
                  1e-4);
    DOUBLES_EQUAL(between(one.model().tolerance[c], other.model().tolerance[c]),
                  both.model().tolerance[c], 1e-4);
  }
}

}  // namespace

// A plain floor's model from two agreeing regions is their mean: the median and the tolerance
// of every channel half way between the two regions' own, here of unlike spreads (luma 120 ± 2
// and 126 ± 4, Cb 0 and 0 ± 1: robust spreads of 2 and 4, and of 0 and 1, levels).
TEST(FloorCue, TwoPlainRegionsConfirmAModelWithTheMeanOfTheirMediansAndTolerances) {
  static FloorCue both{g_rig, confirming_across_1_rad(flat_trusting())};
  check_plain_model_between(both, 0.5F);
}

// A textured model from two agreeing regions has the mean of their longest runs: a region of
// fine stripes of three tones and one of the same stripes with a band of one of them.
TEST(FloorCue, TwoTexturedRegionsConfirmAModelWithTheMeanOfTheirLongestRuns) {
  FloorCueParams p = flat_trusting();
  p.texture_run_min_m = 0.0F;  // no clamp: the regions' own
  p.texture_run_max_m = 10.0F;
  const std::uint32_t band = g_rig.low_res_camera().width_px * 3 / 4;
  const auto stripes = [](std::uint32_t u) {
    return 60.0F + 60.0F * static_cast<float>((u / 2) % 3);
  };
  paint(g_frame, [&](std::uint32_t u, std::uint32_t) {
    return std::array<float, 3>{stripes(u), 0.0F, 0.0F};
  });
  paint(g_frame2, [&](std::uint32_t u, std::uint32_t) {
    return std::array<float, 3>{u >= band ? 180.0F : stripes(u), 0.0F, 0.0F};
  });
  static FloorCue one{g_rig, p};
  static FloorCue other{g_rig, p};
  static FloorCue both{g_rig, confirming_across_1_rad(p)};
  learn_apart_and_together(one, other, both);
  CHECK(one.model().textured);
  CHECK(other.model().textured);
  CHECK(other.model().max_run_m > one.model().max_run_m + 0.1F);  // the band's runs
  CHECK(both.model().textured);
  DOUBLES_EQUAL(0.5F * (one.model().max_run_m + other.model().max_run_m), both.model().max_run_m,
                1e-5);
  for (std::size_t c = 0; c < 3; ++c) {
    DOUBLES_EQUAL(0.5F * (one.model().tolerance[c] + other.model().tolerance[c]),
                  both.model().tolerance[c], 1e-5);
  }
}

// A pixel exactly one tolerance from the region's median is within it: a region of luma 120
// on more than half of it (no spread: the luma minimum applies) and 130 elsewhere is one plain
// surface, learned without textures, and its 130 is floor.
TEST(FloorCue, PixelsExactlyOneToleranceFromARegionsMedianAreItsOwnFloor) {
  FloorCueParams p = flat_trusting();
  p.textured = false;
  static FloorCue fresh{g_rig, p};
  fresh.reset();
  paint(g_frame, [&](std::uint32_t u, std::uint32_t) {
    return std::array<float, 3>{u % 5 < 3 ? 120.0F : 120.0F + p.min_tolerance_luma, 0.0F, 0.0F};
  });
  CHECK(FloorLearn::kLearned == fresh.learn(g_frame, 0.0F, kLookTilt));
  DOUBLES_EQUAL(120.0, fresh.model().median[0], 1e-6);
  DOUBLES_EQUAL(p.min_tolerance_luma, fresh.model().tolerance[0], 1e-6);
  float contrast = 0.0F;
  CHECK(fresh.looks_like_floor(g_frame, 4, g_frame.height - 1, contrast));
  DOUBLES_EQUAL(1.0, contrast, 1e-6);
}

// A waiting region confirms the floor when the needed share of a later region agrees with it,
// that share included: with consistency_min = 1, two plain regions alike in every pixel.
TEST(FloorCue, AWaitingRegionAgreeingInExactlyTheNeededShareConfirmsTheFloor) {
  FloorCueParams p = flat_trusting();
  p.confirm_separation_rad = 1.0F;
  p.consistency_min = 1.0F;
  static FloorCue fresh{g_rig, p};
  fresh.reset();
  fill_patches(g_frame, {120.0F});
  CHECK(FloorLearn::kPending == fresh.learn(g_frame, 0.0F, kLookTilt));
  CHECK(FloorLearn::kLearned == fresh.learn(g_frame, 1.8F, kLookTilt));
  CHECK(fresh.model().valid);
}

// A row's first run counts from the row's first pixel like any other: a band of one tone along
// the image's left edge, where the region's rows begin, gives the texture's longest run.
TEST(FloorCue, ARunAtTheStartOfTheRegionsRowsIsMeasuredLikeAnyOther) {
  FloorCueParams p = flat_trusting();
  p.texture_run_min_m = 0.0F;  // no clamp: the percentile itself
  p.texture_run_max_m = 10.0F;
  static FloorCue fresh{g_rig, p};
  fresh.reset();
  const std::uint32_t band = g_rig.low_res_camera().width_px / 4;  // the band: columns 0..band − 1
  paint(g_frame, [&](std::uint32_t u, std::uint32_t) {
    const float y = u < band ? 180.0F : ((u / 2) % 2 == 0 ? 60.0F : 120.0F);
    return std::array<float, 3>{y, 0.0F, 0.0F};
  });
  CHECK(FloorLearn::kLearned == fresh.learn(g_frame, 0.0F, kLookTilt));
  CHECK(fresh.model().textured);
  check_max_run_against_band(fresh, p, 0, band - 1);
}

// In the region, as along a walk, shades exactly the luma change apart are one colour: a band
// alternating pixel by pixel between 180 and 190 (stripes of 60 and 80 make the change 10) is
// one run, and gives the texture's longest run.
TEST(FloorCue, ShadesExactlyTheLumaChangeApartAreOneRunInTheRegion) {
  FloorCueParams p = flat_trusting();
  p.texture_run_min_m = 0.0F;
  p.texture_run_max_m = 10.0F;
  static FloorCue fresh{g_rig, p};
  fresh.reset();
  const std::uint32_t width = g_rig.low_res_camera().width_px;
  const std::uint32_t band = width * 3 / 4;  // the band: columns band..width − 1
  paint(g_frame, [&](std::uint32_t u, std::uint32_t) {
    const float y = u >= band ? (u % 2 == 0 ? 180.0F : 190.0F) : ((u / 2) % 2 == 0 ? 60.0F : 80.0F);
    return std::array<float, 3>{y, 0.0F, 0.0F};
  });
  CHECK(FloorLearn::kLearned == fresh.learn(g_frame, 0.0F, kLookTilt));
  CHECK(fresh.model().textured);
  DOUBLES_EQUAL(10.0, fresh.model().tolerance[0], 1e-6);  // half the stripes' 20-level step
  check_max_run_against_band(fresh, p, band, width - 1);
}

// A column step of 0 configured is taken as 1: every column of the frame is walked, once.
TEST(FloorCue, AColumnStepOfZeroWalksEveryColumnOnce) {
  FloorCueParams p = flat_trusting();
  p.column_step = 0;
  static FloorCue fresh{g_rig, p};
  CHECK_EQUAL(1U, fresh.params().column_step);
  fresh.reset();
  fill_patches(g_frame, {120.0F});
  CHECK(FloorLearn::kLearned == fresh.learn(g_frame, 0.0F, kLookTilt));
  out.obstacles.clear();
  out.free.clear();
  out.result = fresh.process(g_frame, 0.0F, kLookTilt, out.obstacles, out.free);
  CHECK_EQUAL(std::size_t{g_frame.width}, fresh.column_count());
  for (std::size_t i = 0; i < fresh.column_count(); ++i) {
    CHECK_EQUAL(i, std::size_t{fresh.column(i).u_px});
  }
}

// A full obstacle list is reported like any other full output: a wall across the frame, room
// for every free reading and for two obstacle readings only.
TEST(FloorCue, AnObstacleListTooShortForTheBoundariesFoundIsReportedTruncated) {
  static FloorCue fresh{g_rig, flat_trusting()};
  learned_on_flat_floor(fresh);
  FixedVector<Reading, 2> obstacles;
  FixedVector<Reading, 256> free;
  const FloorCueResult r = fresh.process(g_frame2, 0.0F, kLookTilt, obstacles, free);
  CHECK(r.boundaries >= 60U);
  CHECK(free.size() < free.capacity());  // the free list had room
  CHECK_EQUAL(2U, obstacles.size());
  CHECK(r.truncated);
}

// A frame kept while the model waits keeps luma beyond white as white (255), not wrapped round
// to black: kept at luma 256, it is walked as free floor of luma 250, as the frame itself is.
TEST(FloorCue, AKeptFramesLumaBeyondWhiteIsKeptAsWhite) {
  const FloorCueParams flat = flat_trusting();
  static FloorCue fresh{g_rig, flat};
  fresh.reset();
  fill_patches(g_frame2, {256.0F});
  out.obstacles.clear();
  out.free.clear();
  out.result = fresh.process(g_frame2, 0.0F, kLookTilt, out.obstacles, out.free);
  CHECK(out.result.deferred);
  fill_patches(g_frame, {250.0F});
  CHECK(FloorLearn::kLearned == fresh.learn(g_frame, 0.0F, kLookTilt));
  out.free.clear();
  const FloorCueResult with_kept =
      fresh.process(g_frame2, 0.0F, kLookTilt, out.obstacles, out.free);
  CHECK_EQUAL(1U, with_kept.deferred_walked);
  out.free.clear();
  const FloorCueResult alone = fresh.process(g_frame2, 0.0F, kLookTilt, out.obstacles, out.free);
  CHECK_EQUAL(0U, alone.deferred_walked);
  CHECK_EQUAL(alone.columns, alone.free_readings);  // every walk of the frame is free floor
  CHECK_EQUAL(2 * alone.free_readings, with_kept.free_readings);
}

// The smallest frame a region is learned from is two pixels a side: a frame two pixels wide
// (the image's left edge) or two pixels high (its top rows, tilted down to see the floor 0.7 m
// away there) is learned from, its region as few pixels as the minimum asks; one pixel wide or
// high is not.
TEST(FloorCue, AFrameTwoPixelsWideOrHighIsLearnedFromAndOnePixelIsNot) {
  FloorCueParams p = flat_trusting();
  p.reference_min_pixels = 1;
  static FloorCue fresh{g_rig, p};
  constexpr float kSteep = -1.0F;  // [rad]
  float near_m = 0.0F;
  float far_m = 0.0F;
  CHECK(fresh.floor_coverage(kSteep, near_m, far_m));
  CHECK(far_m > p.reference_min_m && far_m < p.reference_max_m);  // the top row's floor
  for (const std::uint32_t size : {2U, 1U}) {
    const FloorLearn expected = size == 2 ? FloorLearn::kLearned : FloorLearn::kNoRegion;
    fill_patches(g_frame, {120.0F});
    g_frame.width = size;
    fresh.reset();
    CHECK(expected == fresh.learn(g_frame, 0.0F, kLookTilt));
    fill_patches(g_frame, {120.0F});
    g_frame.height = size;
    fresh.reset();
    CHECK(expected == fresh.learn(g_frame, 0.0F, kSteep));
  }
}

namespace {

// A frame of luma tone(ρ) (no chroma), ρ where each pixel sees the floor (the look's lower tilt,
// pan 0), far_tone at or above the horizon.
template <typename Tone>
void paint_by_floor_distance(LowResFrame& frame, Tone tone, float far_tone) {
  const boticelli::stereo::CameraPose pose = g_rig.camera_pose(0.0F, kLookTilt);
  paint(frame, [&](std::uint32_t u, std::uint32_t v) {
    Eigen::Vector3f point;
    const bool seen = floor_seen_at(pose, static_cast<float>(u), static_cast<float>(v), point);
    return std::array<float, 3>{seen ? tone(std::hypot(point.x(), point.y())) : far_tone, 0.0F,
                                0.0F};
  });
}

// A textured floor of 14 greys 16 apart (luma change the minimum, 10; every grey from 16 to 240
// its colour) learned by `cue`.
void learn_fine_greys(FloorCue& cue) {
  cue.reset();
  fill_patches(g_frame, {24.0F, 40.0F, 56.0F, 72.0F, 88.0F, 104.0F, 120.0F, 136.0F, 152.0F, 168.0F,
                         184.0F, 200.0F, 216.0F, 232.0F});
  CHECK(FloorLearn::kLearned == cue.learn(g_frame, 0.0F, kLookTilt));
  CHECK(cue.model().textured);
  DOUBLES_EQUAL(cue.params().min_tolerance_luma, cue.model().tolerance[0], 1e-6);
}

}  // namespace

// Along a walk on a textured floor, one colour stays within twice the change tolerances of its
// stretch's first sample: a floor of one grey whose shade rises by the luma change three times,
// at 0.7, 0.8 and 0.9 m (the walks begin at about 0.6 m), is one stretch to 0.9 m and another
// from there, a plain thing (one colour for longer than the floor's longest run, here 1 m) which
// ends the free floor at 0.9 m.
TEST(FloorCue, AShadeRisingThreeLumaChangesBeginsANewStretchWhereItRisesTheThirdTime) {
  FloorCueParams p = flat_trusting();
  p.texture_run_min_m = 1.0F;  // the longest run: 1 m
  p.texture_run_max_m = 1.0F;
  static FloorCue fresh{g_rig, p};
  learn_fine_greys(fresh);
  const float change = fresh.model().tolerance[0];
  const auto rises = [](float rho) {
    return rho < 0.7F ? 0.0F : (rho < 0.8F ? 1.0F : (rho < 0.9F ? 2.0F : 3.0F));
  };
  paint_by_floor_distance(
      g_frame2, [&](float rho) { return 100.0F + change * rises(rho); }, 100.0F + 3.0F * change);
  out.obstacles.clear();
  out.free.clear();
  out.result = fresh.process(g_frame2, 0.0F, kLookTilt, out.obstacles, out.free);
  CHECK_EQUAL(0U, out.result.obstacle_readings);  // texture_obstacles off
  CHECK_EQUAL(out.result.columns, out.free.size());
  for (std::size_t i = 0; i < fresh.column_count(); ++i) {
    CHECK(fresh.column(i).end == FloorColumn::End::kBoundary);
    DOUBLES_EQUAL(0.9, fresh.column(i).base_rho_m, 0.05);
    DOUBLES_EQUAL(0.9, fresh.column(i).free_rho_m, 0.05);
  }
}

// On a textured floor, a walk in one of its colours from its bottom row to max range, for more
// than half the floor's longest run, says nothing free: the colour may be a plain thing standing
// there, and no floor was seen before it.
TEST(FloorCue, AWalkInOneColourFromItsBottomRowToMaxRangeSaysNothingFree) {
  FloorCueParams p = flat_trusting();
  p.texture_run_min_m = 1.0F;  // the longest run: 1 m
  p.texture_run_max_m = 1.0F;
  p.max_range_m = 1.2F;
  static FloorCue fresh{g_rig, p};
  learn_fine_greys(fresh);
  fill_patches(g_frame2, {104.0F});
  out.obstacles.clear();
  out.free.clear();
  out.result = fresh.process(g_frame2, 0.0F, kLookTilt, out.obstacles, out.free);
  CHECK(out.result.columns > 0U);
  CHECK_EQUAL(0U, out.result.free_readings);
  for (std::size_t i = 0; i < fresh.column_count(); ++i) {
    const FloorColumn& col = fresh.column(i);
    CHECK(col.end == FloorColumn::End::kMaxRange);
    CHECK(p.max_range_m - col.near_rho_m > 0.55F);  // more than half the longest run
    CHECK(p.max_range_m - col.near_rho_m < 0.95F);  // and less than all of it
  }
}

// An update moves a plain floor's model by the learning rate towards the region's, its median
// and its tolerance in every channel: a quarter of the way with learn_rate 0.25, from luma
// 120 ± 2 towards 126 ± 4 (the two floors of unlike spreads).
TEST(FloorCue, AnUpdateMovesAPlainFloorsMediansAndTolerancesByTheLearningRate) {
  static FloorCue updated{g_rig, updating_by_a_quarter(flat_trusting())};
  check_plain_model_between(updated, 0.25F);
}

// A learning rate outside [0, 1] is held to it: above 1 an update takes the region's model
// whole (not beyond it), below 0 it leaves the model as it was (not moved away).
TEST(FloorCue, ALearningRateOutsideZeroToOneIsHeldToIt) {
  FloorCueParams too_high = updating_by_a_quarter(flat_trusting());
  too_high.learn_rate = 3.0F;
  FloorCueParams too_low = too_high;
  too_low.learn_rate = -1.0F;
  static FloorCue high{g_rig, too_high};
  static FloorCue low{g_rig, too_low};
  DOUBLES_EQUAL(1.0, high.params().learn_rate, 0.0);
  DOUBLES_EQUAL(0.0, low.params().learn_rate, 0.0);
  check_plain_model_between(high, 1.0F);
  check_plain_model_between(low, 0.0F);
}

// An update moves a textured floor's histogram by the learning rate towards the region's, bin
// by bin, and its shares with it: a quarter of the way with learn_rate 0.25, between two
// regions of the same colours in different proportions.
TEST(FloorCue, AnUpdateMovesATexturedFloorsHistogramByTheLearningRate) {
  static FloorCue updated{g_rig, updating_by_a_quarter(flat_trusting())};
  check_textured_model_between(updated, 0.25F);
}

// Vignetting dims a pixel's chroma as it dims its luma (the offsets from 128 shrink with it),
// and is undone in both chroma channels: a plain floor of Cb +20 and Cr −20 drawn with the
// fall-off is learned as that colour, and looks like floor in every corner.
TEST(FloorCue, VignettingIsUndoneInBothChromaChannels) {
  FloorCueParams p = trusting();
  p.vignetting = 0.3F;
  static FloorCue fresh{g_rig, p};
  fresh.reset();
  paint_vignetted(p.vignetting, {120.0F, 20.0F, -20.0F});
  CHECK(FloorLearn::kLearned == fresh.learn(g_frame, 0.0F, kLookTilt));
  CHECK_FALSE(fresh.model().textured);
  // The frame's chroma levels are whole (truncated): a level at most, divided by the fall-off.
  DOUBLES_EQUAL(20.0, fresh.model().median[1], 1.5);
  DOUBLES_EQUAL(-20.0, fresh.model().median[2], 1.5);
  for (const auto& [u, v] : image_corners()) {
    float contrast = 0.0F;
    CHECK(fresh.looks_like_floor(g_frame, u, v, contrast));
  }
}

// Only pixels next to each other on a row of the region are neighbours, not the last of one
// row and the first of the next: rows of one tone each, alternating between luma 60 and 200,
// change colour nowhere along a row, so the region is no texture however few changes a texture
// needs (here one pair in a million), and, two colours, not one plain surface either.
TEST(FloorCue, RowsOfOneToneEachAreNoTextureHoweverFewChangesOneNeeds) {
  FloorCueParams p = flat_trusting();
  p.texture_min_edges = 1e-6F;
  static FloorCue fresh{g_rig, p};
  fresh.reset();
  paint(g_frame, [](std::uint32_t, std::uint32_t v) {
    return std::array<float, 3>{v % 2 == 0 ? 60.0F : 200.0F, 0.0F, 0.0F};
  });
  CHECK(FloorLearn::kNotUniform == fresh.learn(g_frame, 0.0F, kLookTilt));
  CHECK_FALSE(fresh.model().valid);
}

// A frame of no pixels seen before the model is neither kept nor dropped: there is nothing to
// keep, no slot is taken, and once the model comes no kept frame is walked.
TEST(FloorCue, AnEmptyFrameSeenBeforeTheModelIsNeitherKeptNorDropped) {
  static FloorCue fresh{g_rig, flat_trusting()};
  fresh.reset();
  for (const bool no_width : {true, false}) {
    fill_patches(g_frame2, {120.0F});
    (no_width ? g_frame2.width : g_frame2.height) = 0;
    out.obstacles.clear();
    out.free.clear();
    out.result = fresh.process(g_frame2, 0.0F, kLookTilt, out.obstacles, out.free);
    CHECK_FALSE(out.result.model_valid);
    CHECK_FALSE(out.result.deferred);
    CHECK_FALSE(out.result.deferred_dropped);
  }
  fill_patches(g_frame, {120.0F});
  CHECK(FloorLearn::kLearned == fresh.learn(g_frame, 0.0F, kLookTilt));
  out.result = fresh.process(g_frame, 0.0F, kLookTilt, out.obstacles, out.free);
  CHECK_EQUAL(0U, out.result.deferred_walked);
  CHECK_EQUAL(out.result.columns, out.result.free_readings);  // the frame itself, all free
}

// A boundary is boundary_run non-floor samples in a row, at least 1 (and at most 8): a line one
// pixel high across the floor (the image's middle row) ends nearly every walk with a run of 1,
// and none with the default run of 3 (one sample of it, and the floor goes on).
TEST(FloorCue, ABoundaryRunOfOneEndsAWalkAtItsFirstSampleNotLikeTheFloor) {
  FloorCueParams p = flat_trusting();
  static std::optional<FloorCue> configured_cue;  // large: not on the stack
  for (const auto& [configured, taken] :
       {std::pair{0U, 1U}, std::pair{1U, 1U}, std::pair{8U, 8U}, std::pair{9U, 8U}}) {
    p.boundary_run = configured;
    configured_cue.emplace(g_rig, p);
    CHECK_EQUAL(taken, configured_cue->params().boundary_run);
  }
  p.boundary_run = 1;
  static FloorCue one{g_rig, p};
  static FloorCue three{g_rig, flat_trusting()};
  const std::uint32_t middle = g_rig.low_res_camera().height_px / 2;
  for (FloorCue* run_of : {&one, &three}) {
    learned_on_flat_floor(*run_of);
    paint(g_frame2, [&](std::uint32_t, std::uint32_t v) {
      return std::array<float, 3>{v == middle ? 220.0F : 120.0F, 0.0F, 0.0F};
    });
    out.obstacles.clear();
    out.free.clear();
    out.result = run_of->process(g_frame2, 0.0F, kLookTilt, out.obstacles, out.free);
    CHECK(out.result.columns >= 60U);
    if (run_of == &one) {
      CHECK(10 * out.result.boundaries >= 9 * out.result.columns);
    } else {
      CHECK_EQUAL(0U, out.result.boundaries);
    }
  }
}

namespace {

// Where a floor point along a walk's azimuth [rad] at horizontal distance rho [m] from the PTU
// centre lies in the image of `pose`'s camera (the walks' own geometry: the azimuth is that of the
// vertical plane through the optical centre).
Eigen::Vector2f pixel_of_walk_point(const boticelli::stereo::CameraPose& pose, float azimuth,
                                    float rho) {
  const Eigen::Vector2f c(pose.centre_m.x(), pose.centre_m.y());
  const Eigen::Vector2f a(std::cos(azimuth), std::sin(azimuth));
  const float along = c.dot(a);
  const float s = -along + std::sqrt(along * along - c.squaredNorm() + rho * rho);
  const Eigen::Vector2f on_floor = c + s * a;
  Eigen::Vector2f pixel;
  CHECK(RigModel::project_ptu(
      pose, g_rig.low_res_camera(),
      Eigen::Vector3f(on_floor.x(), on_floor.y(), -g_rig.params().ptu_height_m), pixel));
  return pixel;
}

}  // namespace

// A walk begins where its plane leaves the frame below, at a sample that rounds to a pixel of
// the frame: in a frame of the image's 41 left columns, the planes of the columns on its right
// lean towards the image's centre below and leave the frame by its right side, and there too the
// walks' near ends lie within half a pixel of its last column.
TEST(FloorCue, EveryWalkBeginsAtASampleThatRoundsToAPixelOfTheFrame) {
  static FloorCue fresh{g_rig, flat_trusting()};
  learned_on_flat_floor(fresh);
  constexpr std::uint32_t kWidth = 41;
  fill_patches(g_frame2, {120.0F});
  g_frame2.width = kWidth;
  out.obstacles.clear();
  out.free.clear();
  out.result = fresh.process(g_frame2, 0.0F, kLookTilt, out.obstacles, out.free);
  CHECK_EQUAL(21U, out.result.columns);
  const boticelli::stereo::CameraPose pose = g_rig.camera_pose(0.0F, kLookTilt);
  std::size_t by_the_side = 0;
  for (std::size_t i = 0; i < fresh.column_count(); ++i) {
    const FloorColumn& col = fresh.column(i);
    const Eigen::Vector2f near = pixel_of_walk_point(pose, col.azimuth_rad, col.near_rho_m);
    CHECK(near.x() >= -0.5F && near.x() < static_cast<float>(kWidth) - 0.5F);
    CHECK(near.y() >= -0.5F && near.y() < static_cast<float>(g_frame2.height) - 0.5F);
    by_the_side += near.x() > static_cast<float>(kWidth) - 1.0F ? 1U : 0U;
  }
  CHECK(by_the_side >= 1U);
}
