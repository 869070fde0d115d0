// The per-piece sums an ALN training pass gathers: normal equations, V-split and hinge-bin sums.
#pragma once

#include <algorithm>
#include <array>
#include <cstddef>
#include <limits>

#include <Eigen/Core>

#include "algo/aln/samples.h"

namespace boticelli::aln {
namespace train_detail {

// Sums of one bin of one input's split candidates, in coordinates u = x - the bin's centre.
struct HingeBin {
  double sw = 0.0;   // sum w
  double su = 0.0;   // sum w u
  double suu = 0.0;  // sum w u^2
  double sr = 0.0;   // sum w r (r the sample's residual)
  double sru = 0.0;  // sum w r u
};

// Per-piece sums over the samples it is responsible for, in coordinates shifted by the
// piece's centroid at the start of the pass (better conditioned). SplitBins: the hinge
// candidates' bins per input (Trainer::kSplitBins).
template <int N, std::size_t SplitBins>
struct Accumulator {
  using VecD = Eigen::Matrix<double, N, 1>;
  using MatD = Eigen::Matrix<double, N, N>;

  double sw = 0.0;  // sum of (robust) weights
  std::size_t count = 0;
  VecD sx = VecD::Zero();
  double sy = 0.0;
  MatD sxx = MatD::Zero();
  VecD sxy = VecD::Zero();
  double sse = 0.0;        // robust-weighted squared residuals
  double loss = 0.0;       // robust loss at the fixed scale (sse without robust weights)
  double sse_plain = 0.0;  // sample-weighted squared residuals
  double sw_plain = 0.0;
  double sr = 0.0;  // sum w r
  // For the V split: |d_j| = |x_j - centroid_j| / width_j (the V a split would add).
  VecD sra = VecD::Zero();  // sum w r |d_j|
  VecD sa = VecD::Zero();   // sum w |d_j|
  VecD saa = VecD::Zero();  // sum w d_j^2
  // Split candidates: SplitBins equal bins per input over [bin_lo, bin_lo + SplitBins
  // bin_step), samples outside in the end bins; and the span the samples really had.
  VecD bin_lo = VecD::Zero();
  VecD bin_step = VecD::Ones();
  VecD bin_scale = VecD::Ones();  // 1 / bin_step
  VecD seen_lo = VecD::Constant(std::numeric_limits<double>::infinity());
  VecD seen_hi = VecD::Constant(-std::numeric_limits<double>::infinity());
  std::array<std::array<HingeBin, SplitBins>, static_cast<std::size_t>(N)> bins{};
  bool binned = false;  // whether `bins` hold this pass's sums (Trainer::gather_bins_)
};

// The span of a piece's samples (where the next pass puts its bins).
template <typename Scalar, int N, std::size_t SplitBins>
inline void keep_span(const Sample<Scalar, N>& s, Accumulator<N, SplitBins>& a) {
  for (int j = 0; j < N; ++j) {
    const double xj = static_cast<double>(s.x(j));
    a.seen_lo(j) = std::min(a.seen_lo(j), xj);
    a.seen_hi(j) = std::max(a.seen_hi(j), xj);
  }
}

// A sample's share of its piece's hinge sums: its bin on each input (SplitBins > 0).
template <typename Scalar, int N, std::size_t SplitBins>
inline void add_to_bins(const Sample<Scalar, N>& s, double w, double r,
                        Accumulator<N, SplitBins>& a) {
  for (int j = 0; j < N; ++j) {
    const double xj = static_cast<double>(s.x(j));
    const double t = (xj - a.bin_lo(j)) * a.bin_scale(j);
    const std::size_t b =
        t <= 0.0 ? 0 : std::min(static_cast<std::size_t>(t), SplitBins - 1);  // NaN-free: t > 0
    const double u = xj - (a.bin_lo(j) + (static_cast<double>(b) + 0.5) * a.bin_step(j));
    HingeBin& bin = a.bins[static_cast<std::size_t>(j)][b];
    bin.sw += w;
    bin.su += w * u;
    bin.suu += w * u * u;
    bin.sr += w * r;
    bin.sru += w * r * u;
  }
}

}  // namespace train_detail
}  // namespace boticelli::aln
