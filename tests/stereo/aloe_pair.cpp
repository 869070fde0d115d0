// The Aloe pair: reading, downsampling, transposing, and scoring matchers against its truth.
#include "aloe_pair.h"

#include <algorithm>
#include <cmath>
#include <ctime>

#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <opencv2/video/tracking.hpp>

#include "algo/core/fixed_vector.h"
#include "algo/image/features.h"

namespace boticelli::test {

namespace {

constexpr std::uint32_t kFactor = 8;

std::int64_t thread_cpu_ns() {
  timespec ts{};
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
  return static_cast<std::int64_t>(ts.tv_sec) * 1000000000 + ts.tv_nsec;
}

double median_ms(std::vector<double> ns) {
  if (ns.empty()) {
    return 0.0;
  }
  std::sort(ns.begin(), ns.end());
  return ns[ns.size() / 2] * 1e-6;
}

// BGR photograph → packed YUYV (BT.601 full range, chroma averaged over pixel pairs), the
// camera's format, cropped to an even width.
std::vector<std::uint8_t> yuyv_from_bgr(const cv::Mat& bgr, std::uint32_t width,
                                        std::uint32_t height) {
  cv::Mat yuv;
  cv::cvtColor(bgr, yuv, cv::COLOR_BGR2YUV);
  std::vector<std::uint8_t> out(std::size_t{width} * height * 2);
  for (std::uint32_t r = 0; r < height; ++r) {
    const auto* row = yuv.ptr<cv::Vec3b>(static_cast<int>(r));
    std::uint8_t* o = out.data() + std::size_t{r} * width * 2;
    for (std::uint32_t c = 0; c < width; c += 2) {
      const cv::Vec3b& a = row[c];
      const cv::Vec3b& b = row[c + 1];
      o[2 * c + 0] = a[0];
      o[2 * c + 1] = static_cast<std::uint8_t>((a[1] + b[1] + 1) / 2);
      o[2 * c + 2] = b[0];
      o[2 * c + 3] = static_cast<std::uint8_t>((a[2] + b[2] + 1) / 2);
    }
  }
  return out;
}

void transpose(const image::LowResFrame& in, image::LowResFrame& out) {
  out.width = in.height;
  out.height = in.width;
  for (std::uint32_t v = 0; v < in.height; ++v) {
    for (std::uint32_t u = 0; u < in.width; ++u) {
      out.luma[out.index(v, u)] = in.luma[in.index(u, v)];
      out.chroma_u[out.index(v, u)] = in.chroma_u[in.index(u, v)];
      out.chroma_v[out.index(v, u)] = in.chroma_v[in.index(u, v)];
    }
  }
}

// A match of the feature at (u, v) found at row v_match: counted against the truth.
void count(const AloePair& pair, std::uint32_t u, std::uint32_t v, float v_match, StereoYield& y) {
  ++y.matched;
  const float truth = pair.disparity_px[pair.first.index(u, v)];
  if (truth < 0.0F) {
    return;
  }
  ++y.with_truth;
  const float d = static_cast<float>(v) - v_match;
  const float error = pair.disparity_error(u, v, d);
  y.within_1px += error <= 1.0F ? 1U : 0U;
  y.beyond_3px += error > 3.0F ? 1U : 0U;
  const float error_of_mean = std::fabs(d - truth);
  y.within_1px_of_mean += error_of_mean <= 1.0F ? 1U : 0U;
  y.beyond_3px_of_mean += error_of_mean > 3.0F ? 1U : 0U;
}

}  // namespace

float AloePair::disparity_error(std::uint32_t u, std::uint32_t v, float d) const {
  float best = -1.0F;
  for (std::uint32_t r = u * factor; r < (u + 1) * factor; ++r) {
    for (std::uint32_t c = v * factor; c < (v + 1) * factor; ++c) {
      const std::uint8_t t = truth_full[std::size_t{c} * truth_full_width + r];
      if (t == 0) {
        return -1.0F;
      }
      const float e = std::fabs(d - static_cast<float>(t) / static_cast<float>(factor));
      best = best < 0.0F ? e : std::min(best, e);
    }
  }
  return best;
}

bool load_aloe_pair(const std::string& directory, AloePair& out, std::string& why) {
  const cv::Mat left = cv::imread(directory + "/aloeL.jpg", cv::IMREAD_COLOR);
  const cv::Mat right = cv::imread(directory + "/aloeR.jpg", cv::IMREAD_COLOR);
  const cv::Mat truth = cv::imread(directory + "/aloeGT.png", cv::IMREAD_GRAYSCALE);
  if (left.empty() || right.empty() || truth.empty()) {
    why = "cannot read aloeL.jpg, aloeR.jpg or aloeGT.png in " + directory;
    return false;
  }
  if (left.size() != right.size() || left.size() != truth.size() || left.cols < 8) {
    why = "the Aloe images differ in size";
    return false;
  }
  const auto width = static_cast<std::uint32_t>(left.cols) & ~1U;
  const auto height = static_cast<std::uint32_t>(left.rows);
  static image::LowResFrame low_left;
  static image::LowResFrame low_right;
  const std::vector<std::uint8_t> yuyv_left = yuyv_from_bgr(left, width, height);
  const std::vector<std::uint8_t> yuyv_right = yuyv_from_bgr(right, width, height);
  if (!image::downsample_yuyv(yuyv_left.data(), width, height, width * 2, kFactor, low_left) ||
      !image::downsample_yuyv(yuyv_right.data(), width, height, width * 2, kFactor, low_right)) {
    why = "the Aloe images do not fit a low-resolution frame";
    return false;
  }
  transpose(low_left, out.first);
  transpose(low_right, out.second);
  // Transposed: column c of the photograph is row c here.
  out.factor = kFactor;
  out.truth_full_width = low_left.height * kFactor;
  out.truth_full.assign(std::size_t{out.truth_full_width} * low_left.width * kFactor, 0);
  for (std::uint32_t r = 0; r < out.truth_full_width; ++r) {
    for (std::uint32_t c = 0; c < low_left.width * kFactor; ++c) {
      out.truth_full[std::size_t{c} * out.truth_full_width + r] =
          truth.at<std::uint8_t>(static_cast<int>(r), static_cast<int>(c));
    }
  }
  out.disparity_px.assign(std::size_t{out.first.width} * out.first.height, -1.0F);
  out.max_disparity_px = 0.0F;
  for (std::uint32_t r = 0; r < low_left.height; ++r) {
    for (std::uint32_t c = 0; c < low_left.width; ++c) {
      float sum = 0.0F;
      bool known = true;
      for (std::uint32_t dr = 0; dr < kFactor && known; ++dr) {
        for (std::uint32_t dc = 0; dc < kFactor; ++dc) {
          const std::uint8_t d = truth.at<std::uint8_t>(static_cast<int>(r * kFactor + dr),
                                                        static_cast<int>(c * kFactor + dc));
          known = known && d > 0;
          sum += static_cast<float>(d);
        }
      }
      if (known) {
        const float d = sum / static_cast<float>(kFactor * kFactor * kFactor);
        out.disparity_px[out.first.index(r, c)] = d;
        out.max_disparity_px = std::max(out.max_disparity_px, d);
      }
    }
  }
  return true;
}

StereoYield track_aloe(const AloePair& pair, const image::TrackParams& params, int repeats) {
  image::FeatureParams feature_params;
  feature_params.max_features = 500;
  // The band covers the whole frame: the selector keeps its 3 px border.
  feature_params.band_half_width_at_f150_px = 1000.0F;
  feature_params.band_half_height_at_f150_px = 1000.0F;
  static image::FeatureSelector selector{feature_params};
  selector = image::FeatureSelector{feature_params};
  const image::BandGeometry band{static_cast<float>(pair.first.width) / 2.0F,
                                 static_cast<float>(pair.first.height) / 2.0F, 150.0F};
  static core::FixedVector<image::Feature, image::FeatureSelector::kMaxFeatures> features;
  const float search = std::ceil(pair.max_disparity_px) + 2.0F;
  StereoYield y;
  std::vector<double> cpu_ns;
  for (int r = 0; r < std::max(repeats, 1); ++r) {
    StereoYield run;
    const std::int64_t c0 = thread_cpu_ns();
    selector.select(pair.first, band, features);
    for (const image::Feature& f : features) {
      const auto u = static_cast<float>(f.u_px);
      const auto v = static_cast<float>(f.v_px);
      const image::EpipolarSegment segment{u, v, u, v - search};
      const image::Track t =
          image::track_feature(pair.first, f.u_px, f.v_px, pair.second, segment, params);
      if (t.found) {
        count(pair, f.u_px, f.v_px, t.v_px, run);
      }
    }
    cpu_ns.push_back(static_cast<double>(thread_cpu_ns() - c0));
    run.features = features.size();
    y = run;
  }
  y.cpu_ms = median_ms(cpu_ns);
  return y;
}

StereoYield track_aloe_opencv(const AloePair& pair, int repeats) {
  const auto to_mat = [](const image::LowResFrame& f) {
    cv::Mat m(static_cast<int>(f.height), static_cast<int>(f.width), CV_8U);
    for (std::uint32_t v = 0; v < f.height; ++v) {
      for (std::uint32_t u = 0; u < f.width; ++u) {
        m.at<std::uint8_t>(static_cast<int>(v), static_cast<int>(u)) =
            static_cast<std::uint8_t>(std::lround(std::clamp(f.y(u, v), 0.0F, 255.0F)));
      }
    }
    return m;
  };
  const cv::Mat first = to_mat(pair.first);
  const cv::Mat second = to_mat(pair.second);
  std::vector<cv::Point2f> corners;
  std::vector<cv::Point2f> tracked;
  std::vector<unsigned char> status;
  std::vector<float> error;
  StereoYield y;
  std::vector<double> cpu_ns;
  // All of OpenCV's work on this thread, so that its thread CPU time is all of it.
  const int threads = cv::getNumThreads();
  cv::setNumThreads(0);
  for (int r = 0; r < std::max(repeats, 1); ++r) {
    StereoYield run;
    const std::int64_t c0 = thread_cpu_ns();
    cv::goodFeaturesToTrack(first, corners, 500, 0.01, 2.0);
    tracked.clear();
    if (!corners.empty()) {
      cv::calcOpticalFlowPyrLK(first, second, corners, tracked, status, error, cv::Size(15, 15), 3);
    }
    cpu_ns.push_back(static_cast<double>(thread_cpu_ns() - c0));
    run.features = corners.size();
    for (std::size_t i = 0; i < tracked.size(); ++i) {
      if (status[i] == 0 || std::fabs(tracked[i].x - corners[i].x) > 1.0F) {
        continue;
      }
      const auto u = static_cast<std::uint32_t>(std::lround(corners[i].x));
      const auto v = static_cast<std::uint32_t>(std::lround(corners[i].y));
      if (u >= pair.first.width || v >= pair.first.height) {
        continue;
      }
      // A corner is sub-pixel: its match is counted at the pixel it rounds to.
      count(pair, u, v, tracked[i].y - (corners[i].y - static_cast<float>(v)), run);
    }
    y = run;
  }
  cv::setNumThreads(threads);
  y.cpu_ms = median_ms(cpu_ns);
  return y;
}

}  // namespace boticelli::test
