// Range accuracy of the whole frame-pair pipeline on rendered walls at 0.3–4.5 m, per range band.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <vector>

#include "algo/core/fixed_vector.h"
#include "algo/evidence/reading.h"
#include "algo/evidence/sensor_model.h"
#include "algo/stereo/stereo_processor.h"
#include "stereo_scenes.h"
#include "CppUTest/TestHarness.h"
#include "alloc_guard.h"

using namespace boticelli;

namespace {

struct Band {
  float lo_m;
  float hi_m;
  std::vector<float> normalized_errors;  // |r − r_true| / δr(r_true)
  std::vector<float> errors_m;
};

stereo::StereoProcessor& processor() {
  static stereo::StereoProcessor instance{stereo::RigModel{}};
  return instance;
}

}  // namespace

TEST_GROUP(RangeAccuracy){};

TEST(RangeAccuracy, MedianErrorIsUnderHalfAPixelOfQuantisationInEveryBand) {
  const stereo::RigModel rig;
  auto& proc = processor();
  static core::FixedVector<evidence::Reading, 4096> readings;
  std::vector<Band> bands = {
      {0.3F, 1.0F, {}, {}}, {1.0F, 2.0F, {}, {}}, {2.0F, 3.0F, {}, {}}, {3.0F, 4.6F, {}, {}}};
  test::WallPair pair;
  const std::vector<float> distances = test::wall_distances_m();
  std::size_t features = 0;
  for (std::size_t k = 0; k < distances.size(); ++k) {
    test::render_wall_pair(rig, k, distances[k], pair, 2);
    readings.clear();
    const stereo::PairPose pose{pair.pan_rad, pair.first_tilt_rad,
                                pair.first_tilt_rad - rig.params().tilt_step_rad};
    proc.process_yuyv(pair.first_yuyv.data(), pair.second_yuyv.data(), rig.camera().width_px * 2,
                      pose, readings);
    features += proc.features().size();
    const stereo::CameraPose first = rig.camera_pose(pose.pan_rad, pose.first_tilt_rad);
    for (const stereo::StereoPoint& p : proc.points()) {
      const Eigen::Vector3f ray =
          stereo::RigModel::ray_ptu(first, rig.low_res_camera(), p.first_px);
      float t = 0.0F;
      CHECK(pair.scene.intersect(first.centre_m, ray, t));
      const Eigen::Vector3f truth = first.centre_m + t * ray;
      const float dr = evidence::range_error_m(t, rig.baseline_m(), rig.low_res_camera().focal_px);
      const float err = std::fabs(p.reading.r_m - truth.norm());
      for (Band& b : bands) {
        if (t >= b.lo_m && t < b.hi_m) {
          b.normalized_errors.push_back(err / dr);
          b.errors_m.push_back(err);
        }
      }
    }
  }
  std::printf("\n  %zu frame pairs, %zu features selected\n", distances.size(), features);
  std::printf("  band [m]   readings  median|err| [m]  median|err|/dr  >2dr\n");
  for (Band& b : bands) {
    CHECK(b.normalized_errors.size() > 100);
    std::vector<float> sorted = b.normalized_errors;
    std::sort(sorted.begin(), sorted.end());
    std::vector<float> metres = b.errors_m;
    std::sort(metres.begin(), metres.end());
    const float median = sorted[sorted.size() / 2];
    const auto outliers = static_cast<std::size_t>(
        std::count_if(sorted.begin(), sorted.end(), [](float e) { return e > 2.0F; }));
    const double outlier_share = static_cast<double>(outliers) / static_cast<double>(sorted.size());
    std::printf("  %.1f-%.1f   %6zu     %8.4f          %6.3f        %5.2f%%\n",
                static_cast<double>(b.lo_m), static_cast<double>(b.hi_m), sorted.size(),
                static_cast<double>(metres[metres.size() / 2]), static_cast<double>(median),
                100.0 * outlier_share);
    CHECK(median <= 0.5F);
    CHECK(outlier_share <= 0.05);
  }
}

// Eq 3.8 of E, or of the normalised error where that is higher (strong texture).
TEST(RangeAccuracy, EvidenceOfEveryReadingIsEq38OfItsMatchError) {
  const stereo::RigModel rig;
  auto& proc = processor();
  static core::FixedVector<evidence::Reading, 4096> readings;
  readings.clear();
  test::WallPair pair;
  test::render_wall_pair(rig, 3, 1.2F, pair, 2);
  const stereo::PairPose pose{pair.pan_rad, pair.first_tilt_rad,
                              pair.first_tilt_rad - rig.params().tilt_step_rad};
  const std::size_t n = proc.process_yuyv(pair.first_yuyv.data(), pair.second_yuyv.data(),
                                          rig.camera().width_px * 2, pose, readings);
  CHECK(n > 50);
  LONGS_EQUAL(proc.points().size(), n);
  const float e_max = proc.params().match_error_max;
  const float n_max = proc.params().normalized_error_max;
  const auto eq38 = [](float error, float max) {
    if (!(error >= 0.0F) || !(error < max)) return 0.0F;
    const float q = error / max;
    return 1.0F - q * q;
  };
  std::size_t by_normalized = 0;
  for (std::size_t i = 0; i < n; ++i) {
    const stereo::StereoPoint& p = proc.points()[i];
    const float m = std::max(eq38(p.match_error, e_max), eq38(p.normalized_error, n_max));
    DOUBLES_EQUAL(m, readings[i].m, 1e-5);
    by_normalized += eq38(p.normalized_error, n_max) > eq38(p.match_error, e_max) ? 1U : 0U;
    CHECK(p.match_error < proc.params().tracking.match_error_thresh ||
          p.normalized_error < proc.params().tracking.normalized_error_thresh);
  }
  CHECK(by_normalized > 0);
}

TEST(RangeAccuracy, FastTriangulationGivesTheSameRangesAsTheExactOne) {
  const stereo::RigModel rig;
  stereo::StereoParams params;
  params.fast_triangulation = true;
  static stereo::StereoProcessor fast{rig, params};
  auto& exact = processor();
  static core::FixedVector<evidence::Reading, 4096> a;
  static core::FixedVector<evidence::Reading, 4096> b;
  a.clear();
  b.clear();
  test::WallPair pair;
  test::render_wall_pair(rig, 4, 0.8F, pair, 2);
  const stereo::PairPose pose{pair.pan_rad, pair.first_tilt_rad,
                              pair.first_tilt_rad - rig.params().tilt_step_rad};
  exact.process_yuyv(pair.first_yuyv.data(), pair.second_yuyv.data(), rig.camera().width_px * 2,
                     pose, a);
  fast.process_yuyv(pair.first_yuyv.data(), pair.second_yuyv.data(), rig.camera().width_px * 2,
                    pose, b);
  CHECK(a.size() > 50);
  LONGS_EQUAL(a.size(), b.size());
  std::vector<float> diffs;
  for (std::size_t i = 0; i < a.size(); ++i) {
    diffs.push_back(std::fabs(a[i].r_m - b[i].r_m) / a[i].r_m);
  }
  std::sort(diffs.begin(), diffs.end());
  // The fast form drops the sub-pixel column of the match (Eq 3.4 uses rows only).
  CHECK(diffs[diffs.size() / 2] < 0.01F);
}

TEST(RangeAccuracy, AFramePairIsProcessedWithoutHeapAllocation) {
  const stereo::RigModel rig;
  auto& proc = processor();
  static core::FixedVector<evidence::Reading, 4096> readings;
  readings.clear();
  test::WallPair pair;
  test::render_wall_pair(rig, 5, 1.5F, pair, 2);
  const stereo::PairPose pose{pair.pan_rad, pair.first_tilt_rad,
                              pair.first_tilt_rad - rig.params().tilt_step_rad};
  std::size_t n = 0;
  CHECK_NO_ALLOCATION(n = proc.process_yuyv(pair.first_yuyv.data(), pair.second_yuyv.data(),
                                            rig.camera().width_px * 2, pose, readings));
  CHECK(n > 50);
}
