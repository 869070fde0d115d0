// Feature tracking along the epipolar band with Eq 3.1 match error and parabolic sub-pixel
// refinement.
#include "algo/image/epipolar_tracker.h"

#include <array>
#include <cmath>
#include <limits>

namespace boticelli::image {

namespace {

constexpr int kHalfWindow = 2;  // 5x5 window
constexpr int kMaxRows = 512;   // longest searched segment [rows]

// The feature's window minus its centre (V of Eq 3.1), row-major, centre included (0).
struct Window {
  std::array<float, 25> values{};
};

Window window_of(const LowResFrame& frame, int u, int v) {
  Window out;
  const float* y = frame.luma.data();
  const auto w = static_cast<int>(frame.width);
  const float centre = y[v * w + u];
  int k = 0;
  for (int dv = -kHalfWindow; dv <= kHalfWindow; ++dv) {
    const float* row = y + (v + dv) * w + u - kHalfWindow;
    for (int du = 0; du < 5; ++du) {
      out.values[static_cast<std::size_t>(k++)] = row[du] - centre;
    }
  }
  return out;
}

float error_against(const Window& feature, const LowResFrame& frame, int u, int v) {
  const float* y = frame.luma.data();
  const auto w = static_cast<int>(frame.width);
  const float centre = y[v * w + u];
  float e = 0.0F;
  int k = 0;
  for (int dv = -kHalfWindow; dv <= kHalfWindow; ++dv) {
    const float* row = y + (v + dv) * w + u - kHalfWindow;
    for (int du = 0; du < 5; ++du) {
      const float d = feature.values[static_cast<std::size_t>(k++)] - (row[du] - centre);
      e += d * d;
    }
  }
  return e;
}

bool window_fits(const LowResFrame& frame, int u, int v) {
  return u >= kHalfWindow && v >= kHalfWindow && u + kHalfWindow < static_cast<int>(frame.width) &&
         v + kHalfWindow < static_cast<int>(frame.height);
}

// Vertex offset of the parabola through (−1, a), (0, b), (1, c), in [−0.5, 0.5].
float parabola_offset(float a, float b, float c) {
  const float curvature = a - 2.0F * b + c;
  if (!(curvature > 0.0F)) {
    return 0.0F;
  }
  const float offset = 0.5F * (a - c) / curvature;
  return offset < -0.5F ? -0.5F : (offset > 0.5F ? 0.5F : offset);
}

}  // namespace

float match_error(const LowResFrame& first, std::uint32_t u1, std::uint32_t v1,
                  const LowResFrame& second, std::uint32_t u2, std::uint32_t v2) {
  const Window feature = window_of(first, static_cast<int>(u1), static_cast<int>(v1));
  return error_against(feature, second, static_cast<int>(u2), static_cast<int>(v2));
}

Track track_feature(const LowResFrame& first, std::uint32_t u1, std::uint32_t v1,
                    const LowResFrame& second, const EpipolarSegment& segment,
                    const TrackParams& params) {
  Track track;
  const auto fu = static_cast<int>(u1);
  const auto fv = static_cast<int>(v1);
  if (!window_fits(first, fu, fv)) {
    return track;
  }
  const Window feature = window_of(first, fu, fv);
  // Rows of the segment, in search order from far to near.
  const float dv_total = segment.near_v_px - segment.far_v_px;
  const float slope =
      std::fabs(dv_total) > 1e-3F ? (segment.near_u_px - segment.far_u_px) / dv_total : 0.0F;
  const auto row_far = static_cast<int>(std::lround(segment.far_v_px));
  const auto row_near = static_cast<int>(std::lround(segment.near_v_px));
  const int step = row_near >= row_far ? 1 : -1;
  const int rows = (row_near - row_far) * step + 1;
  if (rows > kMaxRows) {
    return track;
  }
  const auto half_band = static_cast<int>(std::lround(params.band_half_width_px));
  std::array<float, kMaxRows> row_best{};
  std::array<int, kMaxRows> row_best_u{};
  constexpr float kNone = std::numeric_limits<float>::max();
  int best_row = -1;
  for (int k = 0; k < rows; ++k) {
    const int v = row_far + k * step;
    const float line_u = segment.far_u_px + slope * (static_cast<float>(v) - segment.far_v_px);
    const auto centre_u = static_cast<int>(std::lround(line_u));
    float best = kNone;
    int best_u = centre_u;
    for (int u = centre_u - half_band; u <= centre_u + half_band; ++u) {
      if (!window_fits(second, u, v)) {
        continue;
      }
      const float e = error_against(feature, second, u, v);
      if (e < best) {
        best = e;
        best_u = u;
      }
    }
    row_best[static_cast<std::size_t>(k)] = best;
    row_best_u[static_cast<std::size_t>(k)] = best_u;
    if (best < kNone && (best_row < 0 || best < row_best[static_cast<std::size_t>(best_row)])) {
      best_row = k;
    }
  }
  if (best_row < 0) {
    return track;
  }
  const float best_e = row_best[static_cast<std::size_t>(best_row)];
  float runner_up = kNone;
  for (int k = 0; k < rows; ++k) {
    if (k < best_row - 2 || k > best_row + 2) {
      runner_up = std::fmin(runner_up, row_best[static_cast<std::size_t>(k)]);
    }
  }
  track.match_error = best_e;
  track.runner_up_error = runner_up;
  if (!(best_e < params.match_error_thresh)) {
    return track;
  }
  if (params.distinctiveness < 1.0F && runner_up < kNone &&
      !(best_e < params.distinctiveness * runner_up)) {
    return track;
  }
  const int bu = row_best_u[static_cast<std::size_t>(best_row)];
  const int bv = row_far + best_row * step;
  float dv = 0.0F;
  if (window_fits(second, bu, bv - 1) && window_fits(second, bu, bv + 1)) {
    dv = parabola_offset(error_against(feature, second, bu, bv - 1), best_e,
                         error_against(feature, second, bu, bv + 1));
  }
  // The column follows the epipolar line at the refined row (a separate horizontal
  // parabola would be biased by oblique texture at the integer row).
  const float v_sub = static_cast<float>(bv) + dv;
  track.found = true;
  track.u_px = segment.far_u_px + slope * (v_sub - segment.far_v_px);
  track.v_px = v_sub;
  return track;
}

}  // namespace boticelli::image
