// Tests that every shipped world and the robot model load with SDFormat without errors, and that
// the model has the sim board's dimensions.
#include <stdlib.h>

#include <algorithm>
#include <filesystem>
#include <string>
#include <vector>

#include <sdf/sdf.hh>

#include "board_config.h"

#include "CppUTest/TestHarness.h"

namespace {

std::vector<std::string> shipped_worlds() {
  std::vector<std::string> out;
  std::string dirs = BOTICELLI_WORLD_DIRS;
  std::size_t start = 0;
  while (start <= dirs.size()) {
    const std::size_t end = std::min(dirs.find(':', start), dirs.size());
    const std::filesystem::path dir = dirs.substr(start, end - start);
    if (std::filesystem::is_directory(dir)) {
      for (const auto& entry : std::filesystem::directory_iterator(dir)) {
        if (entry.path().extension() == ".sdf") out.push_back(entry.path().string());
      }
    }
    start = end + 1;
  }
  std::sort(out.begin(), out.end());
  return out;
}

std::string describe(const sdf::Errors& errors) {
  std::string text;
  for (const auto& e : errors) text += e.Message() + "; ";
  return text;
}

}  // namespace

TEST_GROUP(ShippedSdf){void setup() override{
    // SDFormat keeps parsed descriptions in process-wide caches: not leaks of a test.
    MemoryLeakWarningPlugin::saveAndDisableNewDeleteOverloads();
setenv("SDF_PATH", BOTICELLI_MODELS_DIR, 1);
}
void teardown() override {
  unsetenv("SDF_PATH");
  MemoryLeakWarningPlugin::restoreNewDeleteOverloads();
}
}
;

TEST(ShippedSdf, EveryWorldLoadsWithoutErrorsWithTheProjectsModelsOnSdfPath) {
  const std::vector<std::string> worlds = shipped_worlds();
  CHECK(worlds.size() >= 10U);
  for (const std::string& path : worlds) {
    sdf::Root root;
    const sdf::Errors errors = root.Load(path);
    CHECK_EQUAL_TEXT(0U, errors.size(), (path + ": " + describe(errors)).c_str());
    CHECK_EQUAL_TEXT(1U, root.WorldCount(), path.c_str());
    const sdf::World* world = root.WorldByIndex(0);
    CHECK_TEXT(world->ModelNameExists("boticelli"), path.c_str());
  }
}

TEST(ShippedSdf, TheRobotModelHasTheSimBoardsDimensions) {
  const auto config = boticelli::boards::sim::make_config();
  sdf::Root root;
  const sdf::Errors errors = root.Load(std::string(BOTICELLI_MODELS_DIR) + "/boticelli/model.sdf");
  CHECK_EQUAL_TEXT(0U, errors.size(), describe(errors).c_str());
  const sdf::Model* model = root.Model();
  CHECK(model != nullptr);
  STRCMP_EQUAL("boticelli", model->Name().c_str());

  const sdf::Link* chassis = model->LinkByName("chassis");
  CHECK(chassis != nullptr);
  const sdf::Cylinder* body = chassis->CollisionByName("body")->Geom()->CylinderShape();
  CHECK(body != nullptr);
  DOUBLES_EQUAL(config.robot_radius_m, body->Radius(), 1e-6);
  const auto body_pose = chassis->CollisionByName("body")->RawPose();
  DOUBLES_EQUAL(config.ptu_height_m, body_pose.Pos().Z() + body->Length() / 2.0, 1e-6);

  const sdf::Link* left = model->LinkByName("left_wheel");
  const sdf::Link* right = model->LinkByName("right_wheel");
  CHECK(left != nullptr && right != nullptr);
  DOUBLES_EQUAL(config.track_width_m, left->RawPose().Pos().Y() - right->RawPose().Pos().Y(), 1e-6);
  const sdf::Cylinder* tyre = left->CollisionByName("tyre")->Geom()->CylinderShape();
  DOUBLES_EQUAL(config.wheel_radius_m, tyre->Radius(), 1e-6);
  DOUBLES_EQUAL(config.wheel_radius_m, left->RawPose().Pos().Z(), 1e-6);

  const sdf::Link* tilt = model->LinkByName("tilt");
  CHECK(tilt != nullptr);
  DOUBLES_EQUAL(config.ptu_height_m, tilt->RawPose().Pos().Z(), 1e-6);
  const sdf::Sensor* sensor = tilt->SensorByName("camera");
  CHECK(sensor != nullptr);
  DOUBLES_EQUAL(config.lever_m, sensor->RawPose().Pos().X(), 1e-6);
  const sdf::Camera* camera = sensor->CameraSensor();
  CHECK(camera != nullptr);
  CHECK_EQUAL(config.camera_width_px, camera->ImageWidth());
  CHECK_EQUAL(config.camera_height_px, camera->ImageHeight());
  // F = (width / 2) / tan(fov / 2)
  DOUBLES_EQUAL(config.focal_px,
                camera->ImageWidth() / 2.0 / std::tan(camera->HorizontalFov().Radian() / 2.0),
                0.05);
}
