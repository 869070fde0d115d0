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
  float band_half_width_px = 1.0F;     // the band is 2·1 + 1 = 3 px wide (§3.4.1)
  float match_error_thresh = 1500.0F;  // E_thresh: worse best matches are dropped [grey levels²]
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
  float match_error = 0.0F;      // E at the best integer position (Eq 3.1)
  float runner_up_error = 0.0F;  // best E elsewhere on the line
};

// Searches along the segment, row by row (the motion is close to vertical: |K| ≤ 0.03,
// App. A), in a band around the line i' = K·j' + B, keeps the best match below E_thresh and
// refines its row to sub-pixel by a parabola through E at the neighbouring rows; the
// column is the line's at that row.
Track track_feature(const LowResFrame& first, std::uint32_t u1, std::uint32_t v1,
                    const LowResFrame& second, const EpipolarSegment& segment,
                    const TrackParams& params);

}  // namespace boticelli::image
