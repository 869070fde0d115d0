// Target detection (§3.4.2) on rendered scenes: found at 0.5–4 m, never in scenes without it.
#include <array>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <vector>

#include "algo/image/low_res_frame.h"
#include "algo/image/target_detector.h"
#include "algo/evidence/sensor_model.h"
#include "algo/stereo/rig.h"
#include "algo/stereo/stereo_processor.h"
#include "scene_renderer.h"
#include "CppUTest/TestHarness.h"
#include "alloc_guard.h"

using namespace boticelli;

namespace {

// Deterministic scene parameters.
struct Lcg {
  std::uint32_t state;
  float next() {
    state = state * 1664525U + 1013904223U;
    return static_cast<float>(state >> 8) * (1.0F / 16777216.0F);
  }
  float range(float lo, float hi) { return lo + (hi - lo) * next(); }
};

image::LowResFrame& frame() {
  static image::LowResFrame instance;
  return instance;
}

image::TargetDetection render_and_detect(const stereo::RigModel& rig,
                                         const stereo::CameraPose& pose,
                                         const test::SceneRenderer& scene, std::uint32_t seed) {
  std::vector<std::uint8_t> yuyv(std::size_t{rig.camera().width_px} * rig.camera().height_px * 2);
  scene.render_yuyv(rig, pose, yuyv.data(), seed, 1.5F, 2);
  CHECK(image::downsample_yuyv(yuyv.data(), rig.camera().width_px, rig.camera().height_px,
                               rig.camera().width_px * 2, 4, frame()));
  static image::TargetDetector detector;
  image::TargetDetection d;
  CHECK_NO_ALLOCATION(d = detector.detect(frame()));
  return d;
}

// A camouflage wall (blotches of 8 cm) facing the camera, distance_m + 2 cm in front of it
// along its axis: the backdrop the target or a decoy stands in front of.
test::Patch camouflage_backdrop(const stereo::CameraPose& pose, float distance_m) {
  test::Patch wall = test::facing_wall(pose.centre_m, pose.rotation.col(2), distance_m + 0.02F,
                                       5.0F, test::Surface::kCamouflage, 9);
  wall.scale_m = 0.08F;
  return wall;
}

}  // namespace

TEST_GROUP(Target){};

TEST(Target, CornerIsFoundFromHalfAMetreToFourMetres) {
  const stereo::RigModel rig;
  Lcg rng{12345};
  std::printf("\n  distance [m]  found  confidence  corner error [low-res px]\n");
  for (const float distance : {0.5F, 0.8F, 1.2F, 1.8F, 2.5F, 3.2F, 4.0F}) {
    const float pan = rng.range(-3.0F, 3.0F);
    const float tilt = rng.range(-0.15F, 0.15F);
    const stereo::CameraPose pose = rig.camera_pose(pan, tilt);
    test::SceneRenderer scene;
    // Camouflage wall behind, the paper a little in front of it, off the optical axis.
    const Eigen::Vector3f forward = pose.rotation.col(2);
    scene.add(camouflage_backdrop(pose, distance));
    test::Patch paper =
        test::facing_wall(pose.centre_m, forward, distance, 0.15F, test::Surface::kTarget, 1);
    // On the optical axis (the camera may be tilted), shifted within the view.
    paper.centre_m = pose.centre_m + distance * forward +
                     rng.range(-0.2F, 0.2F) * distance * paper.right +
                     rng.range(-0.1F, 0.1F) * distance * paper.up;
    scene.add(paper);
    const image::TargetDetection d = render_and_detect(rig, pose, scene, 77);
    Eigen::Vector2f truth;
    CHECK(stereo::RigModel::project_ptu(pose, rig.low_res_camera(),
                                        test::SceneRenderer::target_corner(paper), truth));
    const float error = (Eigen::Vector2f(d.u_px, d.v_px) - truth).norm();
    std::printf("  %4.1f          %s    %.2f        %.2f\n", static_cast<double>(distance),
                d.found ? "yes" : "no ", static_cast<double>(d.confidence),
                static_cast<double>(error));
    CHECK(d.found);
    CHECK(error < 1.5F);
  }
}

TEST(Target, NothingIsFoundInFiftyScenesWithoutTheTarget) {
  const stereo::RigModel rig;
  Lcg rng{777};
  int false_detections = 0;
  for (int scene_index = 0; scene_index < 50; ++scene_index) {
    const float pan = rng.range(-3.0F, 3.0F);
    const float tilt = rng.range(-0.2F, 0.15F);
    const stereo::CameraPose pose = rig.camera_pose(pan, tilt);
    const Eigen::Vector3f forward = pose.rotation.col(2);
    test::SceneRenderer scene;
    const float distance = rng.range(0.6F, 4.5F);
    test::Patch wall;
    const int kind = scene_index % 3;
    wall = test::facing_wall(pose.centre_m, forward, distance, 6.0F,
                             kind == 0 ? test::Surface::kCamouflage : test::Surface::kPlain,
                             static_cast<std::uint32_t>(scene_index));
    wall.scale_m = rng.range(0.04F, 0.15F);
    wall.colour =
        Eigen::Vector3f(rng.range(0.2F, 0.9F), rng.range(0.2F, 0.9F), rng.range(0.2F, 0.9F));
    scene.add(wall);
    // Boxes (cardboard brown, camouflage or green faces), paper sheets and decoys in front.
    const int objects = 1 + scene_index % 4;
    for (int o = 0; o < objects; ++o) {
      test::Patch box = test::facing_wall(pose.centre_m, forward, distance * rng.range(0.4F, 0.9F),
                                          rng.range(0.1F, 0.4F), test::Surface::kPlain,
                                          static_cast<std::uint32_t>(100 + o));
      box.centre_m += rng.range(-0.4F, 0.4F) * distance * box.right +
                      rng.range(-0.3F, 0.3F) * distance * box.up;
      const int look = (scene_index + o) % 5;
      if (look == 0) box.colour = Eigen::Vector3f(0.55F, 0.4F, 0.25F);  // cardboard
      if (look == 1) box.surface = test::Surface::kCamouflage;
      if (look == 2) box.colour = Eigen::Vector3f(0.12F, 0.6F, 0.22F);  // a plain green box
      if (look == 3) box.surface = test::Surface::kPaper;
      if (look == 4) {
        box.surface = test::Surface::kGreenSquare;  // green square on white paper
        box.target_side_m = 1.2F * box.half_width_m;
      }
      scene.add(box);
    }
    const image::TargetDetection d =
        render_and_detect(rig, pose, scene, static_cast<std::uint32_t>(scene_index));
    if (d.found) {
      ++false_detections;
      std::printf("\n  false detection in scene %d at (%.1f, %.1f), confidence %.2f", scene_index,
                  static_cast<double>(d.u_px), static_cast<double>(d.v_px),
                  static_cast<double>(d.confidence));
    }
  }
  LONGS_EQUAL(0, false_detections);
}

TEST(Target, AGreenTriangleOffWhitePaperOrOfAnotherShapeIsNotTheTarget) {
  // The target's own triangle on a grey, a brown and a pale wall (no white paper round it),
  // and on white paper a triangle three times as tall: each seen as the target would be,
  // from 0.8 to 2.5 m, on a camouflage wall.
  const stereo::RigModel rig;
  int false_detections = 0;
  for (const float distance : {0.8F, 1.5F, 2.5F}) {
    const stereo::CameraPose pose = rig.camera_pose(0.3F, 0.0F);
    const Eigen::Vector3f forward = pose.rotation.col(2);
    for (int decoy = 0; decoy < 4; ++decoy) {
      test::SceneRenderer scene;
      const test::Patch wall = camouflage_backdrop(pose, distance);
      scene.add(wall);
      test::Patch sign =
          test::facing_wall(pose.centre_m, forward, distance, 0.3F, test::Surface::kTarget, 1);
      sign.surface = decoy == 3 ? test::Surface::kTallTriangle : test::Surface::kTriangleOnPlain;
      sign.target_side_m = decoy == 3 ? 0.12F : 0.2F;
      const Eigen::Vector3f colours[] = {
          {0.5F, 0.5F, 0.5F}, {0.55F, 0.4F, 0.25F}, {0.75F, 0.72F, 0.6F}};
      if (decoy < 3) sign.colour = colours[decoy];
      scene.add(sign);
      const image::TargetDetection d =
          render_and_detect(rig, pose, scene, static_cast<std::uint32_t>(31 + decoy));
      if (d.found) {
        ++false_detections;
        std::printf("\n  decoy %d at %.1f m taken for the target (confidence %.2f)", decoy,
                    static_cast<double>(distance), static_cast<double>(d.confidence));
      }
      // The same place with the target itself is found (the decoys are seen as it would be).
      if (decoy == 0) {
        sign.surface = test::Surface::kTarget;
        test::SceneRenderer with_target;
        with_target.add(wall);
        with_target.add(sign);
        CHECK(render_and_detect(rig, pose, with_target, 30).found);
      }
    }
  }
  LONGS_EQUAL(0, false_detections);
}

namespace {

// A colour of the low-resolution frame: luma, and Cb, Cr as offsets from 128.
struct Colour {
  float y;
  int cb;
  int cr;
};
constexpr Colour kTargetGreen{80.0F, -20, -40};
constexpr Colour kWhitePaper{200.0F, 0, 0};

void set_pixel(image::LowResFrame& f, std::uint32_t u, std::uint32_t v, const Colour& c) {
  const std::size_t i = f.index(u, v);
  f.luma[i] = c.y;
  f.chroma_u[i] = static_cast<std::uint8_t>(128 + c.cb);
  f.chroma_v[i] = static_cast<std::uint8_t>(128 + c.cr);
}

// A green triangle drawn pixel by pixel on white paper that fills a 160x120 frame: its
// vertex at (80, 40), 24 rows, row k half as wide as 0.577 k px (equilateral, head-on);
// from the fourth row on, rows alternately `ragged_px` wider and narrower each side.
void draw_triangle(image::LowResFrame& f, float ragged_px, const Colour& green = kTargetGreen,
                   const Colour& paper = kWhitePaper, int rows = 24) {
  f.width = 160;
  f.height = 120;
  for (std::uint32_t v = 0; v < f.height; ++v) {
    for (std::uint32_t u = 0; u < f.width; ++u) set_pixel(f, u, v, paper);
  }
  for (int k = 0; k < rows; ++k) {
    float half = 0.5F + 0.577F * static_cast<float>(k);
    if (k >= 3) half += k % 2 == 1 ? ragged_px : -ragged_px;
    half = std::fmax(half, 0.5F);
    const auto v = static_cast<std::uint32_t>(40 + k);
    for (auto u = static_cast<std::uint32_t>(std::lround(80.0F - half));
         u <= static_cast<std::uint32_t>(std::lround(80.0F + half)); ++u) {
      set_pixel(f, u, v, green);
    }
  }
}

// The drawn triangle's pixels: those of the green colour.
std::size_t green_pixels(const image::LowResFrame& f, const Colour& green) {
  std::size_t n = 0;
  for (std::uint32_t v = 0; v < f.height; ++v) {
    for (std::uint32_t u = 0; u < f.width; ++u) {
      const std::size_t i = f.index(u, v);
      n +=
          f.luma[i] == green.y && f.chroma_u[i] == 128 + green.cb && f.chroma_v[i] == 128 + green.cr
              ? 1U
              : 0U;
    }
  }
  return n;
}

}  // namespace

// A decoy whose confidence lies between half the threshold and the threshold: the same
// triangle with edges ragged by 2 px is still shaped like the target (a detector with
// half the threshold takes it) but its edges are not straight lines.
TEST(Target, ATriangleWithRaggedEdgesIsBelowTheConfidenceThresholdAndNotTheTarget) {
  static image::TargetDetector detector;
  draw_triangle(frame(), 0.0F);
  const image::TargetDetection straight = detector.detect(frame());
  CHECK(straight.found);
  DOUBLES_EQUAL(80.0, straight.u_px, 1.0);
  draw_triangle(frame(), 2.0F);
  image::TargetParams lax;
  lax.min_confidence = 0.5F * image::TargetParams{}.min_confidence;
  static image::TargetDetector lax_detector(lax);
  const image::TargetDetection seen = lax_detector.detect(frame());
  CHECK(seen.found);
  CHECK(seen.confidence < 0.5F);
  CHECK_FALSE(detector.detect(frame()).found);
}

TEST(Target, CornerIsTriangulatedFromBothFramesOfAPair) {
  const stereo::RigModel rig;
  static stereo::StereoProcessor processor{rig};
  static image::LowResFrame second;
  std::vector<std::uint8_t> yuyv(std::size_t{rig.camera().width_px} * rig.camera().height_px * 2);
  std::printf("\n  distance [m]  range error [m]  dr (Eq 3.7) [m]\n");
  for (const float distance : {0.6F, 1.5F, 3.0F}) {
    const float pan = 0.7F;
    const float tilt = 0.05F;
    const stereo::PairPose pose{pan, tilt, tilt - rig.params().tilt_step_rad};
    const stereo::CameraPose first_pose = rig.camera_pose(pan, pose.first_tilt_rad);
    const stereo::CameraPose second_pose = rig.camera_pose(pan, pose.second_tilt_rad);
    test::SceneRenderer scene;
    const Eigen::Vector3f forward = first_pose.rotation.col(2);
    scene.add(test::facing_wall(first_pose.centre_m, forward, distance + 0.02F, 5.0F,
                                test::Surface::kPlain, 3));
    test::Patch paper =
        test::facing_wall(first_pose.centre_m, forward, distance, 0.15F, test::Surface::kTarget, 1);
    paper.centre_m = first_pose.centre_m + distance * forward + 0.05F * distance * paper.right;
    scene.add(paper);
    const std::uint32_t w = rig.camera().width_px;
    const std::uint32_t h = rig.camera().height_px;
    scene.render_yuyv(rig, first_pose, yuyv.data(), 5, 1.5F, 2);
    CHECK(image::downsample_yuyv(yuyv.data(), w, h, w * 2, 4, frame()));
    scene.render_yuyv(rig, second_pose, yuyv.data(), 6, 1.5F, 2);
    CHECK(image::downsample_yuyv(yuyv.data(), w, h, w * 2, 4, second));
    stereo::TargetFix fix;
    CHECK_NO_ALLOCATION(fix = processor.locate_target(frame(), second, pose));
    CHECK(fix.found);
    const Eigen::Vector3f truth = test::SceneRenderer::target_corner(paper);
    const float range_error = std::fabs(fix.reading.r_m - truth.norm());
    const float dr =
        evidence::range_error_m(distance, rig.baseline_m(), rig.low_res_camera().focal_px);
    std::printf("  %4.1f          %.4f           %.3f\n", static_cast<double>(distance),
                static_cast<double>(range_error), static_cast<double>(dr));
    CHECK(range_error < 0.5F * dr);
    // The bearing is as good as the corner's pixel position.
    const Eigen::Vector3f seen = (fix.point_ptu_m - first_pose.centre_m).normalized();
    const Eigen::Vector3f expected = (truth - first_pose.centre_m).normalized();
    CHECK(seen.dot(expected) > std::cos(1.0F / rig.low_res_camera().focal_px));
    // With the self-calibration's inverse-range bias in use, the same fix lies on the same
    // line of sight at 1/r = 1/r̂ − b.
    processor.set_inverse_range_bias(0.1F);
    const stereo::TargetFix calibrated = processor.locate_target(frame(), second, pose);
    processor.set_inverse_range_bias(0.0F);
    CHECK(calibrated.found);
    const float r_read = (fix.point_ptu_m - first_pose.centre_m).norm();
    DOUBLES_EQUAL(1.0F / (1.0F / r_read - 0.1F),
                  (calibrated.point_ptu_m - first_pose.centre_m).norm(), 1e-3F * r_read);
    CHECK((calibrated.point_ptu_m - first_pose.centre_m).normalized().dot(seen) > 0.99999F);
  }
}

// Foliage's green (−Cr about 0.22 of Y − black, above the ratio a blob grows by, below the
// one it starts from) shaped as the target on white paper is no target: no pixel of it starts
// a blob. The target's green on the same paper is found.
TEST(Target, ATriangleOfFoliagesGreenOnWhitePaperIsNotTheTarget) {
  static image::TargetDetector detector;
  draw_triangle(frame(), 0.0F, Colour{120.0F, -12, -23});
  CHECK_FALSE(detector.detect(frame()).found);
  draw_triangle(frame(), 0.0F, Colour{120.0F, -12, -40});
  CHECK(detector.detect(frame()).found);
}

// The green thresholds hold their bounds: a triangle whose −Cb is exactly the seed's share of
// its brightness (0.1 · 100 levels) starts a blob, and a rim of pixels with Cb exactly neutral
// (the growth's share, 0) grows into it: the blob's area is the triangle's and the rim's.
TEST(Target, PixelsExactlyAtTheGreenThresholdsStartAndGrowTheBlob) {
  static image::TargetDetector detector;
  const Colour at_seed{116.0F, -10, -40};  // Y − black = 100
  draw_triangle(frame(), 0.0F, at_seed);
  const std::size_t triangle = green_pixels(frame(), at_seed);
  const image::TargetDetection seeded = detector.detect(frame());
  CHECK(seeded.found);
  CHECK_EQUAL(triangle, seeded.area_px);
  // The rim: the paper pixel left and right of each row of the triangle.
  const Colour rim{200.0F, 0, -23};  // paper-bright: it adds no width to the rows
  for (std::uint32_t v = 40; v < 64; ++v) {
    std::uint32_t first = 0;
    std::uint32_t last = 0;
    for (std::uint32_t u = 0; u < frame().width; ++u) {
      if (frame().chroma_v[frame().index(u, v)] != 128 + at_seed.cr) continue;
      if (first == 0) first = u;
      last = u;
    }
    set_pixel(frame(), first - 1, v, rim);
    set_pixel(frame(), last + 1, v, rim);
  }
  const image::TargetDetection grown = detector.detect(frame());
  CHECK_EQUAL(triangle + 2 * 24, grown.area_px);
  // A rim whose −Cr is exactly the growth's share of its brightness (0.12 · 175 levels) grows
  // into the blob too.
  for (std::uint32_t v = 40; v < 64; ++v) {
    for (std::uint32_t u = 0; u < frame().width; ++u) {
      const std::size_t i = frame().index(u, v);
      if (frame().chroma_v[i] == 128 + rim.cr) set_pixel(frame(), u, v, Colour{191.0F, 0, -21});
    }
  }
  CHECK_EQUAL(triangle + 2 * 24, detector.detect(frame()).area_px);
}

// Under tinted light the paper's mean chroma is the neutral: a triangle within 3 chroma levels
// of such paper is no target, however green its chroma reads against true grey.
TEST(Target, ATriangleOfTheTintedPapersOwnColourIsNotTheTarget) {
  static image::TargetDetector detector;
  const Colour tinted_paper{200.0F, -15, -4};
  draw_triangle(frame(), 0.0F, Colour{30.0F, -16, -6}, tinted_paper);
  CHECK_FALSE(detector.detect(frame()).found);
  // The same dark triangle clearly greener than the paper is found.
  draw_triangle(frame(), 0.0F, Colour{30.0F, -16, -12}, tinted_paper);
  CHECK(detector.detect(frame()).found);
}

// A dark rim beside the triangle (its shadow on the paper, in the paper's own chroma) is not
// greener than the paper: it adds nothing to the rows' widths, and the vertex stays where the
// green puts it, on white paper and on tinted paper (a cream sheet).
TEST(Target, AShadowBesideTheTriangleDoesNotMoveItsVertex) {
  static image::TargetDetector detector;
  for (const Colour& paper : {kWhitePaper, Colour{200.0F, -15, -6}}) {
    draw_triangle(frame(), 0.0F, kTargetGreen, paper);
    const image::TargetDetection clean = detector.detect(frame());
    CHECK(clean.found);
    for (std::uint32_t v = 41; v < 64; ++v) {
      for (std::uint32_t u = 0; u < frame().width; ++u) {
        if (frame().chroma_v[frame().index(u, v)] == 128 + kTargetGreen.cr) {
          set_pixel(frame(), u - 1, v, Colour{40.0F, paper.cb, paper.cr});
          break;
        }
      }
    }
    const image::TargetDetection shadowed = detector.detect(frame());
    CHECK(shadowed.found);
    DOUBLES_EQUAL(clean.u_px, shadowed.u_px, 0.05);
    DOUBLES_EQUAL(clean.v_px, shadowed.v_px, 0.05);
  }
}

// The confidence's factors: white paper all round scales it, and straight edges, half the box
// filled and symmetry each take it from 0.4 to 1 of that (the product of the three).
TEST(Target, ConfidenceIsThePapersShareTimesHowStraightFilledAndSymmetricTheTriangleIs) {
  DOUBLES_EQUAL(1.0, image::target_confidence(1.0F, 0.0F, 0.5F, 0.0F), 1e-6);
  DOUBLES_EQUAL(0.8, image::target_confidence(0.8F, 0.0F, 0.5F, 0.0F), 1e-6);
  DOUBLES_EQUAL(1.0, image::target_confidence(1.3F, 0.0F, 0.5F, 0.0F), 1e-6);  // share clamped
  DOUBLES_EQUAL(0.7, image::target_confidence(1.0F, 0.75F, 0.5F, 0.0F), 1e-6);
  DOUBLES_EQUAL(0.4, image::target_confidence(1.0F, 3.0F, 0.5F, 0.0F), 1e-6);
  DOUBLES_EQUAL(0.7, image::target_confidence(1.0F, 0.0F, 0.65F, 0.0F), 1e-6);
  DOUBLES_EQUAL(0.7, image::target_confidence(1.0F, 0.0F, 0.35F, 0.0F), 1e-6);
  DOUBLES_EQUAL(0.4, image::target_confidence(1.0F, 0.0F, 0.9F, 0.0F), 1e-6);
  DOUBLES_EQUAL(0.85, image::target_confidence(1.0F, 0.0F, 0.5F, 0.3F), 1e-6);
  DOUBLES_EQUAL(0.7, image::target_confidence(1.0F, 0.0F, 0.5F, 0.9F), 1e-6);
  // All three halfway: 0.4 + 0.6 · 0.5 · 0.5 · 0.75.
  DOUBLES_EQUAL(0.5125, image::target_confidence(1.0F, 0.75F, 0.65F, 0.3F), 1e-6);
}

// The vertex is where the edge lines meet, at most two rows above the blob's top row: a
// triangle with its top two rows cut off (a trapezoid, whose edges meet three rows above it)
// is no target.
TEST(Target, ATriangleWithItsTopCutOffIsNotTheTarget) {
  static image::TargetDetector detector;
  draw_triangle(frame(), 0.0F);
  CHECK(detector.detect(frame()).found);
  for (std::uint32_t v = 40; v < 42; ++v) {
    for (std::uint32_t u = 0; u < frame().width; ++u) set_pixel(frame(), u, v, kWhitePaper);
  }
  CHECK_FALSE(detector.detect(frame()).found);
}

// An equilateral triangle, vertex up at (apex_u, apex_v), `height_px` rows high, drawn with
// each pixel mixing green and paper by the share of it the triangle covers (16 x 16 samples),
// as the camera's 4 x 4 averaging does; `light(u, v)` scales the brightness above black of paper
// and triangle alike. Its half width grows by `half_width_per_row` a row: tan 30° head-on, half
// that seen 60° aside.
template <typename Light>
void draw_smooth_triangle(image::LowResFrame& f, float apex_u, float apex_v, float height_px,
                          Light light, float half_width_per_row = 0.57735F) {
  f.width = 160;
  f.height = 120;
  const Colour& g = kTargetGreen;
  const Colour& p = kWhitePaper;
  for (std::uint32_t v = 0; v < f.height; ++v) {
    for (std::uint32_t u = 0; u < f.width; ++u) {
      int inside = 0;
      for (int sy = 0; sy < 16; ++sy) {
        for (int sx = 0; sx < 16; ++sx) {
          // Pixel (u, v) covers [u − 0.5, u + 0.5] x [v − 0.5, v + 0.5].
          const float x = static_cast<float>(u) - 0.5F + (static_cast<float>(sx) + 0.5F) / 16.0F;
          const float y = static_cast<float>(v) - 0.5F + (static_cast<float>(sy) + 0.5F) / 16.0F;
          const float t = y - apex_v;
          if (t >= 0.0F && t <= height_px && std::fabs(x - apex_u) <= half_width_per_row * t) {
            ++inside;
          }
        }
      }
      const float c = static_cast<float>(inside) / 256.0F;
      const std::size_t i = f.index(u, v);
      f.luma[i] = 16.0F + (p.y + (g.y - p.y) * c - 16.0F) *
                              light(static_cast<float>(u), static_cast<float>(v));
      f.chroma_u[i] = static_cast<std::uint8_t>(std::lround(128.0F + c * static_cast<float>(g.cb)));
      f.chroma_v[i] = static_cast<std::uint8_t>(std::lround(128.0F + c * static_cast<float>(g.cr)));
    }
  }
}

// Light falling off across the paper (and the triangle on it alike): the paper's brightness
// is fitted as a plane, so the vertex is found where it is drawn, as under even light.
TEST(Target, UnevenLightAcrossThePaperDoesNotMoveTheVertex) {
  static image::TargetDetector detector;
  // Brightness slopes across the frame, sideways and up-down (0.3: 30 % brighter at one edge).
  constexpr std::array<std::array<float, 2>, 7> kSlopes{{{0.0F, 0.0F},
                                                         {0.3F, 0.0F},
                                                         {-0.3F, 0.0F},
                                                         {0.6F, 0.0F},
                                                         {0.0F, 0.3F},
                                                         {0.0F, -0.3F},
                                                         {0.3F, 0.3F}}};
  for (const auto& [across, down] : kSlopes) {
    draw_smooth_triangle(frame(), 80.3F, 39.6F, 24.0F, [&](float u, float v) {
      return 1.0F + across * (u - 80.0F) / 80.0F + down * (v - 60.0F) / 60.0F;
    });
    const image::TargetDetection d = detector.detect(frame());
    CHECK(d.found);
    DOUBLES_EQUAL(80.3, d.u_px, 0.01);
    DOUBLES_EQUAL(39.6, d.v_px, 0.02);
  }
}

namespace {

// A second frame, for windows cut out of the first.
image::LowResFrame& window() {
  static image::LowResFrame instance;
  return instance;
}

// Copies the window [u0, u0 + w) x [v0, v0 + h) of `from` into `to`: the same scene, the frame's
// edges elsewhere.
void crop(const image::LowResFrame& from, std::uint32_t u0, std::uint32_t v0, std::uint32_t w,
          std::uint32_t h, image::LowResFrame& to) {
  to.width = w;
  to.height = h;
  for (std::uint32_t v = 0; v < h; ++v) {
    for (std::uint32_t u = 0; u < w; ++u) {
      const std::size_t i = from.index(u0 + u, v0 + v);
      const std::size_t j = to.index(u, v);
      to.luma[j] = from.luma[i];
      to.chroma_u[j] = from.chroma_u[i];
      to.chroma_v[j] = from.chroma_v[i];
    }
  }
}

// Copies `from` into `to` mirrored left to right.
void mirror(const image::LowResFrame& from, image::LowResFrame& to) {
  to.width = from.width;
  to.height = from.height;
  for (std::uint32_t v = 0; v < from.height; ++v) {
    for (std::uint32_t u = 0; u < from.width; ++u) {
      const std::size_t i = from.index(u, v);
      const std::size_t j = to.index(from.width - 1 - u, v);
      to.luma[j] = from.luma[i];
      to.chroma_u[j] = from.chroma_u[i];
      to.chroma_v[j] = from.chroma_v[i];
    }
  }
}

constexpr auto kEvenLight = [](float, float) { return 1.0F; };

}  // namespace

// A triangle cut by the frame's edge has no trustworthy vertex. The drawn triangle (columns 66
// to 94, rows 40 to 63) seen through windows of the frame: with a pixel of paper between it and
// an edge it is found; with the edge across it (its top row, its left or right side or its last
// four rows outside the window) or along it (its bottom row on the frame's last) it is not.
TEST(Target, ATriangleCutByAnEdgeOfTheFrameIsNotTheTarget) {
  static image::TargetDetector detector;
  draw_triangle(frame(), 0.0F);
  struct Window {
    std::uint32_t u0, v0, w, h;
    bool found;
  };
  constexpr Window kWindows[] = {
      {0, 39, 160, 81, true}, {0, 41, 160, 79, false},                          // top
      {65, 0, 95, 120, true}, {70, 0, 90, 120, false},                          // left
      {0, 0, 96, 120, true},  {0, 0, 90, 120, false},                           // right
      {0, 0, 160, 65, true},  {0, 0, 160, 64, false},  {0, 0, 160, 60, false},  // bottom
  };
  for (const Window& win : kWindows) {
    crop(frame(), win.u0, win.v0, win.w, win.h, window());
    CHECK_EQUAL_TEXT(win.found, detector.detect(window()).found, "window");
  }
}

// The triangle with its bottom row's first pixel in the frame's second column is found. Joined
// there to green that runs along the frame's left edge from above the triangle to below it, the
// two are one blob, which may go on out of the frame: no target, though the flood (in raster
// order) starts in the edge's column and reaches the triangle only from it.
TEST(Target, ATriangleJoinedToGreenAlongTheFramesEdgeIsNotTheTarget) {
  static image::TargetDetector detector;
  draw_triangle(frame(), 0.0F);
  crop(frame(), 65, 0, 95, 120, window());
  const image::TargetDetection alone = detector.detect(window());
  CHECK(alone.found);
  LONGS_EQUAL(1, alone.box_u_min);
  for (std::uint32_t v = 30; v <= 70; ++v) set_pixel(window(), 0, v, kTargetGreen);
  CHECK_FALSE(detector.detect(window()).found);
}

// The same along the frame's top edge: the triangle's top row in the frame's second row, and
// green along the first row above it, which the flood reaches first (raster order). One blob
// touching the edge, refused; never a blob of the triangle alone, cut off from the green by a
// flood that does not go down from the first row.
TEST(Target, ATriangleJoinedToGreenAlongTheFramesTopEdgeIsNotTheTarget) {
  static image::TargetDetector detector;
  draw_triangle(frame(), 0.0F);
  const image::TargetDetection drawn = detector.detect(frame());
  CHECK(drawn.found);
  const std::uint32_t v0 = drawn.box_v_min - 1;
  crop(frame(), 0, v0, 160, 120 - v0, window());
  const image::TargetDetection alone = detector.detect(window());
  CHECK(alone.found);
  LONGS_EQUAL(1, alone.box_v_min);
  for (std::uint32_t u = alone.box_u_min; u <= alone.box_u_max; ++u) {
    set_pixel(window(), u, 0, kTargetGreen);
  }
  CHECK_FALSE(detector.detect(window()).found);
}

// The detector has no side: a dark patch on the paper left of the triangle lowers its
// confidence as much as the same patch does right of it, in the frame mirrored (the paper
// around the triangle is looked at on every side alike).
TEST(Target, AFrameAndItsMirrorImageGiveTheSameConfidence) {
  static image::TargetDetector detector;
  draw_triangle(frame(), 0.0F);
  const image::TargetDetection clean = detector.detect(frame());
  CHECK(clean.found);
  for (std::uint32_t v = clean.box_v_min; v <= clean.box_v_max; ++v) {
    for (std::uint32_t u = clean.box_u_min - 4; u < clean.box_u_min - 1; ++u) {
      set_pixel(frame(), u, v, Colour{40.0F, 0, 0});
    }
  }
  const image::TargetDetection left = detector.detect(frame());
  CHECK(left.found);
  CHECK(left.confidence < clean.confidence - 0.01F);
  mirror(frame(), window());
  const image::TargetDetection right = detector.detect(window());
  CHECK(right.found);
  DOUBLES_EQUAL(left.confidence, right.confidence, 1e-5);
  LONGS_EQUAL(frame().width - 1 - left.box_u_max, right.box_u_min);
}

// A dark rim left of the triangle (its shadow) touches it: mixed pixels, neither paper nor
// triangle, which do not count against the paper around it, also where the rim lies in the
// frame's first column (the triangle's bottom row starting in the second): the confidence and
// the vertex are those without the shadow.
TEST(Target, AShadowTouchingTheTriangleDoesNotLowerItsConfidenceAlsoAtTheFramesEdge) {
  static image::TargetDetector detector;
  for (const std::uint32_t u0 : {0U, 65U}) {
    draw_triangle(frame(), 0.0F);
    crop(frame(), u0, 0, 160 - u0, 120, window());
    const image::TargetDetection clean = detector.detect(window());
    CHECK(clean.found);
    for (std::uint32_t v = 41; v < 64; ++v) {
      for (std::uint32_t u = 1; u < window().width; ++u) {
        if (window().cr(u, v) == kTargetGreen.cr) {
          set_pixel(window(), u - 1, v, Colour{40.0F, 0, 0});
          break;
        }
      }
    }
    const image::TargetDetection shadowed = detector.detect(window());
    CHECK(shadowed.found);
    DOUBLES_EQUAL(clean.confidence, shadowed.confidence, 1e-6);
    DOUBLES_EQUAL(clean.u_px, shadowed.u_px, 1e-6);
    DOUBLES_EQUAL(clean.v_px, shadowed.v_px, 1e-6);
  }
}

// Far off and seen 60° aside the triangle is a few pixels across: drawn 6 rows high, 0.29 px a
// row wider each side, no pixel of its blob has all four neighbours in it. Its colour is then
// judged from its greenest pixel (the reference chroma, the luma and the green's share of the
// paper's brightness), and it is found, its vertex within 0.05 px of where it is drawn.
TEST(Target, ATriangleTooThinForAnInteriorIsJudgedByItsGreenestPixelAndFound) {
  static image::TargetDetector detector;
  const image::TargetParams& p = detector.params();
  const auto grows = [&](std::uint32_t u, std::uint32_t v) {
    const float bright = std::fmax(0.0F, frame().y(u, v) - p.black_luma);
    const auto minus_cr = static_cast<float>(-frame().cr(u, v));
    return minus_cr >= p.grow_min_chroma && minus_cr >= p.grow_min_cr_ratio * bright &&
           static_cast<float>(-frame().cb(u, v)) >= p.grow_min_cb_ratio * bright;
  };
  for (const float apex_v : {40.25F, 40.5F}) {
    draw_smooth_triangle(frame(), 80.5F, apex_v, 6.0F, kEvenLight, 0.29F);
    const image::TargetDetection d = detector.detect(frame());
    CHECK(d.found);
    DOUBLES_EQUAL(80.5, d.u_px, 0.05);
    DOUBLES_EQUAL(apex_v, d.v_px, 0.05);
    for (std::uint32_t v = d.box_v_min; v <= d.box_v_max; ++v) {
      for (std::uint32_t u = d.box_u_min; u <= d.box_u_max; ++u) {
        CHECK_FALSE(grows(u, v) && grows(u - 1, v) && grows(u + 1, v) && grows(u, v - 1) &&
                    grows(u, v + 1));
      }
    }
  }
}

// A row's extent is measured over its run and two pixels beyond each end, within the frame's
// row: green along the frame's left edge is nothing to a triangle one column of paper from the
// right edge, and the vertex is where it was without it.
TEST(Target, GreenAlongTheFramesLeftEdgeDoesNotMoveATriangleAtItsRightEdge) {
  static image::TargetDetector detector;
  draw_smooth_triangle(frame(), 80.0F, 40.0F, 8.0F, kEvenLight);
  crop(frame(), 0, 0, 86, 120, window());
  const image::TargetDetection alone = detector.detect(window());
  CHECK(alone.found);
  LONGS_EQUAL(84, alone.box_u_max);
  for (std::uint32_t v = 44; v < window().height; ++v) set_pixel(window(), 0, v, kTargetGreen);
  const image::TargetDetection beside = detector.detect(window());
  CHECK(beside.found);
  DOUBLES_EQUAL(alone.u_px, beside.u_px, 1e-6);
  DOUBLES_EQUAL(alone.v_px, beside.v_px, 1e-6);
  DOUBLES_EQUAL(80.0, beside.u_px, 0.02);
  DOUBLES_EQUAL(40.0, beside.v_px, 0.02);
}

// The colour contrast with the paper is the distance between their mean chromas, at least 3
// levels: under tinted light a triangle exactly 3 levels from the paper's colour in Cb alone or
// in Cr alone is the target, and one 2 levels from it in either is not.
TEST(Target, ATriangleThreeChromaLevelsFromThePapersColourInCbOrCrAloneIsTheTarget) {
  static image::TargetDetector detector;
  const Colour tinted_paper{200.0F, -15, -6};
  struct Case {
    int dcb;
    int dcr;
    bool found;
  };
  constexpr Case kCases[] = {{0, -3, true}, {-3, 0, true}, {0, -2, false}, {-2, 0, false}};
  for (const Case& c : kCases) {
    draw_triangle(frame(), 0.0F, Colour{30.0F, tinted_paper.cb + c.dcb, tinted_paper.cr + c.dcr},
                  tinted_paper);
    CHECK_EQUAL_TEXT(c.found, detector.detect(frame()).found, "chroma offset from the paper");
  }
}

// The green's share of the paper's brightness must leave the paper more than 3 grey levels
// brighter than the triangle (at the paper's mean brightness). In a dark scene, paper 8 levels
// above black, a triangle 5 levels above black (3 darker: its share is exactly 1 − 3/8, the
// paper's fitted plane coming out exactly flat) is not the target, and one 4 above black is.
TEST(Target, InTheDarkATriangleOnlyThreeGreyLevelsDarkerThanThePaperIsNotTheTarget) {
  static image::TargetDetector detector;
  const Colour dark_paper{24.0F, 0, 0};
  draw_triangle(frame(), 0.0F, Colour{21.0F, -3, -5}, dark_paper);
  CHECK_FALSE(detector.detect(frame()).found);
  draw_triangle(frame(), 0.0F, Colour{20.0F, -3, -5}, dark_paper);
  CHECK(detector.detect(frame()).found);
}

namespace {

// A triangle whose sides step exactly half a pixel a row, vertex up above column 80: its row k
// (from row 40) is top_width + k pixels wide, whole green pixels and, when that width is even, a
// pixel half green at each end; the paper twice as bright above black as the green. The paper's
// fitted plane comes out exactly flat, and each row's extent is exact, and so are the lines
// fitted to them.
void draw_stepped_triangle(image::LowResFrame& f, int top_width, int rows) {
  const Colour paper{144.0F, 0, 0};
  const Colour green{80.0F, -20, -40};
  const Colour half{112.0F, -10, -20};
  f.width = 160;
  f.height = 120;
  for (std::uint32_t v = 0; v < f.height; ++v) {
    for (std::uint32_t u = 0; u < f.width; ++u) set_pixel(f, u, v, paper);
  }
  for (int k = 0; k < rows; ++k) {
    const int width = top_width + k;
    const auto v = static_cast<std::uint32_t>(40 + k);
    const int whole_half = (width - 1) / 2;  // whole pixels 80 ± this
    for (int j = -whole_half; j <= whole_half; ++j) {
      set_pixel(f, static_cast<std::uint32_t>(80 + j), v, green);
    }
    if (width % 2 == 0) {
      set_pixel(f, static_cast<std::uint32_t>(80 - width / 2), v, half);
      set_pixel(f, static_cast<std::uint32_t>(80 + width / 2), v, half);
    }
  }
}

}  // namespace

// The vertex may lie up to two rows above the blob's top row (a tip too thin to be seen): the
// triangle whose top row is 2 px wide, its edges meeting exactly two rows above it, is the
// target with its vertex there; with a top row 3 px wide, three rows above it, it is not.
TEST(Target, ATriangleWhoseEdgesMeetExactlyTwoRowsAboveItsTopRowIsTheTarget) {
  static image::TargetDetector detector;
  draw_stepped_triangle(frame(), 2, 16);
  const image::TargetDetection d = detector.detect(frame());
  CHECK(d.found);
  LONGS_EQUAL(40, d.box_v_min);
  DOUBLES_EQUAL(80.0, d.u_px, 1e-9);
  DOUBLES_EQUAL(38.0, d.v_px, 1e-9);
  draw_stepped_triangle(frame(), 3, 16);
  CHECK_FALSE(detector.detect(frame()).found);
}
