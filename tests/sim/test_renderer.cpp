// Tests of the ray caster: depth against analytic geometry, the target where the geometry puts
// it, deterministic noise, texture statistics, no allocation per frame.
#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>
#include <string>
#include <vector>

#include "algo/stereo/rig.h"
#include "hal/sim/renderer.h"
#include "hal/sim/sim_world.h"
#include "hal/sim/textures.h"
#include "hal/sim/world.h"
#include "sim_test_worlds.h"

#include "alloc_guard.h"
#include "CppUTest/TestHarness.h"

using namespace boticelli::hal::sim;
using boticelli::hal::sim::test::box_model;
using boticelli::hal::sim::test::small_world;
using boticelli::hal::sim::test::world_path;
using boticelli::stereo::CameraIntrinsics;

namespace {

World g_world;
TextureBank g_bank;
SimWorld g_sim;
char g_error[256];

CameraIntrinsics small_camera(float k1 = 0.0F) {
  CameraIntrinsics c;
  c.width_px = 160;
  c.height_px = 120;
  c.focal_px = 150.0F;
  c.principal_x_px = 79.5F;
  c.principal_y_px = 59.5F;
  c.k1 = k1;
  return c;
}

// Camera at `eye` looking along world +x (camera z), image x to world −y, image y to world −z.
RigidTransform looking_along_x(const Eigen::Vector3f& eye) {
  RigidTransform t;
  t.rotation << 0, 0, 1, -1, 0, 0, 0, -1, 0;
  t.translation_m = eye;
  return t;
}

void load_text(const std::string& xml) {
  CHECK_TEXT(parse_world(xml.c_str(), xml.size(), "test.sdf", g_world, g_error, sizeof g_error),
             g_error);
  CHECK_TEXT(g_bank.build(g_world, g_error, sizeof g_error), g_error);
}

void load_file(const char* name) {
  const std::string path = world_path(name);
  CHECK_TEXT(load_world(path.c_str(), g_world, g_error, sizeof g_error), g_error);
  CHECK_TEXT(g_bank.build(g_world, g_error, sizeof g_error), g_error);
}

void start_renderer(Renderer& renderer, const CameraIntrinsics& camera,
                    const RenderSettings& settings = {}) {
  CHECK_TEXT(renderer.init(g_world, g_bank, camera, settings, g_error, sizeof g_error), g_error);
}

// Decoded colour of pixel (u, v) of a YUYV image (BT.601 limited range).
struct Yuv {
  int y, u, v;
};
Yuv pixel(const std::vector<std::uint8_t>& img, std::uint32_t width, std::uint32_t u,
          std::uint32_t v) {
  const std::size_t pair = (static_cast<std::size_t>(v) * width + (u & ~1U)) * 2;
  return {img[pair + (u & 1U) * 2], img[pair + 1], img[pair + 3]};
}
bool is_green(const Yuv& p) {
  return p.u < 122 && p.v < 115;
}

}  // namespace

TEST_GROUP(Renderer){void setup() override{g_error[0] = '\0';
}
}
;

TEST(Renderer, DepthOfAFrontoParallelWallEqualsTheDistanceToIt) {
  // A wall whose near face is the plane x = 3.
  load_text(small_world(box_model("wall", "3.5 0 1 0 0 0", "1 20 4")));
  Renderer renderer;  // local: its buffers are freed with the test
  start_renderer(renderer, small_camera());
  std::vector<float> depth(160 * 120);
  renderer.render(looking_along_x({0, 0, 1}), 0, nullptr, 0, depth.data());
  for (float d : depth) DOUBLES_EQUAL(3.0, d, 1e-4);
}

TEST(Renderer, DepthOfATiltedFloorPlaneMatchesTheAnalyticRayIntersection) {
  // The floor seen from 0.8 m, the camera pitched 30° down, with radial distortion.
  load_text(small_world(
      "<model name=\"floor\"><link name=\"l\"><visual name=\"v\"><geometry><plane>"
      "<normal>0 0 1</normal><size>200 200</size></plane></geometry></visual></link></model>"));
  const CameraIntrinsics camera = small_camera(-0.08F);
  Renderer renderer;  // local: its buffers are freed with the test
  start_renderer(renderer, camera);
  RigidTransform pose = looking_along_x({0.5F, -0.2F, 0.8F});
  const float pitch = 0.5235988F;
  Eigen::Matrix3f down;  // rotation about the world y axis tipping +x towards −z
  down << std::cos(pitch), 0, std::sin(pitch), 0, 1, 0, -std::sin(pitch), 0, std::cos(pitch);
  pose.rotation = down * pose.rotation;
  std::vector<float> depth(160 * 120);
  renderer.render(pose, 0, nullptr, 0, depth.data());
  int floor_pixels = 0;
  for (std::uint32_t v = 0; v < 120; ++v) {
    for (std::uint32_t u = 0; u < 160; ++u) {
      const Eigen::Vector2f n = camera.normalized_from_pixel(
          Eigen::Vector2f(static_cast<float>(u), static_cast<float>(v)));
      const Eigen::Vector3f ray = pose.rotation * Eigen::Vector3f(n.x(), n.y(), 1.0F);
      const float d = depth[v * 160 + u];
      if (ray.z() < -1e-3F) {
        // Ray parameter to z = 0 is the z-depth, since the ray's camera z is 1.
        const float expected = -pose.translation_m.z() / ray.z();
        if (expected < 40.0F) {  // well inside the 200 x 200 m plane
          DOUBLES_EQUAL(expected, d, 1e-4 * static_cast<double>(expected));
          // The reconstructed point projects back to the same pixel.
          Eigen::Vector2f back;
          CHECK(camera.project(Eigen::Vector3f(n.x() * d, n.y() * d, d), back));
          DOUBLES_EQUAL(static_cast<double>(u), back.x(), 1e-2);
          DOUBLES_EQUAL(static_cast<double>(v), back.y(), 1e-2);
          ++floor_pixels;
        }
      } else {
        CHECK(std::isinf(d));  // sky: nothing hit
      }
    }
  }
  CHECK(floor_pixels > 160 * 60);
}

TEST(Renderer, DepthOfACylinderFollowsItsCurvedSurface) {
  load_text(small_world(
      "<model name=\"pillar\"><pose>4 0 1 0 0 0</pose><link name=\"l\"><visual name=\"v\">"
      "<geometry><cylinder><radius>0.5</radius><length>2</length></cylinder></geometry>"
      "</visual></link></model>"));
  Renderer renderer;  // local: its buffers are freed with the test
  start_renderer(renderer, small_camera());
  std::size_t surface = 0;
  float d = 0.0F;
  // The optical axis hits the front of the pillar at x = 3.5.
  CHECK(renderer.trace_pixel(looking_along_x({0, 0, 1}), 80, 60, surface, d));
  STRCMP_EQUAL("pillar", g_world.surfaces[surface].model);
  DOUBLES_EQUAL(3.5, d, 2e-3);
  std::vector<float> depth(160 * 120);
  renderer.render(looking_along_x({0, 0, 1}), 0, nullptr, 0, depth.data());
  for (std::uint32_t u = 0; u < 160; ++u) {
    // Row through the optical centre height: a ray at slope s hits the circle
    // (x − 4)² + y² = 0.25 at x solving (1 + s²) x² − 8x + 15.75 = 0.
    const float s = (static_cast<float>(u) - 79.5F) / 150.0F;
    const float a = 1.0F + s * s;
    const float disc = 64.0F - 4.0F * a * 15.75F;
    const float got = 0.5F * (depth[59 * 160 + u] + depth[60 * 160 + u]);
    if (disc > 0.01F) {
      DOUBLES_EQUAL((8.0F - std::sqrt(disc)) / (2.0F * a), got, 5e-3);
    } else if (disc < -0.01F) {
      CHECK(got > 4.5F);  // past the pillar: the target's box or nothing
    }
  }
}

TEST(Renderer, TheTargetIsGreenWhereTheGeometryProjectsIt) {
  load_file("cylindrical_room");
  const CameraIntrinsics camera = small_camera();
  Renderer renderer;  // local: its buffers are freed with the test
  start_renderer(renderer, camera);
  const boticelli::stereo::RigModel rig;
  CHECK_TEXT(g_sim.init(g_world, rig, SimParams{}, g_error, sizeof g_error), g_error);
  const RigidTransform pose = g_sim.camera_pose(g_world.start, 0.0F, 0.05F);
  std::vector<std::uint8_t> img(160 * 120 * 2);
  renderer.render(pose, 0, img.data(), 320, nullptr);
  // Project the triangle's centroid and the paper beside it through the camera model.
  const Surface& s = g_world.surfaces[g_world.target_surface];
  const TargetFace face = target_face_frame(s);
  const Eigen::Vector3f centroid =
      g_world.target_point_m - face.up * (s.target_size_m / std::sqrt(3.0F));
  const Eigen::Vector3f paper = face.centre_m - face.up * 0.13F;  // below the triangle's base
  auto project = [&](const Eigen::Vector3f& world_point) {
    const Eigen::Vector3f c = pose.rotation.transpose() * (world_point - pose.translation_m);
    Eigen::Vector2f px;
    CHECK(camera.project(c, px));
    return px;
  };
  const Eigen::Vector2f pc = project(centroid);
  const Eigen::Vector2f pp = project(paper);
  const Eigen::Vector2f pv = project(g_world.target_point_m);
  const auto u_c = static_cast<std::uint32_t>(std::lround(pc.x()));
  const auto v_c = static_cast<std::uint32_t>(std::lround(pc.y()));
  CHECK(is_green(pixel(img, 160, u_c, v_c)));
  const Yuv white = pixel(img, 160, static_cast<std::uint32_t>(std::lround(pp.x())),
                          static_cast<std::uint32_t>(std::lround(pp.y())));
  CHECK(!is_green(white));
  CHECK(white.y > 100);
  // Just above the upper vertex is paper, a little below it is green (chroma is shared by
  // pixel pairs, so look where the triangle is a few pixels wide).
  const auto u_v = static_cast<std::uint32_t>(std::lround(pv.x()));
  CHECK(!is_green(pixel(img, 160, u_v, static_cast<std::uint32_t>(std::lround(pv.y() - 1.5F)))));
  CHECK(is_green(pixel(img, 160, u_v, static_cast<std::uint32_t>(std::lround(pv.y() + 5.0F)))));
  // The depth at the centroid is the distance to the face along the optical axis.
  std::size_t surface = 0;
  float d = 0.0F;
  CHECK(renderer.trace_pixel(pose, u_c, v_c, surface, d));
  UNSIGNED_LONGS_EQUAL(g_world.target_surface, surface);
  const Eigen::Vector3f c = pose.rotation.transpose() * (centroid - pose.translation_m);
  DOUBLES_EQUAL(c.z(), d, 0.02);
}

TEST(Renderer, TheThesisRoomTargetIsHiddenFromTheStartAndVisibleBehindThePartition) {
  load_file("thesis_room");
  Renderer renderer;  // local: its buffers are freed with the test
  start_renderer(renderer, small_camera());
  const boticelli::stereo::RigModel rig;
  CHECK_TEXT(g_sim.init(g_world, rig, SimParams{}, g_error, sizeof g_error), g_error);
  std::vector<std::uint8_t> img(160 * 120 * 2);
  auto green_pixels = [&](const boticelli::core::Pose2& robot) {
    // Look straight at the target: pan towards it in the robot frame.
    const float bearing =
        std::atan2(g_world.target_point_m.y() - robot.y_m, g_world.target_point_m.x() - robot.x_m);
    const float pan = std::remainder(bearing - robot.yaw_rad, 6.2831853F);
    renderer.render(g_sim.camera_pose(robot, pan, 0.2F), 0, img.data(), 320, nullptr);
    int n = 0;
    for (std::uint32_t v = 0; v < 120; ++v) {
      for (std::uint32_t u = 0; u < 160; ++u) n += is_green(pixel(img, 160, u, v)) ? 1 : 0;
    }
    return n;
  };
  CHECK_EQUAL(0, green_pixels(g_world.start));
  CHECK(green_pixels({-1.0F, 1.8F, 1.57F}) > 10);
}

TEST(Renderer, IdenticalSeedsGiveIdenticalFramesAndNoiseIsSeeded) {
  load_file("thesis_room");
  RenderSettings settings;
  settings.seed = 42;
  Renderer renderer;  // local: its buffers are freed with the test
  start_renderer(renderer, small_camera(-0.05F), settings);
  const boticelli::stereo::RigModel rig;
  CHECK_TEXT(g_sim.init(g_world, rig, SimParams{}, g_error, sizeof g_error), g_error);
  const RigidTransform pose = g_sim.camera_pose(g_world.start, 0.3F, -0.1F);
  std::vector<std::uint8_t> a(160 * 120 * 2), b(160 * 120 * 2), c(160 * 120 * 2);
  renderer.render(pose, 7, a.data(), 320, nullptr);
  renderer.render(pose, 7, b.data(), 320, nullptr);
  CHECK(a == b);
  renderer.render(pose, 8, c.data(), 320, nullptr);
  CHECK(a != c);  // the next frame has fresh noise
  settings.seed = 43;
  renderer.set_settings(settings);
  renderer.render(pose, 7, c.data(), 320, nullptr);
  CHECK(a != c);
  // Without noise the frames differ from the noisy ones by about the noise level only.
  settings.noise_sigma_grey = 0.0F;
  renderer.set_settings(settings);
  renderer.render(pose, 7, c.data(), 320, nullptr);
  double sum2 = 0.0;
  for (std::size_t i = 0; i < a.size(); i += 2) {
    const double e = static_cast<double>(a[i]) - static_cast<double>(c[i]);
    sum2 += e * e;
  }
  DOUBLES_EQUAL(2.0, std::sqrt(sum2 / (static_cast<double>(a.size()) / 2.0)), 0.3);
}

TEST(Renderer, VignettingDarkensTheCornersOfAUniformWall) {
  load_text(small_world(box_model("wall", "3.5 0 1 0 0 0", "1 20 4")));
  RenderSettings settings;
  settings.noise_sigma_grey = 0.0F;
  settings.vignetting = 0.3F;
  Renderer renderer;  // local: its buffers are freed with the test
  start_renderer(renderer, small_camera(), settings);
  std::vector<std::uint8_t> img(160 * 120 * 2);
  renderer.render(looking_along_x({0, 0, 1}), 0, img.data(), 320, nullptr);
  const double centre = pixel(img, 160, 80, 60).y - 16.0;
  const double corner = pixel(img, 160, 0, 0).y - 16.0;
  DOUBLES_EQUAL(0.7, corner / centre, 0.03);
}

TEST(Renderer, CamouflageHasStrongVerticalChangesAndLeavesWeakOnes) {
  load_file("thesis_room");  // camouflage walls and the leaves of the tree
  int camouflage = -1;
  int leaves = -1;
  for (std::size_t i = 0; i < g_world.surface_count; ++i) {
    if (g_world.surfaces[i].pattern == Pattern::kCamouflage)
      camouflage = g_world.surfaces[i].texture;
    if (g_world.surfaces[i].pattern == Pattern::kLeaves) leaves = g_world.surfaces[i].texture;
  }
  CHECK(camouflage >= 0 && leaves >= 0);
  auto derivatives = [](int texture, double& along_u, double& along_v) {
    along_u = along_v = 0.0;
    for (std::uint32_t y = 0; y + 1 < kTextureSize; ++y) {
      for (std::uint32_t x = 0; x + 1 < kTextureSize; ++x) {
        const int t = g_bank.texel(texture, x, y);
        along_u += std::abs(g_bank.texel(texture, x + 1, y) - t);
        along_v += std::abs(g_bank.texel(texture, x, y + 1) - t);
      }
    }
  };
  double cu = 0.0, cv = 0.0, lu = 0.0, lv = 0.0;
  derivatives(camouflage, cu, cv);
  derivatives(leaves, lu, lv);
  CHECK(cv / cu > 0.8);  // blotches: as many vertical as horizontal changes
  CHECK(lv / lu < 0.3);  // streaks: weak vertical derivative
  CHECK(cv > 3.0 * lv);  // and the cloth is far busier vertically than the leaves
}

TEST(Renderer, EveryShippedWorldIsClosedBelowTheHorizonAllAround) {
  // From the start, looking round at 8 pans with the camera level: every ray below the
  // horizon hits the floor or something on it — no holes, no NaN.
  const boticelli::stereo::RigModel rig;
  std::vector<float> depth(160 * 120);
  for (const char* name : boticelli::hal::sim::test::kShippedWorlds) {
    load_file(name);
    Renderer renderer;
    start_renderer(renderer, small_camera());
    CHECK_TEXT(g_sim.init(g_world, rig, SimParams{}, g_error, sizeof g_error), g_error);
    for (int k = 0; k < 8; ++k) {
      const float pan = -2.7F + 5.4F * static_cast<float>(k) / 7.0F;
      renderer.render(g_sim.camera_pose(g_world.start, pan, 0.0F), 0, nullptr, 0, depth.data());
      for (std::uint32_t v = 72; v < 120; ++v) {  // 4.8° and more below the horizon
        for (std::uint32_t u = 0; u < 160; ++u) {
          const float d = depth[v * 160 + u];
          CHECK_TEXT(std::isfinite(d) && d > 0.05F && d < 25.0F, name);
        }
      }
    }
  }
}

TEST(Renderer, RenderingAFrameDoesNotAllocate) {
  load_file("thesis_room");
  Renderer renderer;  // local: its buffers are freed with the test
  start_renderer(renderer, small_camera());
  std::vector<std::uint8_t> img(160 * 120 * 2);
  std::vector<float> depth(160 * 120);
  const RigidTransform pose = looking_along_x({0, -1, 0.8F});
  CHECK_NO_ALLOCATION(renderer.render(pose, 1, img.data(), 320, depth.data()));
}

// Chroma noise: Cb and Cr of a plain wall scatter by about chroma_noise_sigma, seeded like the
// luma's. Exposure jitter: each frame's brightness is scaled by one draw of 1 + jitter · g, so
// frames of the same view differ as a whole, and the same frame index repeats itself.
TEST(Renderer, ChromaNoiseScattersCbAndCrAndExposureJitterScalesWholeFrames) {
  load_text(small_world(box_model("wall", "3.5 0 1 0 0 0", "1 20 4")));
  RenderSettings settings;
  settings.noise_sigma_grey = 0.0F;
  settings.vignetting = 0.0F;
  Renderer renderer;  // local: its buffers are freed with the test
  start_renderer(renderer, small_camera(), settings);
  std::vector<std::uint8_t> clean(160 * 120 * 2);
  std::vector<std::uint8_t> img(160 * 120 * 2);
  const RigidTransform view = looking_along_x({0, 0, 1});
  renderer.render(view, 0, clean.data(), 320, nullptr);
  settings.chroma_noise_sigma = 3.0F;
  renderer.set_settings(settings);
  renderer.render(view, 0, img.data(), 320, nullptr);
  double luma2 = 0.0;
  double cb2 = 0.0;
  double cr2 = 0.0;
  for (std::size_t i = 0; i < img.size(); i += 4) {
    const auto d = [&](std::size_t k) {
      return static_cast<double>(img[i + k]) - static_cast<double>(clean[i + k]);
    };
    luma2 += d(0) * d(0) + d(2) * d(2);
    cb2 += d(1) * d(1);
    cr2 += d(3) * d(3);
  }
  const double pairs = static_cast<double>(img.size()) / 4.0;
  DOUBLES_EQUAL(0.0, luma2, 0.0);  // luma untouched
  DOUBLES_EQUAL(3.0, std::sqrt(cb2 / pairs), 0.3);
  DOUBLES_EQUAL(3.0, std::sqrt(cr2 / pairs), 0.3);

  settings.chroma_noise_sigma = 0.0F;
  settings.exposure_jitter = 0.05F;
  renderer.set_settings(settings);
  // Each frame's luma above black is the clean frame's times one factor.
  std::vector<double> factors;
  for (std::uint32_t frame = 0; frame < 40; ++frame) {
    renderer.render(view, frame, img.data(), 320, nullptr);
    const double ratio = (pixel(img, 160, 80, 60).y - 16.0) / (pixel(clean, 160, 80, 60).y - 16.0);
    DOUBLES_EQUAL(
        ratio, (pixel(img, 160, 20, 100).y - 16.0) / (pixel(clean, 160, 20, 100).y - 16.0), 0.02);
    factors.push_back(ratio);
  }
  double mean = 0.0;
  for (const double f : factors) mean += f / static_cast<double>(factors.size());
  double var = 0.0;
  for (const double f : factors)
    var += (f - mean) * (f - mean) / static_cast<double>(factors.size());
  DOUBLES_EQUAL(1.0, mean, 0.03);
  DOUBLES_EQUAL(0.05, std::sqrt(var), 0.025);
  std::vector<std::uint8_t> again(160 * 120 * 2);
  renderer.render(view, 39, again.data(), 320, nullptr);
  CHECK(again == img);
}
