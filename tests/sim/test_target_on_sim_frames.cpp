// Target detection on the sim board's own frames: found at 0.5–4 m and ±60°, triangulated, never
// without it.
#include <Eigen/Core>
#include <algorithm>
#include <chrono>
#include <array>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <string>
#include <vector>

#include "algo/core/geometry.h"
#include "algo/evidence/sensor_model.h"
#include "algo/image/low_res_frame.h"
#include "algo/image/target_detector.h"
#include "algo/stereo/rig.h"
#include "algo/stereo/stereo_processor.h"
#include "board_config.h"
#include "hal/sim/renderer.h"
#include "hal/sim/sim_world.h"
#include "hal/sim/textures.h"
#include "hal/sim/world.h"
#include "sim_test_worlds.h"

#include "alloc_guard.h"
#include "CppUTest/TestHarness.h"

using namespace boticelli;
using hal::sim::RigidTransform;
using hal::sim::test::kShippedWorlds;

namespace {

constexpr std::size_t kWorldCount = sizeof(kShippedWorlds) / sizeof(kShippedWorlds[0]);
constexpr float kDegree = 0.017453293F;

// The sim board's robot, as boards/sim builds it.
const firmware::BoardConfig& config() {
  static const firmware::BoardConfig instance = boards::sim::make_config();
  return instance;
}
const stereo::RigModel& rig() {
  static const stereo::RigModel instance(boards::sim::make_rig_params(config()));
  return instance;
}

// Every shipped world, loaded once (the loader's allocations are freed before it returns).
hal::sim::World& shipped(std::size_t k) {
  static hal::sim::World worlds[kWorldCount];
  static bool loaded[kWorldCount] = {};
  if (!loaded[k]) {
    char error[256];
    const std::string path = hal::sim::test::world_path(kShippedWorlds[k]);
    CHECK_TEXT(hal::sim::load_world(path.c_str(), worlds[k], error, sizeof error), error);
    loaded[k] = true;
  }
  return worlds[k];
}

// One world drawn by the sim board's renderer (textures, settings and camera as the board
// has them) with the board's ground-truth kinematics. Lives for one test (the renderer
// allocates at init).
class SimCamera {
 public:
  explicit SimCamera(hal::sim::World& world, std::uint64_t seed = 1) : world_(world) {
    const boards::sim::SimSettings settings = boards::sim::make_settings(config(), seed);
    char error[256];
    CHECK_TEXT(bank().build(world_, error, sizeof error), error);
    CHECK_TEXT(renderer_.init(world_, bank(), rig().camera(), settings.render, error, sizeof error),
               error);
    CHECK_TEXT(sim_.init(world_, rig(), settings.physics, error, sizeof error), error);
    yuyv_.resize(std::size_t{rig().camera().width_px} * rig().camera().height_px * 2);
  }

  const hal::sim::World& world() const { return world_; }
  hal::sim::SimWorld& sim() { return sim_; }

  // Renders the view and averages it to the processing resolution, as
  // StereoProcessor::process_yuyv does.
  void grab(const RigidTransform& camera, std::uint32_t frame_index, image::LowResFrame& out) {
    const std::uint32_t w = rig().camera().width_px;
    const std::uint32_t h = rig().camera().height_px;
    renderer_.render(camera, frame_index, yuyv_.data(), std::size_t{w} * 2, nullptr);
    CHECK(image::downsample_yuyv(yuyv_.data(), w, h, w * 2, rig().params().downsample_factor, out));
  }

 private:
  static hal::sim::TextureBank& bank() {
    static hal::sim::TextureBank instance;
    return instance;
  }

  hal::sim::World& world_;
  hal::sim::Renderer renderer_;
  hal::sim::SimWorld sim_;
  std::vector<std::uint8_t> yuyv_;
};

// Where the robot stands and how the PTU points.
struct View {
  core::Pose2 robot;
  float pan_rad = 0.0F;
  float tilt_rad = 0.0F;
};

// The robot `distance_m` (camera to the triangle's centre, about) from the target and
// `angle_rad` aside from the face's normal, facing it with the PTU panned by `pan_rad`;
// the PTU tilts to the triangle's centre, then by `extra_tilt_rad` more. The pan and tilt
// axes meet on the optical axis (Ω = 0), so aiming from the PTU centre aims the camera.
View facing_target(const hal::sim::World& world, float distance_m, float angle_rad, float pan_rad,
                   float extra_tilt_rad) {
  const hal::sim::TargetFace face =
      hal::sim::target_face_frame(world.surfaces[world.target_surface]);
  const Eigen::Vector2f normal = Eigen::Vector2f(face.normal.x(), face.normal.y()).normalized();
  const float c = std::cos(angle_rad);
  const float s = std::sin(angle_rad);
  const Eigen::Vector2f out(c * normal.x() - s * normal.y(), s * normal.x() + c * normal.y());
  const float rise = face.centre_m.z() - rig().params().ptu_height_m;
  const float reach = distance_m + rig().params().lever_m;  // PTU centre to the target
  const float across = std::sqrt(std::max(0.01F, reach * reach - rise * rise));
  View view;
  view.robot.x_m = face.centre_m.x() + across * out.x();
  view.robot.y_m = face.centre_m.y() + across * out.y();
  view.robot.yaw_rad = std::atan2(-out.y(), -out.x()) - pan_rad;
  view.pan_rad = pan_rad;
  view.tilt_rad = std::atan2(rise, across) + extra_tilt_rad;
  return view;
}

// The PTU frame in the world for a robot pose (as SimWorld::camera_pose builds it).
RigidTransform world_from_ptu(const core::Pose2& robot) {
  RigidTransform t;
  const float c = std::cos(robot.yaw_rad);
  const float s = std::sin(robot.yaw_rad);
  t.rotation << c, -s, 0.0F, s, c, 0.0F, 0.0F, 0.0F, 1.0F;
  t.translation_m = Eigen::Vector3f(robot.x_m, robot.y_m, rig().params().ptu_height_m);
  return t;
}

// The camera in the world for a robot pose and PTU angles: the rig's kinematics after the
// robot's pose, as the sim camera draws it (checked against SimWorld::camera_pose below).
RigidTransform camera_in_world(const core::Pose2& robot, float pan_rad, float tilt_rad) {
  const stereo::CameraPose cam = rig().camera_pose(pan_rad, tilt_rad);
  return world_from_ptu(robot).then(RigidTransform{cam.rotation, cam.centre_m});
}

// Low-resolution pixel of a world point; false when it is behind the camera.
bool project(const RigidTransform& camera, const Eigen::Vector3f& point, Eigen::Vector2f& px) {
  const Eigen::Vector3f local = camera.rotation.transpose() * (point - camera.translation_m);
  return rig().low_res_camera().project(local, px);
}

bool inside_image(const Eigen::Vector2f& px, float margin_px) {
  const auto& cam = rig().low_res_camera();
  return px.x() >= margin_px && px.y() >= margin_px &&
         px.x() <= static_cast<float>(cam.width_px) - 1.0F - margin_px &&
         px.y() <= static_cast<float>(cam.height_px) - 1.0F - margin_px;
}

// The whole triangle in view: its vertices and centre unoccluded (the line of sight first
// meets the target's surface, so the camera is inside the room too) and well inside the image.
bool triangle_in_view(const hal::sim::World& world, const RigidTransform& camera) {
  const hal::sim::Surface& s = world.surfaces[world.target_surface];
  const hal::sim::TargetFace f = hal::sim::target_face_frame(s);
  const float circumradius = s.target_size_m * 0.57735027F;
  const Eigen::Vector3f points[4] = {
      world.target_point_m, f.centre_m,
      f.centre_m - 0.5F * circumradius * f.up - 0.5F * s.target_size_m * f.right,
      f.centre_m - 0.5F * circumradius * f.up + 0.5F * s.target_size_m * f.right};
  for (const Eigen::Vector3f& p : points) {
    std::size_t surface = 0;
    float t = 0.0F;
    Eigen::Vector2f px;
    if (!hal::sim::cast_ray(world, camera.translation_m, p - camera.translation_m, surface, t) ||
        surface != world.target_surface || t < 0.995F || !project(camera, p, px) ||
        !inside_image(px, 4.0F)) {
      return false;
    }
  }
  return true;
}

// The first shipped world (in the order of kShippedWorlds, starting at `from`) that has
// room for the view: the triangle wholly in view of the first frame (and the second, tilted
// down by Φ, if `pair`). kWorldCount if none.
std::size_t world_with_room_for(float distance_m, float angle_rad, float pan_rad,
                                float extra_tilt_rad, bool pair, std::size_t from = 0) {
  for (std::size_t n = 0; n < kWorldCount; ++n) {
    const std::size_t k = (from + n) % kWorldCount;
    const hal::sim::World& world = shipped(k);
    const View view = facing_target(world, distance_m, angle_rad, pan_rad, extra_tilt_rad);
    if (triangle_in_view(world, camera_in_world(view.robot, view.pan_rad, view.tilt_rad)) &&
        (!pair ||
         triangle_in_view(world, camera_in_world(view.robot, view.pan_rad,
                                                 view.tilt_rad - rig().params().tilt_step_rad)))) {
      return k;
    }
  }
  return kWorldCount;
}

std::size_t world_index(const char* name) {
  for (std::size_t k = 0; k < kWorldCount; ++k) {
    if (std::string(kShippedWorlds[k]) == name) return k;
  }
  FAIL(name);
  return 0;
}

image::LowResFrame& first_frame() {
  static image::LowResFrame instance;
  return instance;
}
image::LowResFrame& second_frame() {
  static image::LowResFrame instance;
  return instance;
}

// The stereo pair of a view (tilt, then tilt − Φ), grabbed into first_frame() and
// second_frame(), with the two cameras' true poses.
struct GrabbedPair {
  stereo::PairPose pair;
  RigidTransform first;
  RigidTransform second;
};
GrabbedPair grab_pair(SimCamera& camera, const View& view) {
  GrabbedPair g;
  g.pair = {view.pan_rad, view.tilt_rad, view.tilt_rad - rig().params().tilt_step_rad};
  g.first = camera.sim().camera_pose(view.robot, g.pair.pan_rad, g.pair.first_tilt_rad);
  g.second = camera.sim().camera_pose(view.robot, g.pair.pan_rad, g.pair.second_tilt_rad);
  camera.grab(g.first, 0, first_frame());
  camera.grab(g.second, 1, second_frame());
  return g;
}

struct Timing {
  double total_us = 0.0;
  int frames = 0;
  double max_us = 0.0;
};

image::TargetDetection timed_detect(image::TargetDetector& detector,
                                    const image::LowResFrame& frame, Timing& timing) {
  image::TargetDetection d;
  const auto start = std::chrono::steady_clock::now();
  CHECK_NO_ALLOCATION(d = detector.detect(frame));
  const double us =
      std::chrono::duration<double, std::micro>(std::chrono::steady_clock::now() - start).count();
  timing.total_us += us;
  timing.max_us = std::max(timing.max_us, us);
  ++timing.frames;
  return d;
}

// Renders one view facing the target and checks the detection: found, the vertex within
// `tolerance_px` of its true projection. The view must leave the triangle wholly in sight.
void check_view(SimCamera& camera, image::TargetDetector& detector, float distance_m,
                float angle_rad, float pan_rad, float extra_tilt_rad, float tolerance_px,
                Timing& timing) {
  const hal::sim::World& world = camera.world();
  const View view = facing_target(world, distance_m, angle_rad, pan_rad, extra_tilt_rad);
  const RigidTransform pose = camera.sim().camera_pose(view.robot, view.pan_rad, view.tilt_rad);
  CHECK_TEXT(triangle_in_view(world, pose), world.name);
  camera.grab(pose, 0, first_frame());
  const image::TargetDetection d = timed_detect(detector, first_frame(), timing);
  Eigen::Vector2f truth;
  CHECK(project(pose, world.target_point_m, truth));
  const float error = (Eigen::Vector2f(d.u_px, d.v_px) - truth).norm();
  const float range = (world.target_point_m - pose.translation_m).norm();
  // The paper's brightness just above the vertex, for the record.
  const float paper = first_frame().y(static_cast<std::uint32_t>(std::lround(truth.x())),
                                      static_cast<std::uint32_t>(std::lround(truth.y())) - 2);
  std::printf(
      "\n  %-26s %4.2f m %+4.0f°  paper Y %5.1f  %s  conf %.2f  area %4zu px  error %.2f px",
      world.name, static_cast<double>(range), static_cast<double>(angle_rad / kDegree),
      static_cast<double>(paper), d.found ? "found " : "MISSED", static_cast<double>(d.confidence),
      d.area_px, static_cast<double>(error));
  CHECK_TEXT(d.found, world.name);
  CHECK_TEXT(error < tolerance_px, world.name);
}

}  // namespace

TEST_GROUP(TargetOnSimFrames){};

TEST(TargetOnSimFrames, TheCameraIsWhereTheSimBoardPutsIt) {
  SimCamera camera(shipped(0));
  const core::Pose2 robot{0.3F, -0.2F, 0.7F};
  const RigidTransform mine = camera_in_world(robot, -0.4F, 0.2F);
  const RigidTransform sims = camera.sim().camera_pose(robot, -0.4F, 0.2F);
  CHECK((mine.translation_m - sims.translation_m).norm() < 1e-5F);
  CHECK((mine.rotation - sims.rotation).norm() < 1e-5F);
}

TEST(TargetOnSimFrames, TheVertexIsFoundFromHalfAMetreToFourMetresUpToSixtyDegreesAside) {
  struct Case {
    float distance_m;
    float angle_deg;
    std::size_t world;
  };
  // Two angles per distance, each in the first shipped world with room for it (from the
  // corridor on: it is long but narrow).
  Case cases[] = {{0.5F, 0.0F, 0},   {0.5F, 60.0F, 0},  {1.0F, -30.0F, 0}, {1.0F, -60.0F, 0},
                  {1.5F, 30.0F, 0},  {1.5F, -45.0F, 0}, {2.0F, 15.0F, 0},  {2.0F, 45.0F, 0},
                  {2.5F, 0.0F, 0},   {2.5F, 60.0F, 0},  {3.0F, -30.0F, 0}, {3.0F, 45.0F, 0},
                  {3.5F, -45.0F, 0}, {3.5F, 30.0F, 0},  {4.0F, 15.0F, 0},  {4.0F, 45.0F, 0}};
  for (Case& c : cases) {
    c.world = world_with_room_for(c.distance_m, c.angle_deg * kDegree, 0.0F, 0.0F, false,
                                  world_index("corridor"));
    CHECK_TEXT(c.world < kWorldCount, "no shipped world has room for the view");
  }
  image::TargetDetector detector{stereo::StereoParams{}.target};
  Timing timing;
  for (std::size_t k = 0; k < kWorldCount; ++k) {
    bool any = false;
    for (const Case& c : cases) any = any || c.world == k;
    if (!any) continue;
    SimCamera camera(shipped(k), 1 + k);
    for (const Case& c : cases) {
      if (c.world == k) {
        check_view(camera, detector, c.distance_m, c.angle_deg * kDegree, 0.0F, 0.0F, 1.0F, timing);
      }
    }
  }
  std::printf("\n  detect: %.0f µs mean, %.0f µs max over %d frames\n",
              timing.total_us / timing.frames, timing.max_us, timing.frames);
}

TEST(TargetOnSimFrames, TheVertexIsFoundUnderDimAndBrightAmbientLight) {
  static hal::sim::World world;
  Timing timing;
  image::TargetDetector detector;
  for (const float ambient : {0.3F, 0.5F, 0.7F}) {
    world = shipped(world_index("rectangular_room"));
    world.ambient = {ambient, ambient, ambient};
    SimCamera camera(world, 7);
    check_view(camera, detector, 1.0F, 40.0F * kDegree, 0.0F, 0.0F, 1.0F, timing);
    check_view(camera, detector, 3.5F, -15.0F * kDegree, 0.1F, 0.0F, 1.0F, timing);
  }
  std::printf("\n");
}

// With the mission's stereo settings: the range from the triangle's edges (the next test).
// The vertex alone is unbiased but its row carries the pixel grid's steps (the sim, like a
// camera without a lens' blur, samples each pixel at one point): over 180 pairs at 1-3 m its
// range is 2% off on average, 152 of them within 0.1 m (with the edges 168).
TEST(TargetOnSimFrames, APairLocatesTheTargetWithinTenCentimetresUpToThreeAndAHalfMetres) {
  static stereo::StereoProcessor processor{rig(),
                                           firmware::mission::make_mission_params(config()).stereo};
  const float phi = rig().params().tilt_step_rad;
  struct Case {
    float distance_m;
    float angle_deg;
  };
  for (const Case& c :
       {Case{0.6F, 20.0F}, Case{1.5F, -45.0F}, Case{2.5F, 10.0F}, Case{3.5F, 0.0F}}) {
    // The triangle's centre between the two frames' optical axes.
    const std::size_t k =
        world_with_room_for(c.distance_m, c.angle_deg * kDegree, 0.05F, 0.5F * phi, true,
                            static_cast<std::size_t>(c.distance_m));
    CHECK_TEXT(k < kWorldCount, "no world has room for a view");
    SimCamera camera(shipped(k), 3);
    const View view =
        facing_target(camera.world(), c.distance_m, c.angle_deg * kDegree, 0.05F, 0.5F * phi);
    const GrabbedPair grabbed = grab_pair(camera, view);
    const stereo::PairPose& pair = grabbed.pair;
    const RigidTransform& first = grabbed.first;
    stereo::TargetFix fix;
    CHECK_NO_ALLOCATION(fix = processor.locate_target(first_frame(), second_frame(), pair));
    const Eigen::Vector3f truth = camera.world().target_point_m;
    const Eigen::Vector3f seen = world_from_ptu(view.robot).apply(fix.point_ptu_m);
    const float range = (truth - first.translation_m).norm();
    std::printf("\n  %-26s %4.2f m %+4.0f°  %s  3-D error %.3f m (along the ray %+.3f m)",
                camera.world().name, static_cast<double>(range), static_cast<double>(c.angle_deg),
                fix.found ? "found" : "MISSED", static_cast<double>((seen - truth).norm()),
                static_cast<double>((seen - first.translation_m).norm() - range));
    CHECK_TEXT(fix.found, camera.world().name);
    CHECK_TEXT((seen - truth).norm() < 0.1F, camera.world().name);
  }
  std::printf("\n");
}

// The vertex's row is two fitted lines' intersection; the triangle's edges, tracked like
// features, give its range several times more precisely (the mission's setting).
TEST(TargetOnSimFrames, TheRangeFromTheTrianglesEdgesIsCloserThanTheVertexAlone) {
  stereo::StereoParams plain_params;
  stereo::StereoParams edge_params;
  edge_params.target_range_from_edges = true;
  static stereo::StereoProcessor plain{rig(), plain_params};
  static stereo::StereoProcessor edges{rig(), edge_params};
  const float phi = rig().params().tilt_step_rad;
  double plain_sum = 0.0;
  double edge_sum = 0.0;
  float edge_worst = 0.0F;
  float plain_worst = 0.0F;
  std::array<float, 18> edge_errors{};
  int cases = 0;
  int with_edges = 0;
  std::printf("\n  distance angle   vertex  edges [3-D error, m]");
  for (const float distance : {1.0F, 1.25F, 1.5F, 2.5F, 3.0F, 3.5F}) {
    for (const float angle_deg : {-40.0F, 0.0F, 30.0F}) {
      const std::size_t k = world_with_room_for(distance, angle_deg * kDegree, 0.05F, 0.5F * phi,
                                                true, static_cast<std::size_t>(cases));
      if (k >= kWorldCount) continue;
      SimCamera camera(shipped(k), 21 + static_cast<std::uint32_t>(cases));
      const View view =
          facing_target(camera.world(), distance, angle_deg * kDegree, 0.05F, 0.5F * phi);
      const stereo::PairPose pair = grab_pair(camera, view).pair;
      const stereo::TargetFix a = plain.locate_target(first_frame(), second_frame(), pair);
      stereo::TargetFix b;
      CHECK_NO_ALLOCATION(b = edges.locate_target(first_frame(), second_frame(), pair));
      CHECK_TEXT(a.found && b.found, camera.world().name);
      if (!a.found || !b.found) continue;
      // Too few edges within the vertex's window: the vertex's own fix stands.
      if (b.edges > 0) {
        CHECK(b.edges >= edge_params.target_min_edges);
        ++with_edges;
      } else {
        CHECK(b.point_ptu_m.isApprox(a.point_ptu_m));
      }
      const Eigen::Vector3f truth = camera.world().target_point_m;
      const float ea = (world_from_ptu(view.robot).apply(a.point_ptu_m) - truth).norm();
      const float eb = (world_from_ptu(view.robot).apply(b.point_ptu_m) - truth).norm();
      std::printf("\n  %5.1f m %+4.0f°  %.3f   %.3f  (%zu edges, %s)",
                  static_cast<double>(distance), static_cast<double>(angle_deg),
                  static_cast<double>(ea), static_cast<double>(eb), b.edges, camera.world().name);
      plain_sum += static_cast<double>(ea);
      edge_sum += static_cast<double>(eb);
      edge_worst = std::max(edge_worst, eb);
      plain_worst = std::max(plain_worst, ea);
      edge_errors[static_cast<std::size_t>(cases)] = eb;
      ++cases;
    }
  }
  std::printf("\n");
  CHECK(cases >= 15);
  // Measured (18 views, 1-3.5 m): errors summed 1.39 m against the vertex's 1.95 m, median
  // 0.03 m for both, worst 0.69 m for both (3.5 m, 40° aside, where no edge fell within
  // the vertex's window and the vertex stood); 0.20 m at 3 m head-on, where the edges' median
  // is pulled short. Without the window the edges put two near views 0.44 m and 1.05 m off
  // (edges that tracked the background), worse than the vertex's worst.
  std::sort(edge_errors.begin(), edge_errors.begin() + cases);
  CHECK(edge_errors[static_cast<std::size_t>(cases / 2)] < 0.05F);
  CHECK(edge_sum < plain_sum);
  CHECK(2 * with_edges >= cases);
  CHECK(edge_worst <= plain_worst);
}

TEST(TargetOnSimFrames, NothingIsFoundInAnyShippedWorldLookingAwayFromTheTarget) {
  image::TargetDetector detector;
  Timing timing;
  int frames = 0;
  int false_detections = 0;
  const float pans[] = {-2.4F, -1.6F, -0.8F, 0.0F, 0.8F, 1.6F, 2.4F};
  const float tilts[] = {-0.35F, 0.0F, 0.3F, -0.15F};
  std::uint32_t view_index = 0;
  for (std::size_t k = 0; k < kWorldCount; ++k) {
    SimCamera camera(shipped(k), 11 + k);
    const hal::sim::World& world = camera.world();
    // From the start, and from 1.2 m in front of the target looking back into the room.
    const hal::sim::TargetFace face =
        hal::sim::target_face_frame(world.surfaces[world.target_surface]);
    core::Pose2 near_target;
    near_target.x_m = face.centre_m.x() + 1.2F * face.normal.x();
    near_target.y_m = face.centre_m.y() + 1.2F * face.normal.y();
    near_target.yaw_rad = std::atan2(face.normal.y(), face.normal.x());
    for (const core::Pose2& robot : {world.start, near_target}) {
      if (!camera.sim().teleport(robot)) continue;
      int views = 0;
      for (std::size_t j = 0; j < 7 && views < 3; ++j, ++view_index) {
        const float pan = pans[(j + 2 * k) % 7];
        const float tilt = tilts[view_index % 4];
        const RigidTransform pose = camera.sim().camera_pose(robot, pan, tilt);
        // Looking away: the target more than 50° off the optical axis (the image's corners
        // are 34° off it).
        const Eigen::Vector3f to_target = (world.target_point_m - pose.translation_m).normalized();
        if (to_target.dot(pose.rotation.col(2)) > std::cos(50.0F * kDegree)) continue;
        camera.grab(pose, view_index, first_frame());
        const image::TargetDetection d = timed_detect(detector, first_frame(), timing);
        ++frames;
        ++views;
        if (d.found) {
          ++false_detections;
          std::printf("\n  false detection in %s, pan %.1f tilt %.2f at (%.1f, %.1f), conf %.2f",
                      world.name, static_cast<double>(pan), static_cast<double>(tilt),
                      static_cast<double>(d.u_px), static_cast<double>(d.v_px),
                      static_cast<double>(d.confidence));
        }
      }
    }
  }
  std::printf("\n  %d frames without the target, %d false detections; detect %.0f µs mean\n",
              frames, false_detections, timing.total_us / timing.frames);
  CHECK(frames >= 50);
  LONGS_EQUAL(0, false_detections);
}

// The sim camera darkens towards the image's corners (vignetting 0.25, as a webcam), and a
// pair's two frames see the triangle 20 px apart: measured against one mean of the paper,
// its edges moved with the image row, and the vertex's disparity came out 0.05 px too large
// (ranges 1.5% short on average, 2.1 px of disparity at 2 m). Against the paper's brightness
// fitted as a plane around the triangle, the vertex's row is unbiased across the image.
TEST(TargetOnSimFrames, TheVertexIsNotPulledByTheImagesVignetting) {
  static stereo::StereoProcessor processor{rig()};
  image::TargetDetector detector{stereo::StereoParams{}.target};
  const float phi = rig().params().tilt_step_rad;
  double row_shift_sum = 0.0;  // (second − first) frame's vertex row error [px]
  double range_sum = 0.0;      // relative range error of the pair's fix
  int views = 0;
  for (const float distance : {1.0F, 1.5F, 2.0F}) {
    for (const float angle_deg : {-30.0F, 0.0F, 30.0F}) {
      // The triangle's centre from half a step above the pair's axes to half below.
      for (int j = 0; j < 6; ++j) {
        const float extra_tilt = (-0.5F + 0.2F * static_cast<float>(j)) * phi;
        const std::size_t k = world_with_room_for(distance, angle_deg * kDegree, 0.05F, extra_tilt,
                                                  true, static_cast<std::size_t>(j));
        CHECK_TEXT(k < kWorldCount, "no world has room for a view");
        SimCamera camera(shipped(k), 40 + static_cast<std::uint32_t>(views));
        const View view =
            facing_target(camera.world(), distance, angle_deg * kDegree, 0.05F, extra_tilt);
        const GrabbedPair grabbed = grab_pair(camera, view);
        const stereo::PairPose& pair = grabbed.pair;
        const RigidTransform& first = grabbed.first;
        const RigidTransform& second = grabbed.second;
        const Eigen::Vector3f truth = camera.world().target_point_m;
        Eigen::Vector2f truth_first;
        Eigen::Vector2f truth_second;
        CHECK(project(first, truth, truth_first));
        CHECK(project(second, truth, truth_second));
        const image::TargetDetection a = detector.detect(first_frame());
        const image::TargetDetection b = detector.detect(second_frame());
        const stereo::TargetFix fix = processor.locate_target(first_frame(), second_frame(), pair);
        CHECK_TEXT(a.found && b.found && fix.found, camera.world().name);
        row_shift_sum +=
            static_cast<double>((b.v_px - truth_second.y()) - (a.v_px - truth_first.y()));
        const float range = (truth - first.translation_m).norm();
        const Eigen::Vector3f seen = world_from_ptu(view.robot).apply(fix.point_ptu_m);
        range_sum += static_cast<double>(((seen - first.translation_m).norm() - range) / range);
        ++views;
      }
    }
  }
  const double row_shift = row_shift_sum / views;
  const double range_bias = range_sum / views;
  std::printf("\n  %d pairs: vertex row shift second - first %+.3f px, range bias %+.2f%%\n", views,
              row_shift, 100.0 * range_bias);
  // Measured: -0.008 px and -0.25% (108 such pairs: -0.000 px, +0.1%); against one mean of
  // the paper -0.059 px and -1.78% (108 pairs: -0.053 px, -1.55%).
  CHECK(std::fabs(row_shift) < 0.02);
  CHECK(std::fabs(range_bias) < 0.006);
}

// Two views of a look a pan step apart (0.37 rad, as the mission's 15 pans) see the vertex
// from camera centres 7.7 cm apart across, against the tilt pair's 2.8 cm: the vertex's
// own row and column, triangulated across, locate it within a tenth of a metre to 3.5 m,
// where a tilt pair's vertex alone is off by more.
TEST(TargetOnSimFrames, TwoViewsAPanStepApartLocateTheVertexWithinATenthOfAMetreTo3_5m) {
  static stereo::StereoProcessor processor{rig()};
  image::TargetDetector detector{stereo::StereoParams{}.target};
  const float step = 0.37F;
  double across_sum = 0.0;
  float across_worst = 0.0F;
  double pair_sum = 0.0;
  int views = 0;
  std::printf("\n  distance angle   across  tilt pair [3-D error, m]");
  for (const float distance : {1.0F, 1.5F, 2.0F, 2.5F, 3.0F, 3.5F}) {
    for (const float angle_deg : {-30.0F, 0.0F, 30.0F}) {
      // The triangle a third of a step off the first view's axis, two thirds off the second's.
      const float pan = 0.33F * step;
      const std::size_t k = world_with_room_for(distance, angle_deg * kDegree, pan, 0.0F, false,
                                                static_cast<std::size_t>(views));
      if (k >= kWorldCount) continue;
      SimCamera camera(shipped(k), 60 + static_cast<std::uint32_t>(views));
      const View view = facing_target(camera.world(), distance, angle_deg * kDegree, pan, 0.0F);
      const float tilt = view.tilt_rad;
      const float phi = rig().params().tilt_step_rad;
      const RigidTransform first = camera.sim().camera_pose(view.robot, view.pan_rad, tilt);
      const RigidTransform later = camera.sim().camera_pose(view.robot, view.pan_rad - step, tilt);
      if (!triangle_in_view(camera.world(), later)) continue;
      camera.grab(first, 0, first_frame());
      const image::TargetDetection a = detector.detect(first_frame());
      camera.grab(later, 1, second_frame());
      const image::TargetDetection b = detector.detect(second_frame());
      CHECK_TEXT(a.found && b.found, camera.world().name);
      const stereo::TargetSighting earlier_sighting{a, view.pan_rad, tilt};
      const stereo::TargetSighting later_sighting{b, view.pan_rad - step, tilt};
      stereo::TargetFix across;
      CHECK_NO_ALLOCATION(across =
                              processor.locate_target_across(earlier_sighting, later_sighting));
      CHECK_TEXT(across.found, camera.world().name);
      const Eigen::Vector3f truth = camera.world().target_point_m;
      const float error = (world_from_ptu(view.robot).apply(across.point_ptu_m) - truth).norm();
      // Its expected error: Eq 3.7 with the baseline across, 2.7 times the tilt pair's.
      CHECK(across.range_error_m <
            0.6F * evidence::range_error_m((truth - first.translation_m).norm(), rig().baseline_m(),
                                           rig().low_res_camera().focal_px));
      // The tilt pair at the first view's pan, its vertex alone, for comparison.
      camera.grab(camera.sim().camera_pose(view.robot, view.pan_rad, tilt - phi), 2,
                  second_frame());
      const stereo::TargetFix pair =
          processor.locate_target(first_frame(), second_frame(), {view.pan_rad, tilt, tilt - phi});
      const float pair_error =
          pair.found ? (world_from_ptu(view.robot).apply(pair.point_ptu_m) - truth).norm() : 1.0F;
      std::printf("\n  %5.1f m %+4.0f°  %.3f   %.3f  (%s)", static_cast<double>(distance),
                  static_cast<double>(angle_deg), static_cast<double>(error),
                  static_cast<double>(pair_error), camera.world().name);
      across_sum += static_cast<double>(error);
      pair_sum += static_cast<double>(pair_error);
      across_worst = std::max(across_worst, error);
      ++views;
    }
  }
  std::printf("\n  %d views: across %.3f m mean, %.3f m worst; tilt pair %.3f m mean\n", views,
              across_sum / views, static_cast<double>(across_worst), pair_sum / views);
  // Measured (13 views, 1.5-3.5 m): across 0.018 m mean, 0.072 m worst (3.5 m, 30° aside);
  // the tilt pairs' vertices 0.100 m mean, 0.381 m worst.
  CHECK(views >= 12);
  CHECK(across_worst < 0.1F);
  CHECK(across_sum < 0.5 * pair_sum);
}

// The vertices of two views triangulate only as one point: rows that do not meet (another
// green blob, a vertex misplaced) and views without a baseline across are refused.
TEST(TargetOnSimFrames, TwoViewsWhoseVerticesDoNotMeetOrHaveNoBaselineGiveNoFix) {
  static stereo::StereoProcessor processor{rig()};
  image::TargetDetector detector{stereo::StereoParams{}.target};
  const std::size_t k = world_with_room_for(2.0F, 0.0F, 0.12F, 0.0F, false);
  CHECK(k < kWorldCount);
  SimCamera camera(shipped(k), 90);
  const View view = facing_target(camera.world(), 2.0F, 0.0F, 0.12F, 0.0F);
  camera.grab(camera.sim().camera_pose(view.robot, view.pan_rad, view.tilt_rad), 0, first_frame());
  camera.grab(camera.sim().camera_pose(view.robot, view.pan_rad - 0.37F, view.tilt_rad), 1,
              second_frame());
  const image::TargetDetection a = detector.detect(first_frame());
  image::TargetDetection b = detector.detect(second_frame());
  CHECK(a.found && b.found);
  const stereo::TargetSighting earlier{a, view.pan_rad, view.tilt_rad};
  CHECK(processor.locate_target_across(earlier, {b, view.pan_rad - 0.37F, view.tilt_rad}).found);
  // The same frame twice: no baseline.
  CHECK_FALSE(processor.locate_target_across(earlier, earlier).found);
  // Pans closer than the tilt step: a baseline shorter than the tilt pair's.
  CHECK_FALSE(
      processor.locate_target_across(earlier, {a, view.pan_rad - 0.1F, view.tilt_rad}).found);
  // The second vertex three rows lower: the rays pass 3 px apart.
  b.v_px += 3.0F;
  CHECK_FALSE(
      processor.locate_target_across(earlier, {b, view.pan_rad - 0.37F, view.tilt_rad}).found);
  b.v_px -= 2.0F;  // one row: within the gap allowed
  CHECK(processor.locate_target_across(earlier, {b, view.pan_rad - 0.37F, view.tilt_rad}).found);
  // Either detection missing.
  b.found = false;
  CHECK_FALSE(
      processor.locate_target_across(earlier, {b, view.pan_rad - 0.37F, view.tilt_rad}).found);
}
