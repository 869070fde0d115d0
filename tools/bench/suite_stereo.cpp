// Benchmark suite "stereo": time and depth accuracy per frame pair, ours against OpenCV; the Aloe
// pair.
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <ctime>
#include <string>
#include <vector>

#include "algo/core/fixed_vector.h"
#include "algo/evidence/reading.h"
#include "algo/evidence/sensor_model.h"
#include "algo/stereo/stereo_processor.h"
#include "bench.h"
#include "stereo_scenes.h"
#ifdef BOTICELLI_OPENCV_SAMPLES_DIR
#include "aloe_pair.h"
#endif

#ifdef BOTICELLI_BENCH_HAVE_OPENCV
#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>
#include <opencv2/video/tracking.hpp>
#endif

namespace {

using boticelli::stereo::CameraPose;
using boticelli::stereo::RigModel;

constexpr float kBandEdges[] = {0.3F, 1.0F, 2.0F, 3.0F, 4.6F};
constexpr const char* kBandNames[] = {"0.3-1", "1-2", "2-3", "3-4.5"};
constexpr int kBands = 4;

// Errors |r − r_true| / δr(r_true) (Eq 3.7) and |r − r_true| / r_true per range band of the
// true range: the second is what the ray samples' δr / r is sized from (docs/evidence.md).
struct Accuracy {
  std::vector<float> normalized[kBands];
  std::vector<float> relative[kBands];
  std::size_t readings = 0;

  void add(const boticelli::test::WallPair& pair, const RigModel& rig, const CameraPose& first,
           const Eigen::Vector2f& first_px, const Eigen::Vector3f& point_ptu_m) {
    const Eigen::Vector3f ray = RigModel::ray_ptu(first, rig.low_res_camera(), first_px);
    float t = 0.0F;
    if (!pair.scene.intersect(first.centre_m, ray, t)) {
      return;
    }
    ++readings;
    const float truth = (first.centre_m + t * ray).norm();
    const float dr =
        boticelli::evidence::range_error_m(t, rig.baseline_m(), rig.low_res_camera().focal_px);
    for (int b = 0; b < kBands; ++b) {
      if (t >= kBandEdges[b] && t < kBandEdges[b + 1]) {
        normalized[b].push_back(std::fabs(point_ptu_m.norm() - truth) / dr);
        relative[b].push_back(std::fabs(point_ptu_m.norm() - truth) / truth);
      }
    }
  }

  void emit_into(boticelli::bench::JsonLine& line) {
    char key[64];
    for (int b = 0; b < kBands; ++b) {
      std::vector<float>& v = normalized[b];
      std::sort(v.begin(), v.end());
      const double median = v.empty() ? -1.0 : static_cast<double>(v[v.size() / 2]);
      const auto outliers =
          static_cast<double>(std::count_if(v.begin(), v.end(), [](float e) { return e > 2.0F; }));
      std::snprintf(key, sizeof key, "median_err_over_dr_%s_m", kBandNames[b]);
      line.num(key, median);
      std::snprintf(key, sizeof key, "outliers_pct_%s_m", kBandNames[b]);
      line.num(key, v.empty() ? -1.0 : 100.0 * outliers / static_cast<double>(v.size()));
      std::vector<float>& rel = relative[b];
      std::sort(rel.begin(), rel.end());
      for (const int pct : {50, 90, 95}) {
        std::snprintf(key, sizeof key, "p%d_err_over_r_%s_m", pct, kBandNames[b]);
        line.num(key, rel.empty() ? -1.0
                                  : static_cast<double>(
                                        rel[rel.size() * static_cast<std::size_t>(pct) / 100]));
      }
    }
  }
};

// CPU time of this thread [ns]: robust to other processes sharing the cores.
std::int64_t thread_cpu_ns() {
  timespec ts{};
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
  return static_cast<std::int64_t>(ts.tv_sec) * 1000000000 + ts.tv_nsec;
}

double median_ms(std::vector<double>& ns) {
  std::sort(ns.begin(), ns.end());
  return ns[ns.size() / 2] * 1e-6;
}

boticelli::stereo::PairPose pair_pose(const RigModel& rig, const boticelli::test::WallPair& pair) {
  return {pair.pan_rad, pair.first_tilt_rad, pair.first_tilt_rad - rig.params().tilt_step_rad};
}

// The Middlebury "Aloe" pair (a real photograph pair with ground truth, OpenCV's sample
// data) at 160x138, transposed: the tracker with its defaults, with the thesis's test alone
// (E_thresh on whole rows), and OpenCV GFTT + PyrLK on the same frames.
void aloe_cases() {
  namespace bench = boticelli::bench;
#ifdef BOTICELLI_OPENCV_SAMPLES_DIR
  static boticelli::test::AloePair pair;
  std::string why;
  if (!boticelli::test::load_aloe_pair(BOTICELLI_OPENCV_SAMPLES_DIR, pair, why)) {
    bench::JsonLine("stereo", "aloe").text("skipped", why.c_str()).emit();
    return;
  }
  constexpr int kAloeRepeats = 50;
  const auto emit = [](const char* name, const boticelli::test::StereoYield& y) {
    bench::JsonLine line("stereo", name);
    line.integer("features", static_cast<std::int64_t>(y.features))
        .integer("matched", static_cast<std::int64_t>(y.matched))
        .num("yield", y.yield())
        .num("within_1px", y.share_within_1px())
        .num("beyond_3px", y.share_beyond_3px())
        .num("within_1px_of_block_mean",
             y.with_truth == 0
                 ? 0.0
                 : static_cast<double>(y.within_1px_of_mean) / static_cast<double>(y.with_truth))
        .num("beyond_3px_of_block_mean",
             y.with_truth == 0
                 ? 0.0
                 : static_cast<double>(y.beyond_3px_of_mean) / static_cast<double>(y.with_truth))
        .num("cpu_ms_median", y.cpu_ms);
    line.emit();
  };
  emit("aloe_ours",
       boticelli::test::track_aloe(pair, boticelli::image::TrackParams{}, kAloeRepeats));
  boticelli::image::TrackParams whole_rows;
  whole_rows.half_pixel_search = false;
  whole_rows.normalized_error_thresh = 0.0F;
  emit("aloe_ours_thesis_test", boticelli::test::track_aloe(pair, whole_rows, kAloeRepeats));
  boticelli::image::TrackParams half_only = boticelli::image::TrackParams{};
  half_only.normalized_error_thresh = 0.0F;
  emit("aloe_ours_half_rows_only", boticelli::test::track_aloe(pair, half_only, kAloeRepeats));
  boticelli::image::TrackParams normalized_only = whole_rows;
  normalized_only.normalized_error_thresh = boticelli::image::TrackParams{}.normalized_error_thresh;
  emit("aloe_ours_normalized_only",
       boticelli::test::track_aloe(pair, normalized_only, kAloeRepeats));
  emit("aloe_opencv_gftt_pyrlk", boticelli::test::track_aloe_opencv(pair, kAloeRepeats));
#else
  bench::JsonLine("stereo", "aloe")
      .text("skipped", "OpenCV or its sample data (opencv-doc) not found at configure time")
      .emit();
#endif
}

}  // namespace

BOTICELLI_BENCH_SUITE(stereo,
                      "frame pair: downsample+select+track+triangulate, vs OpenCV GFTT+PyrLK") {
  namespace bench = boticelli::bench;
  const RigModel rig;
  static boticelli::stereo::StereoProcessor processor{rig};
  static boticelli::core::FixedVector<boticelli::evidence::Reading, 4096> readings;
  const std::vector<float> distances = boticelli::test::wall_distances_m();
  std::vector<boticelli::test::WallPair> pairs(distances.size());
  for (std::size_t k = 0; k < distances.size(); ++k) {
    boticelli::test::render_wall_pair(rig, k, distances[k], pairs[k]);
  }
  const std::uint32_t stride = rig.camera().width_px * 2;
  constexpr int kRepeats = 30;

  // Ours: YUYV → 160x120 (both frames), 500 features, epipolar tracking, exact triangulation.
  {
    Accuracy accuracy;
    std::size_t features = 0;
    for (const auto& pair : pairs) {
      readings.clear();
      processor.process_yuyv(pair.first_yuyv.data(), pair.second_yuyv.data(), stride,
                             pair_pose(rig, pair), readings);
      features += processor.features().size();
      const CameraPose first = rig.camera_pose(pair.pan_rad, pair.first_tilt_rad);
      for (const auto& p : processor.points()) {
        accuracy.add(pair, rig, first, p.first_px, p.point_ptu_m);
      }
    }
    std::vector<double> per_pair_ns;
    std::vector<double> per_pair_cpu_ns;
    for (int r = 0; r < kRepeats; ++r) {
      for (const auto& pair : pairs) {
        readings.clear();
        const std::int64_t c0 = thread_cpu_ns();
        const std::int64_t t0 = bench::now_ns();
        processor.process_yuyv(pair.first_yuyv.data(), pair.second_yuyv.data(), stride,
                               pair_pose(rig, pair), readings);
        const std::int64_t t1 = bench::now_ns();
        const std::int64_t c1 = thread_cpu_ns();
        bench::do_not_optimize(readings.size());
        per_pair_ns.push_back(static_cast<double>(t1 - t0));
        per_pair_cpu_ns.push_back(static_cast<double>(c1 - c0));
      }
    }
    bench::JsonLine line("stereo", "ours_epipolar");
    line.integer("pairs", static_cast<std::int64_t>(pairs.size()))
        .num("ms_per_pair_median", median_ms(per_pair_ns))
        .num("cpu_ms_per_pair_median", median_ms(per_pair_cpu_ns))
        .num("features_per_pair", static_cast<double>(features) / static_cast<double>(pairs.size()))
        .num("readings_per_pair",
             static_cast<double>(accuracy.readings) / static_cast<double>(pairs.size()));
    accuracy.emit_into(line);
    line.emit();
  }

#ifdef BOTICELLI_BENCH_HAVE_OPENCV
  // OpenCV: YUYV → grey → 160x120 (area averaging), goodFeaturesToTrack (500, same band),
  // calcOpticalFlowPyrLK, then the same triangulation.
  {
    const auto& cam = rig.low_res_camera();
    cv::Mat mask =
        cv::Mat::zeros(static_cast<int>(cam.height_px), static_cast<int>(cam.width_px), CV_8U);
    const float half_w = 53.0F * cam.focal_px / 150.0F;
    const float half_h = 40.0F * cam.focal_px / 150.0F;
    cv::rectangle(mask,
                  cv::Point(static_cast<int>(cam.principal_x_px - half_w),
                            static_cast<int>(cam.principal_y_px - half_h)),
                  cv::Point(static_cast<int>(cam.principal_x_px + half_w),
                            static_cast<int>(cam.principal_y_px + half_h)),
                  cv::Scalar(255), cv::FILLED);
    cv::Mat full_first;
    cv::Mat full_second;
    cv::Mat grey_first;
    cv::Mat grey_second;
    cv::Mat small_first;
    cv::Mat small_second;
    std::vector<cv::Point2f> corners;
    std::vector<cv::Point2f> tracked;
    std::vector<unsigned char> status;
    std::vector<float> error;
    Accuracy accuracy;
    std::vector<double> per_pair_ns;
    std::vector<double> per_pair_cpu_ns;
    for (int r = 0; r < kRepeats + 1; ++r) {
      for (const auto& pair : pairs) {
        const CameraPose first = rig.camera_pose(pair.pan_rad, pair.first_tilt_rad);
        const CameraPose second =
            rig.camera_pose(pair.pan_rad, pair.first_tilt_rad - rig.params().tilt_step_rad);
        const cv::Mat yuyv_first(static_cast<int>(rig.camera().height_px),
                                 static_cast<int>(rig.camera().width_px), CV_8UC2,
                                 const_cast<std::uint8_t*>(pair.first_yuyv.data()));
        const cv::Mat yuyv_second(static_cast<int>(rig.camera().height_px),
                                  static_cast<int>(rig.camera().width_px), CV_8UC2,
                                  const_cast<std::uint8_t*>(pair.second_yuyv.data()));
        readings.clear();
        const std::int64_t c0 = thread_cpu_ns();
        const std::int64_t t0 = bench::now_ns();
        cv::cvtColor(yuyv_first, grey_first, cv::COLOR_YUV2GRAY_YUYV);
        cv::cvtColor(yuyv_second, grey_second, cv::COLOR_YUV2GRAY_YUYV);
        cv::resize(grey_first, small_first,
                   cv::Size(static_cast<int>(cam.width_px), static_cast<int>(cam.height_px)), 0, 0,
                   cv::INTER_AREA);
        cv::resize(grey_second, small_second,
                   cv::Size(static_cast<int>(cam.width_px), static_cast<int>(cam.height_px)), 0, 0,
                   cv::INTER_AREA);
        cv::goodFeaturesToTrack(small_first, corners, 500, 0.01, 2.0, mask);
        tracked.clear();
        if (!corners.empty()) {
          cv::calcOpticalFlowPyrLK(small_first, small_second, corners, tracked, status, error,
                                   cv::Size(15, 15), 3);
        }
        std::size_t n = 0;
        for (std::size_t i = 0; i < tracked.size(); ++i) {
          if (status[i] == 0) continue;
          Eigen::Vector3f point;
          const Eigen::Vector2f p1(corners[i].x, corners[i].y);
          const Eigen::Vector2f p2(tracked[i].x, tracked[i].y);
          if (!processor.triangulate(first, second, p1, p2, point)) continue;
          if ((point - first.centre_m).norm() < processor.params().min_range_m) continue;
          boticelli::evidence::Reading reading;
          reading.r_m = point.norm();
          (void)readings.push_back(reading);
          ++n;
          if (r == 0) {
            accuracy.add(pair, rig, first, p1, point);
          }
        }
        const std::int64_t t1 = bench::now_ns();
        const std::int64_t c1 = thread_cpu_ns();
        bench::do_not_optimize(n);
        if (r > 0) {
          per_pair_ns.push_back(static_cast<double>(t1 - t0));
          per_pair_cpu_ns.push_back(static_cast<double>(c1 - c0));
        }
      }
    }
    bench::JsonLine line("stereo", "opencv_gftt_pyrlk");
    line.integer("pairs", static_cast<std::int64_t>(pairs.size()))
        .num("ms_per_pair_median", median_ms(per_pair_ns))
        .num("cpu_ms_per_pair_median", median_ms(per_pair_cpu_ns))
        .num("readings_per_pair",
             static_cast<double>(accuracy.readings) / static_cast<double>(pairs.size()));
    accuracy.emit_into(line);
    line.emit();
  }
#else
  bench::JsonLine("stereo", "opencv_gftt_pyrlk")
      .text("skipped", "OpenCV not found at configure time")
      .emit();
#endif
  aloe_cases();
  return 0;
}
