// Epipolar tracking (§3.4.1, App. A): Eq 3.1 match error along a 3 px band, sub-pixel refined.
#pragma once

#include <cstdint>

#include "algo/image/low_res_frame.h"

namespace boticelli::image {

// Eq 3.1: E = Σ (V[n] − V'[n])² over the 5x5 windows centred on (u1, v1) in `first` and
// (u2, v2) in `second`, where V[n] is a window pixel minus the window's centre pixel
// [grey levels²]. Both windows must lie inside their frames.
float match_error(const LowResFrame& first, std::uint32_t u1, std::uint32_t v1,
                  const LowResFrame& second, std::uint32_t u2, std::uint32_t v2);

// The part of the epipolar line to search, in second-frame pixels: from where the feature
// would be seen if it were infinitely far to where it would be at the nearest range.
struct EpipolarSegment {
  float far_u_px = 0.0F;
  float far_v_px = 0.0F;
  float near_u_px = 0.0F;
  float near_v_px = 0.0F;
};

struct TrackParams {
  float band_half_width_px = 1.0F;  // the band is 2·1 + 1 = 3 px wide (§3.4.1)
  // E_thresh [grey levels²]: a best match with E at or above it is dropped unless the
  // normalised test below keeps it. E is taken at the best sampled position of the search
  // (whole rows, and half rows with half_pixel_search). Weak texture's E is mostly noise,
  // which this absolute limit is sized for.
  float match_error_thresh = 1500.0F;
  // The search samples E at half rows as well as at whole rows (at the half rows beside each
  // whole row that is a local minimum of E; the second frame's two rows averaged). With
  // whole rows only, a true match whose disparity falls near a half pixel is sampled half a
  // pixel off at best, where a strong feature's E is many times its E at the match: it fails
  // E_thresh and loses to a repeat of the texture that falls on a whole row. With half rows
  // every match is sampled within a quarter pixel.
  bool half_pixel_search = true;
  // A match at or above E_thresh is kept if its normalised error after sub-pixel refinement,
  // Σ (I2 − T − b)² / Σ (T − T̄)² over the 5x5 window (T the feature's window, I2 the second
  // frame bilinearly sampled at the refined match, b the mean brightness difference), is
  // below this: strong texture's error relative to its own contrast, whichever fraction of
  // a pixel the disparity has. 0 disables it (E_thresh alone, the thesis's test).
  float normalized_error_thresh = 0.3F;
  // A match must beat the best one elsewhere on the line (more than 2 rows away) by this
  // factor; 1 disables it. Rejects repeated texture, the main source of outliers (§3.6).
  float distinctiveness = 0.8F;
  // After the parabola, a few Gauss-Newton steps along the line on bilinearly sampled
  // luma (a one-dimensional Lucas-Kanade): beats the parabola's bias towards whole pixels.
  bool refine_along_line = true;
  // Multiple windows (Fusiello, Roberto & Trucco 1997): when the centred 5x5 window finds
  // no match, the windows shifted this many rows up and down are tried, and the better match
  // kept. At an occlusion edge (the rim of an overhang against the floor behind it) the
  // centred window holds both surfaces, which move differently between the frames, so it
  // matches neither; a shifted window lies on one side. 0: the thesis's single window.
  std::uint32_t window_shift_px = 0;
};

struct Track {
  bool found = false;
  float u_px = 0.0F;  // match in the second frame, sub-pixel
  float v_px = 0.0F;
  float match_error = 0.0F;      // E at the best sampled position (Eq 3.1)
  float runner_up_error = 0.0F;  // best E elsewhere on the line
  // The refined match's normalised error (see TrackParams::normalized_error_thresh); −1 if
  // it was not computed (the test is off, or the window left the frame).
  float normalized_error = -1.0F;
};

// Searches along the segment, row by row (the motion is close to vertical: |K| ≤ 0.03,
// App. A) and with half_pixel_search every half row, in a band around the line
// i' = K·j' + B, keeps the best match below E_thresh that is distinctive, and refines its
// row to sub-pixel by a parabola through E at the neighbouring samples, then along the line
// (refine_along_line); the column is the line's at that row.
Track track_feature(const LowResFrame& first, std::uint32_t u1, std::uint32_t v1,
                    const LowResFrame& second, const EpipolarSegment& segment,
                    const TrackParams& params);

}  // namespace boticelli::image
