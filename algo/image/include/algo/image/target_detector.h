// Target detection (§3.4.2): the upper vertex of a green equilateral triangle on white paper.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>

#include "algo/image/low_res_frame.h"

namespace boticelli::image {

// Every colour threshold is relative, so the detector works under any light level: a
// pixel's chroma is compared with its own brightness above black (chromaticity does not
// change with the illumination), and the paper's brightness with the triangle's.
struct TargetParams {
  float black_luma = 16.0F;  // luma of black (BT.601 limited range) [grey levels]
  // Green: −Cr ≥ ratio·(Y − black) and −Cb ≥ ratio·(Y − black), with −Cr above a floor
  // [grey levels] that quantisation and noise do not reach. A blob starts at a pixel that
  // passes the seed thresholds (the sim's target green has −Cr/(Y − black) ≈ 0.63, its
  // foliage ≈ 0.22, camouflage ≈ 0.02) and grows over 4-neighbours that pass the grow ones
  // (pixels at least about a third covered by the triangle).
  float seed_min_cr_ratio = 0.35F;
  float seed_min_cb_ratio = 0.1F;
  float seed_min_chroma = 5.0F;
  float grow_min_cr_ratio = 0.12F;
  float grow_min_cb_ratio = 0.0F;
  float grow_min_chroma = 3.0F;
  // White paper around the triangle: at least this many times as bright above black as the
  // triangle's interior (the sim's paper ≈ 2.6x, the test renderer's ≈ 2.2x) ...
  float white_min_luma_ratio = 1.5F;
  // ... and grey: |Cb|, |Cr| at most this share of (Y − black), or of 20 grey levels if more.
  float white_max_chroma_ratio = 0.1F;
  std::size_t min_area_px = 6;      // smallest triangle considered [low-resolution px]
  float min_white_surround = 0.6F;  // share of white pixels around the triangle
  float min_confidence = 0.5F;
};

struct TargetDetection {
  bool found = false;
  float u_px = 0.0F;  // the corner (upper vertex), low-resolution pixels, sub-pixel
  float v_px = 0.0F;
  float confidence = 0.0F;  // in [0, 1]
  std::size_t area_px = 0;  // green area of the triangle [low-resolution px]
  // The triangle's bounding box, inclusive [low-resolution px].
  std::uint32_t box_u_min = 0;
  std::uint32_t box_u_max = 0;
  std::uint32_t box_v_min = 0;
  std::uint32_t box_v_max = 0;
};

// Confidence in [0, 1] of a candidate from its measures: the share of white paper around it
// (a factor), and how straight its two edge lines are (the larger RMS residual, 0 px best, 1.5
// px or more worst), how near half its bounding box it fills (0.5 best, 0.2 or 0.8 worst) and
// how symmetric it is (skew |b_l + b_r| / (b_r − b_l) of the edges' slopes, 0 best, 0.6
// worst): white_share · (0.4 + 0.6 · straight · filled · (0.5 + 0.5 · symmetric)).
[[nodiscard]] float target_confidence(float white_share, float residual_px, float fill, float skew);

// Finds green blobs (connected components, hysteresis on chromaticity), keeps those shaped
// like an upward triangle seen from up to about 60° off its normal (left and right edges
// straight and converging to a vertex at the top, the base at the bottom, about half the
// bounding box filled) and surrounded by paper brighter than the green and grey; the
// vertex is where the two edge lines fit to the blob's rows meet, each row's extent
// measured to a fraction of a pixel from how far its pixels' luma lies between the paper's
// (a plane fitted to the paper around the triangle: vignetting and uneven light darken it
// across the image) and the triangle's (the same share of the paper's everywhere).
// Returns the most confident candidate. Allocation-free.
class TargetDetector {
 public:
  explicit TargetDetector(const TargetParams& params = {}) : params_(params) {}
  [[nodiscard]] const TargetParams& params() const { return params_; }
  TargetDetection detect(const LowResFrame& frame);

 private:
  // Passes the green thresholds for a blob's seed (strict) or for growing it (loose).
  [[nodiscard]] bool is_green(const LowResFrame& frame, std::size_t i, bool seed) const;
  TargetDetection examine(const LowResFrame& frame, std::uint32_t label, std::size_t area,
                          std::uint32_t u_min, std::uint32_t u_max, std::uint32_t v_min,
                          std::uint32_t v_max);

  TargetParams params_;
  std::array<std::uint32_t, LowResFrame::kMaxPixels> labels_{};
  std::array<std::uint32_t, LowResFrame::kMaxPixels> queue_{};
  // Sub-pixel left and right extents of the candidate's inner rows [low-resolution px].
  std::array<double, LowResFrame::kMaxHeight> row_left_{};
  std::array<double, LowResFrame::kMaxHeight> row_right_{};
};

}  // namespace boticelli::image
