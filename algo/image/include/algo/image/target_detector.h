// Target detection (§3.4.2): the upper vertex of a green equilateral triangle on white paper.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>

#include "algo/image/low_res_frame.h"

namespace boticelli::image {

struct TargetParams {
  int green_max_cr = -24;           // green: Cr (V − 128) at most this ...
  int green_max_cb = -8;            // ... and Cb (U − 128) at most this
  float green_min_luma = 40.0F;     // and not black [grey levels]
  float white_min_luma = 140.0F;    // white paper: bright ...
  int white_max_chroma = 20;        // ... and grey: |Cb|, |Cr| at most this
  std::size_t min_area_px = 10;     // smallest triangle considered [low-resolution px]
  float min_white_surround = 0.6F;  // share of white pixels around the triangle
  float min_confidence = 0.5F;
};

struct TargetDetection {
  bool found = false;
  float u_px = 0.0F;  // the corner (upper vertex), low-resolution pixels, sub-pixel
  float v_px = 0.0F;
  float confidence = 0.0F;  // in [0, 1]
  std::size_t area_px = 0;  // green area of the triangle [low-resolution px]
};

// Finds green blobs (connected components), keeps those shaped like an upward triangle
// (left and right edges straight and converging to a vertex at the top, about half the
// bounding box filled) and surrounded by white; the vertex is where the two edge lines fit
// to the blob's rows meet. Returns the most confident candidate.
class TargetDetector {
 public:
  explicit TargetDetector(const TargetParams& params = {}) : params_(params) {}
  [[nodiscard]] const TargetParams& params() const { return params_; }
  TargetDetection detect(const LowResFrame& frame);

 private:
  [[nodiscard]] bool is_green(const LowResFrame& frame, std::size_t i) const;
  [[nodiscard]] bool is_white(const LowResFrame& frame, std::size_t i) const;
  TargetDetection examine(const LowResFrame& frame, std::uint32_t label, std::size_t area,
                          std::uint32_t u_min, std::uint32_t u_max, std::uint32_t v_min,
                          std::uint32_t v_max);

  TargetParams params_;
  std::array<std::uint32_t, LowResFrame::kMaxPixels> labels_{};
  std::array<std::uint32_t, LowResFrame::kMaxPixels> queue_{};
  std::array<std::int32_t, LowResFrame::kMaxHeight> row_first_{};
  std::array<std::int32_t, LowResFrame::kMaxHeight> row_last_{};
};

}  // namespace boticelli::image
