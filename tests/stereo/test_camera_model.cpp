// Tests of the camera model against OpenCV's: distortion and undistortion of random points.
#include <cmath>
#include <cstdint>
#include <random>
#include <vector>

#include <opencv2/calib3d.hpp>
#include <opencv2/core.hpp>

#include "algo/stereo/rig.h"
#include "CppUTest/TestHarness.h"
#include "CppUTest/MemoryLeakWarningPlugin.h"
#include "alloc_guard.h"

using namespace boticelli;

namespace {

// Lenses as calibrateCamera reports them for webcams: mild barrel, a strong wide-angle one,
// and one with tangential terms (a sensor not square to the lens).
stereo::CameraIntrinsics lens(int which) {
  stereo::CameraIntrinsics c;
  c.focal_px = 600.0F;
  c.principal_x_px = 322.4F;
  c.principal_y_px = 236.8F;
  switch (which) {
    case 0:
      c.k1 = -0.12F;
      c.k2 = 0.08F;
      break;
    case 1:
      c.k1 = -0.32F;
      c.k2 = 0.12F;
      c.k3 = -0.02F;
      break;
    default:
      c.k1 = -0.05F;
      c.k2 = 0.02F;
      c.p1 = 0.002F;
      c.p2 = -0.0015F;
      c.k3 = 0.01F;
      break;
  }
  return c;
}

cv::Mat camera_matrix(const stereo::CameraIntrinsics& c) {
  return (cv::Mat_<double>(3, 3) << c.focal_px, 0.0, c.principal_x_px, 0.0, c.focal_px,
          c.principal_y_px, 0.0, 0.0, 1.0);
}

cv::Mat coefficients(const stereo::CameraIntrinsics& c) {
  return (cv::Mat_<double>(1, 5) << c.k1, c.k2, c.p1, c.p2, c.k3);
}

}  // namespace

TEST_GROUP(CameraModel){// OpenCV keeps buffers process-wide: not leaks of a test.
                        void setup()
                            override{MemoryLeakWarningPlugin::saveAndDisableNewDeleteOverloads();
}
void teardown() override {
  MemoryLeakWarningPlugin::restoreNewDeleteOverloads();
}
}
;

// Random pixels over the whole 640x480 image, undistorted by the model and by OpenCV's
// undistortPoints (iterated to convergence): the same normalised coordinates to 1e-5 (under
// a hundredth of a pixel at F = 600 px).
TEST(CameraModel, UndistortionAgreesWithOpenCvsUndistortPoints) {
  std::mt19937 rng(49);
  std::uniform_real_distribution<float> u(0.0F, 639.0F);
  std::uniform_real_distribution<float> v(0.0F, 479.0F);
  for (int which = 0; which < 3; ++which) {
    const stereo::CameraIntrinsics c = lens(which);
    std::vector<cv::Point2f> pixels;
    for (int i = 0; i < 500; ++i) {
      pixels.emplace_back(u(rng), v(rng));
    }
    std::vector<cv::Point2f> theirs;
    cv::undistortPoints(
        pixels, theirs, camera_matrix(c), coefficients(c), cv::noArray(), cv::noArray(),
        cv::TermCriteria(cv::TermCriteria::COUNT | cv::TermCriteria::EPS, 100, 1e-12));
    double worst = 0.0;
    for (std::size_t i = 0; i < pixels.size(); ++i) {
      Eigen::Vector2f ours;
      CHECK_NO_ALLOCATION(ours =
                              c.normalized_from_pixel(Eigen::Vector2f(pixels[i].x, pixels[i].y)));
      worst = std::fmax(worst, std::hypot(ours.x() - theirs[i].x, ours.y() - theirs[i].y));
    }
    CHECK(worst < 1e-5);
  }
}

// Random normalised points distorted by the model and projected by OpenCV's projectPoints
// (no rotation or translation): the same pixels to 1e-3 px.
TEST(CameraModel, DistortionAgreesWithOpenCvsProjectPoints) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<float> x(-0.55F, 0.55F);
  std::uniform_real_distribution<float> y(-0.4F, 0.4F);
  for (int which = 0; which < 3; ++which) {
    const stereo::CameraIntrinsics c = lens(which);
    std::vector<cv::Point3f> points;
    for (int i = 0; i < 500; ++i) {
      points.emplace_back(x(rng), y(rng), 1.0F);
    }
    std::vector<cv::Point2f> theirs;
    cv::projectPoints(points, cv::Vec3d(0, 0, 0), cv::Vec3d(0, 0, 0), camera_matrix(c),
                      coefficients(c), theirs);
    double worst = 0.0;
    for (std::size_t i = 0; i < points.size(); ++i) {
      const Eigen::Vector2f ours =
          c.pixel_from_normalized(Eigen::Vector2f(points[i].x, points[i].y));
      worst = std::fmax(worst, std::hypot(ours.x() - theirs[i].x, ours.y() - theirs[i].y));
    }
    CHECK(worst < 1e-3);
  }
}

// With k2 = p1 = p2 = k3 = 0 the model is the one-term model it replaced, to the bit, at every
// pixel of a 640x480 image and back.
TEST(CameraModel, WithKOneAloneTheModelIsTheOneTermModel) {
  stereo::CameraIntrinsics c;
  c.k1 = -0.02F;
  for (int row = 0; row < 480; row += 3) {
    for (int col = 0; col < 640; col += 3) {
      const Eigen::Vector2f pixel(static_cast<float>(col) + 0.25F, static_cast<float>(row));
      const Eigen::Vector2f distorted((pixel.x() - c.principal_x_px) / c.focal_px,
                                      (pixel.y() - c.principal_y_px) / c.focal_px);
      Eigen::Vector2f x = distorted;
      for (int iteration = 0; iteration < 8; ++iteration) {
        x = distorted / (1.0F + c.k1 * x.squaredNorm());
      }
      const Eigen::Vector2f n = c.normalized_from_pixel(pixel);
      CHECK(n.x() == x.x() && n.y() == x.y());
      const float scale = 1.0F + c.k1 * x.squaredNorm();
      const Eigen::Vector2f back = c.pixel_from_normalized(x);
      CHECK(back.x() == c.principal_x_px + c.focal_px * scale * x.x());
      CHECK(back.y() == c.principal_y_px + c.focal_px * scale * x.y());
    }
  }
}
