// Tests of triangulation (Eqs 3.2, 3.4), readings about the PTU centre, and Eq 3.7/3.8 bookkeeping.
#include <cmath>

#include <Eigen/Core>

#include "algo/core/angles.h"
#include "algo/evidence/sensor_model.h"
#include "algo/stereo/rig.h"
#include "algo/stereo/triangulation.h"
#include "CppUTest/TestHarness.h"

using namespace boticelli::stereo;

TEST_GROUP(Triangulation){};

TEST(Triangulation, ExactFormRecoversAPointFromItsTwoImages) {
  const RigModel rig;
  const CameraIntrinsics& cam = rig.low_res_camera();
  const CameraPose first = rig.camera_pose(-0.7F, 0.1F);
  const CameraPose second = rig.second_pose(-0.7F, 0.1F);
  const Eigen::Vector3f truth = first.to_ptu(Eigen::Vector3f(0.3F, -0.2F, 2.0F));
  Eigen::Vector2f p1;
  Eigen::Vector2f p2;
  CHECK(RigModel::project_ptu(first, cam, truth, p1));
  CHECK(RigModel::project_ptu(second, cam, truth, p2));
  Eigen::Vector3f point;
  CHECK(triangulate_exact(first.centre_m, RigModel::ray_ptu(first, cam, p1), second.centre_m,
                          RigModel::ray_ptu(second, cam, p2), point));
  CHECK((point - truth).norm() < 1e-3F);
}

TEST(Triangulation, FastFormAgreesWithTheExactOneNearTheImageCentre) {
  const RigModel rig;
  const CameraIntrinsics& cam = rig.low_res_camera();
  const CameraPose first = rig.camera_pose(0.3F, -0.05F);
  const CameraPose second = rig.second_pose(0.3F, -0.05F);
  for (const float depth : {0.3F, 1.0F, 2.5F, 4.5F}) {
    for (const float x : {-0.3F, 0.0F, 0.25F}) {
      const Eigen::Vector3f truth_cam(x * depth, -0.2F * depth, depth);
      const Eigen::Vector3f truth = first.to_ptu(truth_cam);
      Eigen::Vector2f p1;
      Eigen::Vector2f p2;
      CHECK(RigModel::project_ptu(first, cam, truth, p1));
      CHECK(RigModel::project_ptu(second, cam, truth, p2));
      Eigen::Vector3f fast_cam;
      CHECK(triangulate_fast(first, second, cam.normalized_from_pixel(p1),
                             cam.normalized_from_pixel(p2), fast_cam));
      // Eq 3.4 ignores the horizontal part of the motion; with the tilt axis parallel to
      // the image rows that part is zero, so the two forms agree.
      DOUBLES_EQUAL(truth_cam.z(), fast_cam.z(), 1e-3F * depth);
      DOUBLES_EQUAL(truth_cam.x(), fast_cam.x(), 1e-3F * depth);
    }
  }
}

TEST(Triangulation, RaysThatMeetBehindTheCameraAreRejected) {
  Eigen::Vector3f point;
  CHECK_FALSE(triangulate_exact(Eigen::Vector3f::Zero(), Eigen::Vector3f::UnitX(),
                                Eigen::Vector3f(0, 0, -0.03F),
                                Eigen::Vector3f(1.0F, 0.0F, -0.1F).normalized(), point));
  CHECK_FALSE(triangulate_exact(Eigen::Vector3f::Zero(), Eigen::Vector3f::UnitX(),
                                Eigen::Vector3f(0, 0, -0.03F), Eigen::Vector3f::UnitX(), point));
  // In front of the first camera (1 m along its ray) but behind the second.
  CHECK_FALSE(triangulate_exact(Eigen::Vector3f::Zero(), Eigen::Vector3f::UnitX(),
                                Eigen::Vector3f(2.0F, 1.0F, 0.0F),
                                Eigen::Vector3f(1.0F, 1.0F, 0.0F).normalized(), point));
}

TEST(Triangulation, ReadingIsTakenAboutThePtuCentre) {
  const auto reading = reading_from_point(Eigen::Vector3f(-1.0F, -1.0F, 0.5F), 0.8F);
  DOUBLES_EQUAL(1.25 * boticelli::core::kPi<double>, reading.alpha_rad, 1e-5);
  DOUBLES_EQUAL(0.5, reading.h_m, 1e-6);
  DOUBLES_EQUAL(1.5, reading.r_m, 1e-6);
  DOUBLES_EQUAL(0.8, reading.m, 1e-6);
  // Seen from the PTU centre unless a view is given; then that is where its line of sight
  // starts.
  DOUBLES_EQUAL(0.0, reading.view_x_m, 0.0);
  const auto seen = reading_from_point(Eigen::Vector3f(-1.0F, -1.0F, 0.5F), 0.8F,
                                       Eigen::Vector3f(0.1F, -0.2F, 0.05F));
  DOUBLES_EQUAL(0.1, seen.view_x_m, 1e-7);
  DOUBLES_EQUAL(-0.2, seen.view_y_m, 1e-7);
  DOUBLES_EQUAL(0.05, seen.view_z_m, 1e-7);
  DOUBLES_EQUAL(1.5, seen.r_m, 1e-6);
}

TEST(Triangulation, OnePixelOfDisparityMovesTheRangeByLessThanEq37ButMoreThanHalfOfIt) {
  // Eq 3.7's δr = 2r²/(bF + r) bounds the range error of one pixel of disparity.
  const RigModel rig;
  const CameraIntrinsics& cam = rig.low_res_camera();
  const CameraPose first = rig.camera_pose(0.0F, 0.0F);
  const CameraPose second = rig.second_pose(0.0F, 0.0F);
  for (const float depth : {0.5F, 1.0F, 2.0F}) {
    const Eigen::Vector3f truth = first.to_ptu(Eigen::Vector3f(0.0F, 0.0F, depth));
    Eigen::Vector2f p1;
    Eigen::Vector2f p2;
    CHECK(RigModel::project_ptu(first, cam, truth, p1));
    CHECK(RigModel::project_ptu(second, cam, truth, p2));
    Eigen::Vector3f moved;
    CHECK(triangulate_exact(first.centre_m, RigModel::ray_ptu(first, cam, p1), second.centre_m,
                            RigModel::ray_ptu(second, cam, p2 + Eigen::Vector2f(0.0F, 0.5F)),
                            moved));
    const float change = 2.0F * ((moved - first.centre_m).norm() - depth);  // per pixel
    const float dr = boticelli::evidence::range_error_m(depth, rig.baseline_m(), cam.focal_px);
    // Eq 3.7 is the bound for a one-pixel error; first order gives r²/(bF) ≈ δr·(bF + r)/(2bF).
    CHECK(std::fabs(change) < dr);
    CHECK(std::fabs(change) > 0.5F * dr);
  }
}

// The inverse-range bias removed: the point stays on its line of sight from the optical centre
// and moves to 1/r = 1/r̂ − b (farther for b > 0, nearer for b < 0); one the bias puts beyond
// the maximum range, or behind the camera, is refused and left as it was.
TEST(Triangulation, AnInverseRangeBiasIsRemovedAlongTheLineOfSight) {
  const Eigen::Vector3f centre(0.05F, -0.02F, 0.1F);
  const Eigen::Vector3f direction = Eigen::Vector3f(3.0F, 1.0F, -0.5F).normalized();
  const Eigen::Vector3f read = centre + 2.5F * direction;  // r̂ = 2.5 m
  for (const float bias : {0.1F, -0.1F, 0.0F}) {
    Eigen::Vector3f p = read;
    CHECK(remove_inverse_range_bias(centre, bias, 20.0F, p));
    const float expected = 1.0F / (1.0F / 2.5F - bias);  // 3.333, 2.0, 2.5 m
    DOUBLES_EQUAL(expected, (p - centre).norm(), 1e-5);
    CHECK(((p - centre).normalized() - direction).norm() < 1e-6F);
  }
  Eigen::Vector3f p = read;
  CHECK_FALSE(remove_inverse_range_bias(centre, 0.4F, 20.0F, p));   // 1/r = 0: at infinity
  CHECK_FALSE(remove_inverse_range_bias(centre, 0.5F, 20.0F, p));   // behind the camera
  CHECK_FALSE(remove_inverse_range_bias(centre, 0.36F, 20.0F, p));  // 25 m, beyond 20
  CHECK((p - read).norm() == 0.0F);
  CHECK(remove_inverse_range_bias(centre, 0.34F, 20.0F, p));  // 16.7 m
}
