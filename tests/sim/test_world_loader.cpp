// Tests of the world loader: shipped worlds, the SDF subset's semantics, rejected files.
#include <cmath>
#include <cstring>
#include <string>

#include "algo/stereo/rig.h"
#include "hal/sim/renderer.h"
#include "hal/sim/sim_world.h"
#include "hal/sim/textures.h"
#include "hal/sim/world.h"
#include "sim_test_worlds.h"

#include "CppUTest/TestHarness.h"

using namespace boticelli::hal::sim;
using boticelli::hal::sim::test::box_model;
using boticelli::hal::sim::test::small_world;
using boticelli::hal::sim::test::world_path;

namespace {
World g_world;
TextureBank g_bank;
SimWorld g_sim;
char g_error[256];

bool parse(const std::string& xml) {
  return parse_world(xml.c_str(), xml.size(), "test.sdf", g_world, g_error, sizeof g_error);
}
}  // namespace

TEST_GROUP(WorldLoader){void setup() override{g_error[0] = '\0';
}
}
;

TEST(WorldLoader, EveryShippedWorldLoadsWithAFreeStartAndOneTarget) {
  const boticelli::stereo::RigModel rig;
  for (const char* name : boticelli::hal::sim::test::kShippedWorlds) {
    const std::string path = world_path(name);
    CHECK_TEXT(load_world(path.c_str(), g_world, g_error, sizeof g_error), g_error);
    CHECK_TEXT(g_bank.build(g_world, g_error, sizeof g_error), g_error);
    CHECK_TEXT(g_sim.init(g_world, rig, SimParams{}, g_error, sizeof g_error), g_error);
    CHECK_TEXT(g_world.surface_count >= 5, name);
    CHECK_TEXT(g_world.collider_count >= 4, name);
    CHECK_TEXT(g_world.surfaces[g_world.target_surface].target_face != kNoFace, name);
    // The target is on a wall at a height the camera can see (between 0.3 and 2 m).
    CHECK_TEXT(g_world.target_point_m.z() > 0.3F && g_world.target_point_m.z() < 2.0F, name);
    CHECK_TEXT(g_sim.clearance_m(g_world.start.x_m, g_world.start.y_m) > 0.1F, name);
  }
}

TEST(WorldLoader, ThesisRoomHidesTheTargetFromTheStartBehindThePartition) {
  const std::string path = world_path("thesis_room");
  CHECK_TEXT(load_world(path.c_str(), g_world, g_error, sizeof g_error), g_error);
  const Eigen::Vector3f eye(g_world.start.x_m, g_world.start.y_m, 0.8F);
  const Eigen::Vector3f to_target = g_world.target_point_m - eye;
  std::size_t surface = 0;
  float t = 0.0F;
  CHECK(cast_ray(g_world, eye, to_target, surface, t));
  CHECK(t < 0.9F);  // something is in the way
  STRCMP_EQUAL("partition", g_world.surfaces[surface].model);
  // The room is about 5 x 6 m with 2 m walls.
  float min_x = 1e9F, max_x = -1e9F, min_y = 1e9F, max_y = -1e9F, max_z = 0.0F;
  for (std::size_t i = 0; i < g_world.collider_count; ++i) {
    const Collider& c = g_world.colliders[i];
    for (std::size_t k = 0; k < c.hull_size; ++k) {
      min_x = std::fmin(min_x, c.hull[k].x_m);
      max_x = std::fmax(max_x, c.hull[k].x_m);
      min_y = std::fmin(min_y, c.hull[k].y_m);
      max_y = std::fmax(max_y, c.hull[k].y_m);
    }
    max_z = std::fmax(max_z, c.z_max_m);
  }
  DOUBLES_EQUAL(5.1, max_x - min_x, 0.2);
  DOUBLES_EQUAL(6.1, max_y - min_y, 0.2);
  DOUBLES_EQUAL(2.0, max_z, 1e-4);
}

TEST(WorldLoader, TheExplorationRoomsHideTheTargetFromTheStartButNotFromEverywhere) {
  struct Case {
    const char* world;
    float seen_from_x_m, seen_from_y_m;  // a free place with the target in plain view
  };
  const Case cases[] = {{"thesis_room", -1.0F, 1.8F},
                        {"l_shaped_room", 1.5F, -1.5F},
                        {"two_rooms_doorway", 2.0F, 0.5F}};
  const boticelli::stereo::RigModel rig;
  for (const Case& c : cases) {
    const std::string path = world_path(c.world);
    CHECK_TEXT(load_world(path.c_str(), g_world, g_error, sizeof g_error), g_error);
    CHECK_TEXT(g_sim.init(g_world, rig, SimParams{}, g_error, sizeof g_error), g_error);
    auto first_hit = [&](float x_m, float y_m) {
      const Eigen::Vector3f eye(x_m, y_m, 0.6F);
      std::size_t surface = 0;
      float t = 0.0F;
      CHECK(cast_ray(g_world, eye, g_world.target_point_m - eye, surface, t));
      return t < 0.999F ? std::string(g_world.surfaces[surface].model) : std::string("target");
    };
    CHECK_TEXT(first_hit(g_world.start.x_m, g_world.start.y_m) != "target", c.world);
    CHECK_TEXT(g_sim.clearance_m(c.seen_from_x_m, c.seen_from_y_m) > 0.0F, c.world);
    STRCMP_EQUAL_TEXT("target", first_hit(c.seen_from_x_m, c.seen_from_y_m).c_str(), c.world);
  }
}

TEST(WorldLoader, PosesComposeModelThenLinkThenVisual) {
  const std::string models =
      "<model name=\"m\"><pose>1 0 0 0 0 1.5707963</pose>"
      "<link name=\"l\"><pose>2 0 0 0 0 0</pose>"
      "<visual name=\"v\"><pose>0 0 0.5 0 0 0</pose>"
      "<geometry><box><size>1 2 1</size></box></geometry></visual></link></model>";
  CHECK_TEXT(parse(small_world(models)), g_error);
  const Surface& s = g_world.surfaces[1];
  // Link x = 2 turned by the model's 90° yaw → world (1, 2, 0.5).
  DOUBLES_EQUAL(1.0, s.world_from_local.translation_m.x(), 1e-5);
  DOUBLES_EQUAL(2.0, s.world_from_local.translation_m.y(), 1e-5);
  DOUBLES_EQUAL(0.5, s.world_from_local.translation_m.z(), 1e-5);
  // The box's local x points along world y.
  DOUBLES_EQUAL(1.0, s.world_from_local.rotation(1, 0), 1e-5);
  DOUBLES_EQUAL(0.5, s.half_size_m.x(), 1e-6);
  // Its collider (from the visual, no collision element) is the 2 x 1 m footprint.
  const Collider& c = g_world.colliders[1];
  CHECK_FALSE(c.circle);
  UNSIGNED_LONGS_EQUAL(4, c.hull_size);
  DOUBLES_EQUAL(0.0, c.z_min_m, 1e-5);
  DOUBLES_EQUAL(1.0, c.z_max_m, 1e-5);
}

TEST(WorldLoader, RollPitchYawRotateAboutFixedAxesRollFirst) {
  const float pose[6] = {0, 0, 0, 1.5707963F, 0, 1.5707963F};
  const RigidTransform t = transform_from_pose(pose);
  // Roll 90° takes local y to z; then yaw 90° leaves z; local x goes to world y.
  const Eigen::Vector3f y = t.apply(Eigen::Vector3f::UnitY());
  DOUBLES_EQUAL(1.0, y.z(), 1e-5);
  const Eigen::Vector3f x = t.apply(Eigen::Vector3f::UnitX());
  DOUBLES_EQUAL(1.0, x.y(), 1e-5);
}

TEST(WorldLoader, CollisionElementsReplaceVisualsAndPlanesNeverCollide) {
  const std::string models =
      "<model name=\"c\"><link name=\"l\">"
      "<collision name=\"c\"><geometry><cylinder><radius>0.3</radius><length>1</length>"
      "</cylinder></geometry></collision>"
      "<visual name=\"v\"><geometry><box><size>3 3 3</size></box></geometry></visual>"
      "</link></model>"
      "<model name=\"floor\"><link name=\"l\"><visual name=\"v\"><geometry><plane>"
      "<normal>0 0 1</normal><size>10 10</size></plane></geometry></visual></link></model>";
  CHECK_TEXT(parse(small_world(models, "2 2 0 0 0 0")), g_error);
  UNSIGNED_LONGS_EQUAL(3, g_world.surface_count);   // target, box, floor
  UNSIGNED_LONGS_EQUAL(2, g_world.collider_count);  // target box and the cylinder only
  CHECK(g_world.colliders[1].circle);
  DOUBLES_EQUAL(0.3, g_world.colliders[1].radius_m, 1e-6);
}

TEST(WorldLoader, UnknownElementsAreIgnoredAndDefaultsApply) {
  const std::string models =
      "<physics type=\"ode\"><max_step_size>0.001</max_step_size></physics>"
      "<gui><camera name=\"c\"/></gui>"
      "<include><uri>model://sun</uri></include>"
      "<model name=\"m\"><plugin name=\"p\" filename=\"x.so\"/><link name=\"l\">"
      "<inertial><mass>1</mass></inertial>"
      "<visual name=\"v\"><geometry><box><size>1 1 1</size></box></geometry>"
      "<cast_shadows>false</cast_shadows></visual></link></model>";
  CHECK_TEXT(parse(small_world(models)), g_error);
  const Surface& s = g_world.surfaces[1];
  DOUBLES_EQUAL(0.7, s.diffuse.r, 1e-6);
  CHECK(s.pattern == Pattern::kPlain);
  DOUBLES_EQUAL(0.5, g_world.ambient.g, 1e-6);
  DOUBLES_EQUAL(-1.0, g_world.light_direction.z(), 1e-6);
}

TEST(WorldLoader, TheTargetPointIsTheUpperVertexOfTheTriangle) {
  CHECK_TEXT(parse(small_world("")), g_error);
  // Paper box at (-4, 0, 1), face +x at x = -3.995, triangle side 0.2: vertex 0.2/√3 above.
  DOUBLES_EQUAL(-3.995, g_world.target_point_m.x(), 1e-5);
  DOUBLES_EQUAL(0.0, g_world.target_point_m.y(), 1e-5);
  DOUBLES_EQUAL(1.0 + 0.2 / std::sqrt(3.0), g_world.target_point_m.z(), 1e-5);
  DOUBLES_EQUAL(1.0, g_world.target_normal.x(), 1e-6);
}

namespace {
struct BadWorld {
  const char* what;
  std::string xml;
  const char* message;  // expected in the error
  int line;             // expected line (0: any)
};

std::string replace(std::string s, const std::string& from, const std::string& to) {
  const std::size_t at = s.find(from);
  if (at != std::string::npos) s.replace(at, from.size(), to);
  return s;
}
}  // namespace

TEST(WorldLoader, MalformedFilesAreRejectedWithFileLineAndProblem) {
  const std::string good = small_world(box_model("b", "1 1 0.5 0 0 0", "1 1 1"));
  CHECK_TEXT(parse(good), g_error);
  const BadWorld cases[] = {
      {"unclosed tag", replace(good, "</world>", ""), "malformed XML", 0},
      {"not sdf", "<world/>", "root element is not <sdf>", 1},
      {"no world", "<sdf>\n</sdf>", "has no <world>", 1},
      {"no robot", replace(good, "<include><uri>model://boticelli</uri>", "<include><uri>x</uri>"),
       "no robot", 2},
      {"no target", replace(good, "<boticelli:target face=\"+x\" size=\"0.2\"/>", ""),
       "no <boticelli:target>", 2},
      {"two targets",
       small_world("<model name=\"t2\"><link name=\"l\"><visual name=\"v\"><geometry><box><size>"
                   "1 1 1</size></box></geometry><boticelli:target face=\"-y\" size=\"0.2\"/>"
                   "</visual></link></model>"),
       "a second <boticelli:target>", 5},
      {"mesh", replace(good, "<box><size>1 1 1</size></box>", "<mesh><uri>a.dae</uri></mesh>"),
       "unsupported geometry <mesh>", 5},
      {"sphere",
       replace(good, "<box><size>1 1 1</size></box>", "<sphere><radius>1</radius></sphere>"),
       "unsupported geometry <sphere>", 5},
      {"negative size", replace(good, "1 1 1</size>", "1 -1 1</size>"), "must be > 0", 5},
      {"zero size", replace(good, "1 1 1</size>", "1 0 1</size>"), "must be > 0", 5},
      {"size beyond 1 km", replace(good, "1 1 1</size>", "1 1 1001</size>"), "<= 1000 m", 5},
      {"not a number", replace(good, "1 1 0.5 0 0 0", "1 one 0.5 0 0 0"), "is not a number", 5},
      {"five pose numbers", replace(good, "1 1 0.5 0 0 0", "1 1 0.5 0 0"), "has 5 numbers", 5},
      {"seven pose numbers", replace(good, "1 1 0.5 0 0 0", "1 1 0.5 0 0 0 0"),
       "more than 6 numbers", 5},
      {"infinite", replace(good, "1 1 0.5 0 0 0", "1 inf 0.5 0 0 0"), "is not a number", 5},
      {"box without size", replace(good, "<box><size>1 1 1</size></box>", "<box/>"),
       "<box> has no <size>", 5},
      {"no geometry", replace(good, "<geometry><box><size>1 1 1</size></box></geometry>", ""),
       "has no <geometry>", 5},
      {"cylinder without radius",
       small_world("<model name=\"c\"><link name=\"l\"><visual name=\"v\"><geometry><cylinder>"
                   "<length>1</length></cylinder></geometry></visual></link></model>"),
       "<cylinder> has no <radius>", 5},
      {"unknown pattern", replace(good, "<boticelli:pattern>paper", "<boticelli:pattern>tartan"),
       "unknown pattern", 4},
      {"bad target face", replace(good, "face=\"+x\"", "face=\"up\""), "is not one of", 4},
      {"target too big", replace(good, "size=\"0.2\"", "size=\"0.5\""), "fit the", 4},
      {"target on a cylinder",
       small_world("<model name=\"c\"><link name=\"l\"><visual name=\"v\"><geometry><cylinder>"
                   "<radius>1</radius><length>1</length></cylinder></geometry>"
                   "<boticelli:target face=\"+x\" size=\"0.2\"/></visual></link></model>"),
       "must be on a box", 5},
      {"colour out of range",
       replace(good, "<geometry><box><size>1 1 1",
               "<material><diffuse>1.5 0 0 1</diffuse></material><geometry><box><size>1 1 1"),
       "outside [0, 1]", 5},
      {"two robots",
       replace(good, "</world>",
               "<include><uri>model://boticelli</uri><pose>1 1 0 0 0 0</pose></include></world>"),
       "a second robot", 6},
      {"far away", replace(good, "1 1 0.5 0 0 0", "1 1e5 0.5 0 0 0"), "beyond", 5},
  };
  for (const BadWorld& c : cases) {
    g_error[0] = '\0';
    CHECK_FALSE_TEXT(parse(c.xml), c.what);
    CHECK_TEXT(std::strstr(g_error, c.message) != nullptr,
               (std::string(c.what) + ": " + g_error).c_str());
    CHECK_TEXT(std::strncmp(g_error, "test.sdf:", 9) == 0, g_error);
    if (c.line != 0) {
      const std::string expected = "test.sdf:" + std::to_string(c.line) + ":";
      CHECK_TEXT(std::strncmp(g_error, expected.c_str(), expected.size()) == 0,
                 (std::string(c.what) + ": " + g_error).c_str());
    }
  }
}

TEST(WorldLoader, AMissingFileIsAnErrorNamingIt) {
  CHECK_FALSE(load_world("/nonexistent/room.sdf", g_world, g_error, sizeof g_error));
  CHECK(std::strstr(g_error, "/nonexistent/room.sdf") != nullptr);
  CHECK(std::strstr(g_error, "cannot open") != nullptr);
}

TEST(WorldLoader, ADirectoryIsAnErrorNamingItAndTheReason) {
  CHECK_FALSE(load_world("/tmp", g_world, g_error, sizeof g_error));
  STRCMP_EQUAL("/tmp: cannot read the world file: Is a directory", g_error);
}

TEST(WorldLoader, TooManyVisualsAreRejectedNotTruncated) {
  std::string models;
  for (std::size_t i = 0; i < kMaxSurfaces; ++i) {
    models += box_model("b", "3 3 0.5 0 0 0", "0.1 0.1 0.1");
  }
  CHECK_FALSE(parse(small_world(models)));
  CHECK(std::strstr(g_error, "more than") != nullptr);
}

TEST(WorldLoader, AStartInsideAnObstacleIsRejectedByTheSimulation) {
  CHECK_TEXT(parse(small_world(box_model("crate", "0.3 0 0.5 0 0 0", "0.5 0.5 1"))), g_error);
  const boticelli::stereo::RigModel rig;
  CHECK_FALSE(g_sim.init(g_world, rig, SimParams{}, g_error, sizeof g_error));
  CHECK(std::strstr(g_error, "crate") != nullptr);
}

namespace {
// A 0.2 m cube at (3 + 0.3 i, 3) with the given pattern and seed.
std::string patterned_box(int i, const char* pattern, int seed) {
  return "<model name=\"p" + std::to_string(i) + "\"><pose>" + std::to_string(3.0 + 0.3 * i) +
         " 3 0.5 0 0 0</pose><link name=\"l\"><visual name=\"v\"><geometry><box><size>0.2 0.2 "
         "0.2</size></box></geometry><boticelli:pattern seed=\"" +
         std::to_string(seed) + "\">" + pattern + "</boticelli:pattern></visual></link></model>\n";
}
}  // namespace

TEST(WorldLoader, AWorldWithSixtyFourDistinctPatternSeedsGetsSixtyFourTextures) {
  // 56 camouflage seeds and the 8 leaves seeds a bank holds: 64 distinct pairs.
  std::string models;
  for (int i = 0; i < 56; ++i) models += patterned_box(i, "camouflage", 100 + i);
  for (int i = 0; i < 8; ++i) models += patterned_box(56 + i, "leaves", 100 + i);
  CHECK_TEXT(parse(small_world(models)), g_error);
  CHECK_TEXT(g_bank.build(g_world, g_error, sizeof g_error), g_error);
  CHECK_EQUAL(kMaxTextures, g_bank.size());
  bool used[kMaxTextures] = {};
  for (std::size_t i = 0; i < g_world.surface_count; ++i) {
    const int t = g_world.surfaces[i].texture;
    if (g_world.surfaces[i].pattern == Pattern::kPaper) continue;
    CHECK(t >= 0 && t < static_cast<int>(kMaxTextures));
    CHECK_FALSE(used[t]);
    used[t] = true;
  }
  // Distinct seeds give distinct cloth: the first and last camouflage differ somewhere.
  const int first = g_world.surfaces[1].texture;
  const int last = g_world.surfaces[56].texture;
  int differing = 0;
  for (std::uint32_t x = 0; x < kTextureSize; ++x) {
    differing += g_bank.texel(first, x, 7) != g_bank.texel(last, x, 7) ? 1 : 0;
  }
  CHECK(differing > 100);
  // The bank stays a few MB: 2 bits a camouflage texel, a byte a leaves texel.
  CHECK(sizeof(TextureBank) < (7U << 20U));
}

TEST(WorldLoader, MoreDistinctPatternSeedsThanTheBankHoldsAreRejected) {
  std::string models;
  for (int i = 0; i <= static_cast<int>(kMaxTextures); ++i) {
    models += patterned_box(i, "camouflage", 100 + i);
  }
  CHECK_TEXT(parse(small_world(models)), g_error);
  CHECK_FALSE(g_bank.build(g_world, g_error, sizeof g_error));
  CHECK(std::strstr(g_error, "more than 64 distinct pattern seeds") != nullptr);
  std::string trees;
  for (int i = 0; i <= static_cast<int>(kMaxLeavesTextures); ++i) {
    trees += patterned_box(i, "leaves", 100 + i);
  }
  CHECK_TEXT(parse(small_world(trees)), g_error);
  CHECK_FALSE(g_bank.build(g_world, g_error, sizeof g_error));
  CHECK(std::strstr(g_error, "distinct leaves seeds") != nullptr);
}
