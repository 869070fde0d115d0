// Tracking along the epipolar band: Eq 3.1 match error, parabola and 1-D Lucas-Kanade refinement.
#include "algo/image/epipolar_tracker.h"

#include <array>
#include <cmath>
#include <cstddef>
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
    const float* row = y + std::ptrdiff_t{v + dv} * w + u - kHalfWindow;
    for (int du = 0; du < 5; ++du) {
      out.values[static_cast<std::size_t>(k++)] = row[du] - centre;
    }
  }
  return out;
}

// Eq 3.1 against the window at (u, v); stops early, returning a partial sum above `bound`,
// once the sum exceeds it (the search only needs exact values below the bound).
float error_against(const Window& feature, const LowResFrame& frame, int u, int v,
                    float bound = std::numeric_limits<float>::max()) {
  const float* y = frame.luma.data();
  const auto w = static_cast<int>(frame.width);
  const float centre = y[v * w + u];
  float e = 0.0F;
  int k = 0;
  for (int dv = -kHalfWindow; dv <= kHalfWindow; ++dv) {
    const float* row = y + std::ptrdiff_t{v + dv} * w + u - kHalfWindow;
    for (int du = 0; du < 5; ++du) {
      const float d = feature.values[static_cast<std::size_t>(k++)] - (row[du] - centre);
      e += d * d;
    }
    if (e > bound) {
      return e;
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

float bilinear(const LowResFrame& frame, float x, float y) {
  const auto x0 = static_cast<int>(x);
  const auto y0 = static_cast<int>(y);
  const float fx = x - static_cast<float>(x0);
  const float fy = y - static_cast<float>(y0);
  const auto w = static_cast<int>(frame.width);
  const float* p = frame.luma.data() + std::ptrdiff_t{y0} * w + x0;
  const float top = p[0] + fx * (p[1] - p[0]);
  const float bottom = p[w] + fx * (p[w + 1] - p[w]);
  return top + fy * (bottom - top);
}

// Gauss-Newton refinement of the match along the epipolar line (a Lucas-Kanade step in
// one dimension, with a brightness offset): minimises Σ (I2(x + s·d) − T(x) − b)² over the
// 5x5 window, d = (K, 1) the line direction per row. The template gradient stands in for
// the image's (inverse compositional), so the 2x2 normal matrix is built once. Returns
// false (v unchanged) if the window leaves the image or the step does not settle.
bool refine_along_line(const LowResFrame& first, int fu, int fv, const LowResFrame& second,
                       const EpipolarSegment& segment, float slope, float& v) {
  const auto w1 = static_cast<int>(first.width);
  const auto h1 = static_cast<int>(first.height);
  if (fu < 3 || fv < 3 || fu + 3 >= w1 || fv + 3 >= h1) {
    return false;
  }
  std::array<float, 25> templ{};
  std::array<float, 25> grad{};
  const float* y = first.luma.data();
  float sgg = 0.0F;
  float sg = 0.0F;
  float st = 0.0F;
  int k = 0;
  for (int dv = -kHalfWindow; dv <= kHalfWindow; ++dv) {
    for (int du = -kHalfWindow; du <= kHalfWindow; ++du) {
      const int i = (fv + dv) * w1 + fu + du;
      const float g = slope * 0.5F * (y[i + 1] - y[i - 1]) + 0.5F * (y[i + w1] - y[i - w1]);
      templ[static_cast<std::size_t>(k)] = y[i];
      grad[static_cast<std::size_t>(k)] = g;
      sgg += g * g;
      sg += g;
      st += y[i];
      ++k;
    }
  }
  const float det = 25.0F * sgg - sg * sg;
  if (!(det > 1e-3F * 25.0F * sgg) || !(sgg > 1.0F)) {
    return false;
  }
  const float x_limit =
      static_cast<float>(second.width) - 1.0F - static_cast<float>(kHalfWindow) - 1e-3F;
  const float y_limit =
      static_cast<float>(second.height) - 1.0F - static_cast<float>(kHalfWindow) - 1e-3F;
  const float start = v;
  float current = v;
  float offset = 0.0F;
  for (int iteration = 0; iteration < 4; ++iteration) {
    const float cu = segment.far_u_px + slope * (current - segment.far_v_px);
    if (cu < static_cast<float>(kHalfWindow) || current < static_cast<float>(kHalfWindow) ||
        cu > x_limit || current > y_limit) {
      return false;
    }
    float seg = 0.0F;
    float se = 0.0F;
    float si = 0.0F;
    k = 0;
    for (int dv = -kHalfWindow; dv <= kHalfWindow; ++dv) {
      for (int du = -kHalfWindow; du <= kHalfWindow; ++du) {
        const float sample =
            bilinear(second, cu + static_cast<float>(du), current + static_cast<float>(dv));
        if (iteration == 0) {
          si += sample;
        }
        const float e = sample - templ[static_cast<std::size_t>(k)] - offset;
        seg += grad[static_cast<std::size_t>(k)] * e;
        se += e;
        ++k;
      }
    }
    if (iteration == 0) {
      // Start from the mean brightness difference and redo the sums with it.
      offset = (si - st) / 25.0F;
      se -= 25.0F * offset;
      seg -= offset * sg;
    }
    // [Σg² Σg; Σg 25]·[Δs; Δb] = −[Σg·e; Σe]
    const float step = -(25.0F * seg - sg * se) / det;
    const float offset_step = -(sgg * se - sg * seg) / det;
    current += step;
    offset += offset_step;
    if (std::fabs(current - start) > 1.0F) {
      return false;
    }
    if (std::fabs(step) < 0.005F) {
      break;
    }
  }
  v = current;
  return true;
}

}  // namespace

float match_error(const LowResFrame& first, std::uint32_t u1, std::uint32_t v1,
                  const LowResFrame& second, std::uint32_t u2, std::uint32_t v2) {
  const Window feature = window_of(first, static_cast<int>(u1), static_cast<int>(v1));
  return error_against(feature, second, static_cast<int>(u2), static_cast<int>(v2));
}

namespace {

// track_feature with the centred window only.
Track track_centred(const LowResFrame& first, std::uint32_t u1, std::uint32_t v1,
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
  // Values above this bound cannot be the best nor a runner-up that rejects it.
  const float runner_up_scale = params.distinctiveness > 0.0F && params.distinctiveness < 1.0F
                                    ? 1.0F / params.distinctiveness
                                    : 1.0F;
  float bound = kNone;
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
      const float e = error_against(feature, second, u, v, std::fmin(bound, best));
      if (e < best) {
        best = e;
        best_u = u;
      }
    }
    row_best[static_cast<std::size_t>(k)] = best;
    row_best_u[static_cast<std::size_t>(k)] = best_u;
    if (best < kNone && (best_row < 0 || best < row_best[static_cast<std::size_t>(best_row)])) {
      best_row = k;
      bound = best * runner_up_scale;
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
  // A best match against the image border is where the search was cut off, not a minimum:
  // the true match has most likely left the frame.
  if (!window_fits(second, bu, bv - 1) || !window_fits(second, bu, bv + 1)) {
    return track;
  }
  const float dv = parabola_offset(error_against(feature, second, bu, bv - 1), best_e,
                                   error_against(feature, second, bu, bv + 1));
  // The column follows the epipolar line at the refined row (a separate horizontal
  // parabola would be biased by oblique texture at the integer row).
  float v_sub = static_cast<float>(bv) + dv;
  if (params.refine_along_line) {
    (void)refine_along_line(first, fu, fv, second, segment, slope, v_sub);
  }
  track.found = true;
  track.u_px = segment.far_u_px + slope * (v_sub - segment.far_v_px);
  track.v_px = v_sub;
  return track;
}

}  // namespace

Track track_feature(const LowResFrame& first, std::uint32_t u1, std::uint32_t v1,
                    const LowResFrame& second, const EpipolarSegment& segment,
                    const TrackParams& params) {
  const Track centred = track_centred(first, u1, v1, second, segment, params);
  // Only a match that was distinctive but too poor: one that was not distinctive is
  // repeated texture, which another window does not make unique.
  const bool distinctive = params.distinctiveness >= 1.0F ||
                           !(centred.runner_up_error < std::numeric_limits<float>::max()) ||
                           centred.match_error < params.distinctiveness * centred.runner_up_error;
  if (centred.found || params.window_shift_px == 0 || centred.match_error <= 0.0F || !distinctive) {
    return centred;
  }
  // Shifted windows: the window of pixel (u1, v1 + s) moved along the same line, s = −shift
  // then +shift (the motion is nearly vertical, so the shifted pixel's line is the same
  // line shifted by s rows). The match of (u1, v1) is that window's match minus s.
  Track best = centred;
  const auto shift = static_cast<float>(params.window_shift_px);
  for (const float s : {-shift, shift}) {
    const float v_shifted = static_cast<float>(v1) + s;
    if (v_shifted < 0.0F) {
      continue;
    }
    EpipolarSegment moved = segment;
    moved.far_v_px += s;
    moved.near_v_px += s;
    Track t =
        track_centred(first, u1, static_cast<std::uint32_t>(v_shifted), second, moved, params);
    if (t.found && (!best.found || t.match_error < best.match_error)) {
      t.v_px -= s;
      const float dv_total = segment.near_v_px - segment.far_v_px;
      const float slope =
          std::fabs(dv_total) > 1e-3F ? (segment.near_u_px - segment.far_u_px) / dv_total : 0.0F;
      t.u_px = segment.far_u_px + slope * (t.v_px - segment.far_v_px);
      best = t;
    }
  }
  return best;
}

}  // namespace boticelli::image
