// Tracking along the epipolar band: Eq 3.1 match error, parabola and 1-D Lucas-Kanade refinement.
#include "algo/image/epipolar_tracker.h"

#include <algorithm>
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

// The feature's window a quarter row up, at v − 1/4: rows 1/4·Y[v + dv − 1] + 3/4·Y[v + dv],
// minus its centre likewise. Half-row samples of the search put the second frame's window a
// quarter row down and this one a quarter row up: both are interpolated alike, so a true
// match between two rows is not penalised by the interpolation (linear interpolation at a
// quarter is off by 3/32 of the second difference on both sides, which cancels; at the
// midpoint of the second frame alone it would be off by 1/8 of it), and a texture's repeat
// on a whole row does not beat it.
Window window_quarter_up(const LowResFrame& frame, int u, int v) {
  Window out;
  const float* y = frame.luma.data();
  const auto w = static_cast<int>(frame.width);
  const auto at = [&](int uu, int vv) {
    const float* p = y + std::ptrdiff_t{vv} * w + uu;
    return 0.25F * p[-w] + 0.75F * p[0];
  };
  const float centre = at(u, v);
  int k = 0;
  for (int dv = -kHalfWindow; dv <= kHalfWindow; ++dv) {
    for (int du = -kHalfWindow; du <= kHalfWindow; ++du) {
      out.values[static_cast<std::size_t>(k++)] = at(u + du, v + dv) - centre;
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

// Eq 3.1 of `feature_quarter_up` (window_quarter_up) against the window a quarter row below
// row v (rows 3/4·Y[v + dv] + 1/4·Y[v + dv + 1]): the match half a row below v, with the
// same early stop as error_against.
float error_against_half(const Window& feature_quarter_up, const LowResFrame& frame, int u, int v,
                         float bound = std::numeric_limits<float>::max()) {
  const Window& feature = feature_quarter_up;
  const float* y = frame.luma.data();
  const auto w = static_cast<int>(frame.width);
  const float centre = 0.75F * y[v * w + u] + 0.25F * y[(v + 1) * w + u];
  float e = 0.0F;
  int k = 0;
  for (int dv = -kHalfWindow; dv <= kHalfWindow; ++dv) {
    const float* row = y + std::ptrdiff_t{v + dv} * w + u - kHalfWindow;
    const float* below = row + w;
    for (int du = 0; du < 5; ++du) {
      const float d = feature.values[static_cast<std::size_t>(k++)] -
                      (0.75F * row[du] + 0.25F * below[du] - centre);
      e += d * d;
    }
    if (e > bound) {
      return e;
    }
  }
  return e;
}

// The feature's windows: as it is, and a quarter row up for the half-row samples.
struct FeatureWindows {
  Window whole;
  Window quarter_up;
};

// Eq 3.1 against the windows at columns u0 .. u0 + count − 1 (count ≤ 3) of row v, or half
// a row below it (error_against_half): one pass over the window's rows serves the three
// columns. Stops once every sum exceeds `bound` (the sums are then partial, each above it).
void errors_of_columns(const FeatureWindows& windows, const LowResFrame& frame, int u0, int count,
                       int v, bool half_row, float bound, std::array<float, 3>& out) {
  const Window& feature = half_row ? windows.quarter_up : windows.whole;
  const float* y = frame.luma.data();
  const auto w = static_cast<int>(frame.width);
  std::array<float, 3> centre{};
  for (int k = 0; k < count; ++k) {
    const float* c = y + std::ptrdiff_t{v} * w + u0 + k;
    centre[static_cast<std::size_t>(k)] = half_row ? 0.75F * c[0] + 0.25F * c[w] : c[0];
  }
  out = {0.0F, 0.0F, 0.0F};
  std::array<float, 7> row{};
  const int span = count + 2 * kHalfWindow;
  for (int dv = -kHalfWindow; dv <= kHalfWindow; ++dv) {
    const float* r = y + std::ptrdiff_t{v + dv} * w + u0 - kHalfWindow;
    for (int i = 0; i < span; ++i) {
      row[static_cast<std::size_t>(i)] = half_row ? 0.75F * r[i] + 0.25F * r[i + w] : r[i];
    }
    const float* f = feature.values.data() + (dv + kHalfWindow) * 5;
    bool all_above = true;
    for (int k = 0; k < count; ++k) {
      const float c = centre[static_cast<std::size_t>(k)];
      float e = out[static_cast<std::size_t>(k)];
      for (int du = 0; du < 5; ++du) {
        const float d = f[du] - (row[static_cast<std::size_t>(k + du)] - c);
        e += d * d;
      }
      out[static_cast<std::size_t>(k)] = e;
      all_above = all_above && e > bound;
    }
    if (all_above) {
      return;
    }
  }
}

// The nearest integer, halves up (lround's inline equivalent for the frame's coordinates).
int nearest(float x) {
  const float shifted = x + 0.5F;
  const auto i = static_cast<int>(shifted);
  return static_cast<float>(i) > shifted ? i - 1 : i;
}

// Positions in half rows: h = 2·row (whole rows) or 2·row + 1 (half a row below `row`).
int floor_half(int h) {
  return h >= 0 ? h / 2 : -((1 - h) / 2);
}

bool window_fits_half(const LowResFrame& frame, int u, int h) {
  const int v = floor_half(h);
  return window_fits(frame, u, v) && (h % 2 == 0 || window_fits(frame, u, v + 1));
}

float error_at_half(const FeatureWindows& windows, const LowResFrame& frame, int u, int h,
                    float bound = std::numeric_limits<float>::max()) {
  const int v = floor_half(h);
  return h % 2 == 0 ? error_against(windows.whole, frame, u, v, bound)
                    : error_against_half(windows.quarter_up, frame, u, v, bound);
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

// Σ (I2 − T − b)² / Σ (T − T̄)² over the 5x5 window: T the first frame's window at (fu, fv),
// I2 the second frame bilinearly sampled around the line's point at row v, b the mean
// difference I2 − T. −1 if a window leaves its frame or the feature's window is flat.
float normalized_error(const LowResFrame& first, int fu, int fv, const LowResFrame& second,
                       const EpipolarSegment& segment, float slope, float v) {
  const float cu = segment.far_u_px + slope * (v - segment.far_v_px);
  const float x_limit =
      static_cast<float>(second.width) - 1.0F - static_cast<float>(kHalfWindow) - 1e-3F;
  const float y_limit =
      static_cast<float>(second.height) - 1.0F - static_cast<float>(kHalfWindow) - 1e-3F;
  if (!window_fits(first, fu, fv) || cu < static_cast<float>(kHalfWindow) ||
      v < static_cast<float>(kHalfWindow) || cu > x_limit || v > y_limit) {
    return -1.0F;
  }
  std::array<float, 25> diff{};
  float st = 0.0F;
  float stt = 0.0F;
  float sd = 0.0F;
  int k = 0;
  for (int dv = -kHalfWindow; dv <= kHalfWindow; ++dv) {
    for (int du = -kHalfWindow; du <= kHalfWindow; ++du) {
      const float t =
          first.luma[static_cast<std::size_t>((fv + dv) * static_cast<int>(first.width) + fu + du)];
      const float d = bilinear(second, cu + static_cast<float>(du), v + static_cast<float>(dv)) - t;
      diff[static_cast<std::size_t>(k++)] = d;
      st += t;
      stt += t * t;
      sd += d;
    }
  }
  const float energy = stt - st * st / 25.0F;
  if (!(energy > 1e-3F)) {
    return -1.0F;
  }
  const float b = sd / 25.0F;
  float residual = 0.0F;
  for (const float d : diff) {
    residual += (d - b) * (d - b);
  }
  return residual / energy;
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
  // The quarter-row window needs the row above the whole window's.
  if (params.half_pixel_search && !window_fits(first, fu, fv - 1)) {
    return track;
  }
  FeatureWindows feature;
  feature.whole = window_of(first, fu, fv);
  if (params.half_pixel_search) {
    feature.quarter_up = window_quarter_up(first, fu, fv);
  }
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
  // Samples along the segment in search order, every `spacing` half rows (2: whole rows,
  // 1: half rows too); sample j is at half-row position h_far + j·spacing·step.
  const int spacing = params.half_pixel_search ? 1 : 2;
  const int samples = (rows - 1) * (2 / spacing) + 1;
  const int h_far = 2 * row_far;
  const int h_step = spacing * step;
  // Not zeroed (8 KB a feature): every sample read below is written first.
  std::array<float, 2 * kMaxRows> sample_best;  // NOLINT(cppcoreguidelines-pro-type-member-init)
  std::array<int, 2 * kMaxRows> sample_best_u;  // NOLINT(cppcoreguidelines-pro-type-member-init)
  constexpr float kNone = std::numeric_limits<float>::max();
  int best = -1;
  // Values above this bound cannot be the best nor a runner-up that rejects it.
  const float runner_up_scale = params.distinctiveness > 0.0F && params.distinctiveness < 1.0F
                                    ? 1.0F / params.distinctiveness
                                    : 1.0F;
  float bound = kNone;
  // One sample: the best E over the band's columns at sample j (kNone where no window fits).
  const auto sample_at = [&](int j) {
    const int h = h_far + j * h_step;
    const float line_u =
        segment.far_u_px + slope * (0.5F * static_cast<float>(h) - segment.far_v_px);
    const int centre_u = nearest(line_u);
    const int v = floor_half(h);
    const bool half_row = h % 2 != 0;
    // The band's columns whose window fits (all rows of it: v − 2 .. v + 2, + 1 if half).
    const int u_lo = std::max(centre_u - half_band, kHalfWindow);
    const int u_hi =
        std::min(centre_u + half_band, static_cast<int>(second.width) - 1 - kHalfWindow);
    const bool rows_fit =
        v >= kHalfWindow && v + kHalfWindow + (half_row ? 1 : 0) < static_cast<int>(second.height);
    float sample = kNone;
    int sample_u = centre_u;
    std::array<float, 3> errors{};
    for (int u = u_lo; rows_fit && u <= u_hi; u += 3) {
      const int count = std::min(3, u_hi - u + 1);
      errors_of_columns(feature, second, u, count, v, half_row, bound < sample ? bound : sample,
                        errors);
      for (int k = 0; k < count; ++k) {
        if (errors[static_cast<std::size_t>(k)] < sample) {
          sample = errors[static_cast<std::size_t>(k)];
          sample_u = u + k;
        }
      }
    }
    sample_best[static_cast<std::size_t>(j)] = sample;
    sample_best_u[static_cast<std::size_t>(j)] = sample_u;
    if (sample < kNone && (best < 0 || sample < sample_best[static_cast<std::size_t>(best)])) {
      best = j;
      bound = sample * runner_up_scale;
    }
  };
  // Whole rows first; then the half rows beside each whole row that is a local minimum: a
  // match between two rows makes one of them a local minimum, and elsewhere E between two
  // rows does not fall below both.
  const int whole = 2 / spacing;
  for (int j = 0; j < samples; j += whole) {
    sample_at(j);
  }
  if (whole > 1) {
    for (int j = 1; j < samples; j += 2) {
      sample_best[static_cast<std::size_t>(j)] = kNone;
    }
    for (int j = 0; j < samples; j += 2) {
      const float e = sample_best[static_cast<std::size_t>(j)];
      const bool left_higher = j == 0 || !(sample_best[static_cast<std::size_t>(j - 2)] < e);
      const bool right_higher =
          j + 2 >= samples || !(sample_best[static_cast<std::size_t>(j + 2)] < e);
      if (!(e < kNone) || !left_higher || !right_higher) {
        continue;
      }
      if (j > 0 && !(sample_best[static_cast<std::size_t>(j - 1)] < kNone)) {
        sample_at(j - 1);
      }
      if (j + 1 < samples) {
        sample_at(j + 1);
      }
    }
  }
  if (best < 0) {
    return track;
  }
  const float best_e = sample_best[static_cast<std::size_t>(best)];
  // The runner-up is more than 2 rows (4 half rows) away.
  const int exclude = 4 / spacing;
  float runner_up = kNone;
  for (int j = 0; j < samples; ++j) {
    if (j < best - exclude || j > best + exclude) {
      const float e = sample_best[static_cast<std::size_t>(j)];
      runner_up = e < runner_up ? e : runner_up;
    }
  }
  track.match_error = best_e;
  track.runner_up_error = runner_up;
  const bool below_thresh = best_e < params.match_error_thresh;
  const bool normalized_test = params.normalized_error_thresh > 0.0F;
  if (!below_thresh && !normalized_test) {
    return track;
  }
  if (params.distinctiveness < 1.0F && runner_up < kNone &&
      !(best_e < params.distinctiveness * runner_up)) {
    return track;
  }
  const int bu = sample_best_u[static_cast<std::size_t>(best)];
  const int bh = h_far + best * h_step;
  // A best match against the image border is where the search was cut off, not a minimum:
  // the true match has most likely left the frame.
  if (!window_fits_half(second, bu, bh - 2) || !window_fits_half(second, bu, bh + 2)) {
    return track;
  }
  const float dv = parabola_offset(error_at_half(feature, second, bu, bh - spacing), best_e,
                                   error_at_half(feature, second, bu, bh + spacing)) *
                   0.5F * static_cast<float>(spacing);
  // The column follows the epipolar line at the refined row (a separate horizontal
  // parabola would be biased by oblique texture at the integer row).
  float v_sub = 0.5F * static_cast<float>(bh) + dv;
  if (params.refine_along_line) {
    (void)refine_along_line(first, fu, fv, second, segment, slope, v_sub);
  }
  if (normalized_test) {
    track.normalized_error = normalized_error(first, fu, fv, second, segment, slope, v_sub);
  }
  // E_thresh admits what noise leaves on weak texture; the normalised error, what is small
  // beside strong texture, wherever the match falls between pixels.
  if (!below_thresh && !(track.normalized_error >= 0.0F &&
                         track.normalized_error < params.normalized_error_thresh)) {
    return track;
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
