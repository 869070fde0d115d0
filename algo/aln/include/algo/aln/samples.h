// Training samples for an ALN: a caller-owned buffer seen through a non-owning view.
#pragma once

#include <cstddef>
#include <span>

#include <Eigen/Core>

namespace boticelli::aln {

// One sample {x_k, y_k} with a weight (thesis Eq 4.22's w; 1 unless the caller knows better).
template <typename Scalar, int N>
struct Sample {
  Eigen::Matrix<Scalar, N, 1> x = Eigen::Matrix<Scalar, N, 1>::Zero();
  Scalar y = Scalar(0);
  Scalar weight = Scalar(1);
};

// A view of samples the caller owns (e.g. a FixedVector<Sample<float, 3>, 250000> or a
// static array). The trainer reads it and never copies or resizes it.
template <typename Scalar, int N>
using SampleSet = std::span<const Sample<Scalar, N>>;

}  // namespace boticelli::aln
