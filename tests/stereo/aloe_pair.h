// The Middlebury "Aloe" stereo pair (OpenCV's sample data) as the epipolar tracker sees it.
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "algo/image/epipolar_tracker.h"
#include "algo/image/low_res_frame.h"

namespace boticelli::test {

// The pair averaged by downsample_yuyv in 8x8 blocks (1282x1110 → 160x138)
// and transposed, so that the disparity, horizontal in the photographs, runs along the
// columns like the tilt pair's near-vertical motion: a left-image point at low-resolution
// (u, v) is seen in the right image at (u, v − d). Reading the files needs OpenCV.
struct AloePair {
  image::LowResFrame first;   // left image, transposed: 138 columns, 160 rows
  image::LowResFrame second;  // right image, the same
  // Ground truth d per low-resolution pixel of `first` [low-resolution px], the mean of the
  // block's full-resolution disparities / 8; negative where any of them is unknown.
  std::vector<float> disparity_px;
  float max_disparity_px = 0.0F;  // the largest known d [low-resolution px]
  // The full-resolution truth (×1, 0 unknown), transposed like the frames: a block that
  // straddles a depth edge holds two surfaces, and a match of either one is right.
  std::vector<std::uint8_t> truth_full;
  std::uint32_t truth_full_width = 0;  // [px], = 8 · first.width
  std::uint32_t factor = 8;            // full-resolution px per low-resolution px

  // |d − d_true| for a match of the feature at low-resolution (u, v) with disparity d
  // [low-resolution px]: the distance to the nearest of the block's 64 true disparities;
  // negative where any of them is unknown.
  [[nodiscard]] float disparity_error(std::uint32_t u, std::uint32_t v, float d) const;
};

// Reads aloeL.jpg, aloeR.jpg and aloeGT.png (disparity ×1) from `directory`; false with a
// reason if a file is missing or not the expected size.
bool load_aloe_pair(const std::string& directory, AloePair& out, std::string& why);

// The tracker's or a peer's result on the pair, counted against the ground truth.
struct StereoYield {
  std::size_t features = 0;    // selected
  std::size_t matched = 0;     // kept by the matcher
  std::size_t with_truth = 0;  // kept, where the ground truth is known
  std::size_t within_1px = 0;  // |d − d_true| ≤ 1 low-resolution px (AloePair::disparity_error)
  std::size_t beyond_3px = 0;  // |d − d_true| > 3 low-resolution px
  // The same against the block's mean true disparity (a block on a depth edge counts as
  // wrong for a match of either surface).
  std::size_t within_1px_of_mean = 0;
  std::size_t beyond_3px_of_mean = 0;
  double cpu_ms = 0.0;  // selection and matching, median over the repeats [ms]

  [[nodiscard]] double yield() const {
    return features == 0 ? 0.0 : static_cast<double>(matched) / static_cast<double>(features);
  }
  [[nodiscard]] double share_within_1px() const {
    return with_truth == 0 ? 0.0
                           : static_cast<double>(within_1px) / static_cast<double>(with_truth);
  }
  [[nodiscard]] double share_beyond_3px() const {
    return with_truth == 0 ? 0.0
                           : static_cast<double>(beyond_3px) / static_cast<double>(with_truth);
  }
};

// The project's feature selector (500 features over the whole frame, 3 px from the border)
// and epipolar tracker on the pair, searching each feature's column from d = 0 to the
// largest true disparity plus 2 px. `repeats` timed runs (thread CPU time).
StereoYield track_aloe(const AloePair& pair, const image::TrackParams& params, int repeats = 1);

// The peer: OpenCV's goodFeaturesToTrack (500, quality 0.01, 2 px apart) and pyramidal
// Lucas-Kanade (15x15, 3 levels) on the same frames (luma rounded to 8 bits), its tracks
// kept where they drift at most 1 px across the search direction. OpenCV runs on the
// calling thread alone (setNumThreads(0)) so that cpu_ms is all of its work.
StereoYield track_aloe_opencv(const AloePair& pair, int repeats = 1);

}  // namespace boticelli::test
