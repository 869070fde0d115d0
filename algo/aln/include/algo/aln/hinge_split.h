// The ALN trainer's hinge split candidates, scored from a piece's per-bin sums (max-affine).
#pragma once

#include <algorithm>
#include <array>
#include <cstddef>

#include "algo/aln/aln.h"
#include "algo/aln/trainer_sums.h"

namespace boticelli::aln {
namespace train_detail {

// A hinge split (Trainer::split_hinge) turns piece p into kind(A', B) with A' = A + c0 and
// B = A' + g (x_j - t) on the hinge's side (g (t - x_j) on the other), so kind(A', B) = A +
// c0 + max(0, g h) for MAX (g > 0) or A + c0 + min(0, g h) for MIN (g < 0), h = max(0, +-(x_j
// - t)): a hinge along input j at t. Every bin edge of every input, on both sides, is a
// candidate; c0 and g are the weighted least-squares fit of the piece's residuals r ~ c0 + g h
// from the bins' sums, with g held so that B's weight stays inside its bounds. The candidate
// is drawn (seeded) from those that lower the squared error within kSplitTie of the most
// (neighbouring hinge positions score almost alike) and its hinge shifted a little (seeded),
// so another seed gives another model to retry with.
struct SplitChoice {
  int axis = -1;
  double t = 0.0;
  double side = 1.0;
  double g = 0.0;
  double c0 = 0.0;
  double gain = 0.0;
};
inline constexpr double kSplitTie = 0.95;

// Candidates per piece: every inner bin edge of every input, on either side.
template <int N, std::size_t SplitBins>
inline constexpr std::size_t kSplitCandidates = static_cast<std::size_t>(N) *
                                                (SplitBins > 0 ? SplitBins - 1 : 0) * 2;

// The least-squares hinge r ~ c0 + g h from its sums, g held so that B's weight along j,
// w_j + side g, stays inside the bounds [lo_j, hi_j]; gain = the fall in the squared error.
inline SplitChoice candidate(int j, double t, double side, double w_j, double lo_j, double hi_j,
                             double sw, double rbar, double sh, double shh, double srh,
                             double step) {
  const double hbar = sh / sw;
  const double var_h = shh / sw - hbar * hbar;
  if (!(var_h > 1e-12 * step * step)) return SplitChoice{};
  const double cov = srh / sw - rbar * hbar;
  const double g_lo = side > 0.0 ? lo_j - w_j : w_j - hi_j;
  const double g_hi = side > 0.0 ? hi_j - w_j : w_j - lo_j;
  const double g = std::clamp(cov / var_h, std::min(g_lo, 0.0), std::max(g_hi, 0.0));
  const double gain = sw * (2.0 * g * cov - g * g * var_h);
  if (!(gain > 0.0) || g == 0.0) return SplitChoice{};
  return SplitChoice{j, t, side, g, rbar - g * hbar, gain};
}

// Every candidate of piece `piece` of `model` from its pass's sums `a`, in O(SplitBins) per
// input: the bins' moments about the span's low end, summed from either end, give each edge's
// sums of h = max(0, +-(x - t)), h^2 and r h directly.
template <typename Scalar, int N, std::size_t MaxPieces, std::size_t SplitBins>
inline void split_candidates(const Aln<Scalar, N, MaxPieces>& model,
                             const Accumulator<N, SplitBins>& a, const Piece<Scalar, N>& piece,
                             std::array<SplitChoice, kSplitCandidates<N, SplitBins>>& out) {
  const double sw = a.sw;
  const double rbar = a.sr / sw;
  std::size_t k = 0;
  for (int j = 0; j < N; ++j) {
    const auto& bins = a.bins[static_cast<std::size_t>(j)];
    const double step = a.bin_step(j);
    // Moments of v = x - bin_lo per bin: m0 = sum w, m1 = sum w v, m2 = sum w v^2,
    // r0 = sum w r, r1 = sum w r v.
    std::array<std::array<double, 5>, SplitBins> m{};
    for (std::size_t b = 0; b < SplitBins; ++b) {
      const HingeBin& bin = bins[b];
      const double c = (static_cast<double>(b) + 0.5) * step;
      m[b] = {bin.sw, bin.su + c * bin.sw, bin.suu + 2.0 * c * bin.su + c * c * bin.sw, bin.sr,
              bin.sru + c * bin.sr};
    }
    std::array<double, 5> total{};
    for (const auto& mb : m) {
      for (std::size_t i = 0; i < 5; ++i) total[i] += mb[i];
    }
    std::array<double, 5> left{};  // the bins below the edge
    const double w_j = static_cast<double>(piece.weight(j));
    const double lo_j = static_cast<double>(model.weight_lo(j));
    const double hi_j = static_cast<double>(model.weight_hi(j));
    for (std::size_t e = 1; e < SplitBins; ++e) {
      for (std::size_t i = 0; i < 5; ++i) left[i] += m[e - 1][i];
      const double tau = static_cast<double>(e) * step;
      for (const double side : {1.0, -1.0}) {
        std::array<double, 5> s{};
        for (std::size_t i = 0; i < 5; ++i) s[i] = side > 0.0 ? total[i] - left[i] : left[i];
        const double sh = side * (s[1] - tau * s[0]);
        const double shh = s[2] - 2.0 * tau * s[1] + tau * tau * s[0];
        const double srh = side * (s[4] - tau * s[3]);
        out[k++] =
            candidate(j, a.bin_lo(j) + tau, side, w_j, lo_j, hi_j, sw, rbar, sh, shh, srh, step);
      }
    }
  }
}

}  // namespace train_detail
}  // namespace boticelli::aln
