// Tests of the rig model: poses, baseline, projection, and the epipolar line of Appendix A.
#include <cmath>
#include <cstdio>

#include <Eigen/Geometry>

#include "algo/core/angles.h"
#include "algo/stereo/rig.h"
#include "algo/stereo/triangulation.h"
#include "CppUTest/TestHarness.h"

using boticelli::core::deg_to_rad;
using namespace boticelli::stereo;

TEST_GROUP(Rig){};

TEST(Rig, AtRestTheCameraLooksForwardFromTheEndOfTheLever) {
  const RigModel rig;
  const CameraPose pose = rig.camera_pose(0.0F, 0.0F);
  DOUBLES_EQUAL(0.21, pose.centre_m.x(), 1e-6);
  DOUBLES_EQUAL(0.0, pose.centre_m.y(), 1e-6);
  DOUBLES_EQUAL(0.0, pose.centre_m.z(), 1e-6);
  // Optical axis +x, image right −y (robot's right), image down −z.
  CHECK((pose.rotation.col(2) - Eigen::Vector3f::UnitX()).norm() < 1e-6F);
  CHECK((pose.rotation.col(0) + Eigen::Vector3f::UnitY()).norm() < 1e-6F);
  CHECK((pose.rotation.col(1) + Eigen::Vector3f::UnitZ()).norm() < 1e-6F);
}

TEST(Rig, PanTurnsLeftAndPositiveTiltLooksUp) {
  const RigModel rig;
  const CameraPose left = rig.camera_pose(deg_to_rad(90.0F), 0.0F);
  CHECK((left.rotation.col(2) - Eigen::Vector3f::UnitY()).norm() < 1e-6F);
  DOUBLES_EQUAL(0.21, left.centre_m.y(), 1e-6);
  const CameraPose up = rig.camera_pose(0.0F, deg_to_rad(30.0F));
  CHECK(up.rotation.col(2).z() > 0.49F);
  CHECK(up.centre_m.z() > 0.1F);
}

TEST(Rig, TiltingDownByPhiMovesTheCameraDownByTheBaseline) {
  const RigModel rig;
  const CameraPose first = rig.camera_pose(0.4F, 0.05F);
  const CameraPose second = rig.second_pose(0.4F, 0.05F);
  const float moved = (second.centre_m - first.centre_m).norm();
  // 2·L·sin(Φ/2) = 2·0.21·sin(3.85°) = 0.0282 m (§3.4.1: "baseline h ≈ 3 cm").
  DOUBLES_EQUAL(0.0282, moved, 2e-4);
  DOUBLES_EQUAL(moved, rig.baseline_m(), 1e-6);
  CHECK(second.centre_m.z() < first.centre_m.z());
}

TEST(Rig, SupportAngleRaisesTheCameraWithoutChangingTheBaseline) {
  RigParams params;
  params.support_angle_rad = deg_to_rad(20.0F);
  const RigModel rig(params);
  const CameraPose pose = rig.camera_pose(0.0F, 0.0F);
  DOUBLES_EQUAL(0.21 * std::sin(deg_to_rad(20.0)), pose.centre_m.z(), 1e-6);
  const float moved = (rig.second_pose(0.0F, 0.0F).centre_m - pose.centre_m).norm();
  DOUBLES_EQUAL(rig.baseline_m(), moved, 1e-6);
}

TEST(Rig, LowResolutionCameraHasTheThesisFocalLength) {
  const RigModel rig;
  DOUBLES_EQUAL(150.0, rig.low_res_camera().focal_px, 1e-6);
  LONGS_EQUAL(160, rig.low_res_camera().width_px);
  LONGS_EQUAL(120, rig.low_res_camera().height_px);
  // Full-res pixel centre 319.5 is the boundary between low-res pixels 79 and 80.
  DOUBLES_EQUAL(79.5, rig.low_res_camera().principal_x_px, 1e-6);
}

TEST(Rig, ProjectionAndBackProjectionInvertEachOtherWithDistortion) {
  CameraIntrinsics camera;
  camera.k1 = -0.12F;
  const Eigen::Vector2f pixels[] = {
      {10.0F, 20.0F}, {319.5F, 239.5F}, {600.0F, 400.0F}, {100.0F, 470.0F}};
  for (const Eigen::Vector2f& pixel : pixels) {
    const Eigen::Vector3f ray = camera.back_project(pixel);
    DOUBLES_EQUAL(1.0, ray.norm(), 1e-5);
    Eigen::Vector2f again;
    CHECK(camera.project(2.5F * ray, again));
    DOUBLES_EQUAL(pixel.x(), again.x(), 0.01);
    DOUBLES_EQUAL(pixel.y(), again.y(), 0.01);
  }
  Eigen::Vector2f untouched(-1.0F, -1.0F);
  CHECK_FALSE(camera.project(Eigen::Vector3f(0.0F, 0.0F, -1.0F), untouched));
}

TEST(Rig, EpipolarSlopeMatchesAppendixAOverTheBand) {
  // App. A: L = 21 cm, Φ = 7.7°, F = 150: K varies from −0.0242 to 0.0242 for
  // i ∈ [−53, 53], j ∈ [−40, 40].
  const RigModel rig;
  const CameraPose first = rig.camera_pose(0.0F, 0.0F);
  const CameraPose second = rig.second_pose(0.0F, 0.0F);
  float k_min = 1.0F;
  float k_max = -1.0F;
  for (int i = -53; i <= 53; ++i) {
    for (int j = -40; j <= 40; ++j) {
      float k = 0.0F;
      float b = 0.0F;
      CHECK(epipolar_line(first, second, rig.low_res_camera(), static_cast<float>(i),
                          static_cast<float>(j), k, b));
      k_min = std::fmin(k_min, k);
      k_max = std::fmax(k_max, k);
      if (i == 0) {
        DOUBLES_EQUAL(0.0, k, 1e-6);  // the centre column moves straight down
      }
    }
  }
  std::printf(
      "\n  App. A epipolar slope over the band: K in [%.4f, %.4f] (thesis: [-0.0242, 0.0242])\n",
      static_cast<double>(k_min), static_cast<double>(k_max));
  DOUBLES_EQUAL(-0.0242, k_min, 0.0242 * 0.03);
  DOUBLES_EQUAL(0.0242, k_max, 0.0242 * 0.03);
}

TEST(Rig, EpipolarLinePassesThroughTheImagesOfTheFeaturesPoints) {
  const RigModel rig;
  const CameraIntrinsics& cam = rig.low_res_camera();
  const CameraPose first = rig.camera_pose(1.0F, 0.2F);
  const CameraPose second = rig.second_pose(1.0F, 0.2F);
  const float i = 40.0F;
  const float j = -30.0F;
  float k = 0.0F;
  float b = 0.0F;
  CHECK(epipolar_line(first, second, cam, i, j, k, b));
  const Eigen::Vector3f ray = RigModel::ray_ptu(
      first, cam, Eigen::Vector2f(i + cam.principal_x_px, j + cam.principal_y_px));
  for (const float depth : {0.3F, 1.0F, 4.0F}) {
    Eigen::Vector2f px;
    CHECK(RigModel::project_ptu(second, cam, first.centre_m + depth * ray, px));
    const float i2 = px.x() - cam.principal_x_px;
    const float j2 = px.y() - cam.principal_y_px;
    DOUBLES_EQUAL(k * j2 + b, i2, 1e-3);
  }
}
