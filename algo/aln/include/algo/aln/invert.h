// Inversion of an ALN in a monotone input (thesis §5.4.1): r = F^-1(alpha, h, m) from m = F(alpha,
// h, r).
#pragma once

#include <array>
#include <cstddef>
#include <limits>

#include "algo/aln/aln.h"

namespace boticelli::aln {

// Writes into `out` the inverse of `model` in input k = variable_index.
// Ordering: `out` has the same N inputs as `model`, in the same order, except that input k
// is the former output; the output of `out` is the former input k. So for the occupancy
// model m = F(alpha, h, r) (inputs 0, 1, 2) and k = 2, out is r = F^-1(alpha, h, m).
// Each piece y = c_y + sum_i w_i (x_i - c_i) is solved for x_k (its weights divided by -w_k,
// so the output weight is -1 again in the Eq 5.5 form); its centroid stays the same point.
// Node kinds: MIN and MAX swap when F increases in x_k, and stay when it decreases.
// Exact for the unfilleted function: F(x with x_k = F^-1(x with x_k = m)) = m.
// Ranges move with their variables. Weight bounds of `out`: unbounded, except input k,
// whose bounds are [1/hi_k, 1/lo_k] (for increasing) mapped from the original's.
// Returns false (out untouched) if some piece has w_k = 0 or the pieces disagree in the sign
// of w_k (not monotone). `out` may be `model` itself.
template <typename Scalar, int N, std::size_t MaxPieces>
bool invert(const Aln<Scalar, N, MaxPieces>& model, int variable_index,
            Aln<Scalar, N, MaxPieces>& out) {
  using Model = Aln<Scalar, N, MaxPieces>;
  using PieceType = Piece<Scalar, N>;
  if (variable_index < 0 || variable_index >= N) return false;
  const int k = variable_index;
  int sign = 0;
  for (const PieceType& p : model.pieces()) {
    const Scalar w = p.weight(k);
    const int s = w > Scalar(0) ? 1 : (w < Scalar(0) ? -1 : 0);
    if (s == 0 || (sign != 0 && s != sign)) return false;
    sign = s;
  }
  std::array<PieceType, MaxPieces> pieces{};
  std::array<typename Model::Node, Model::kMaxNodes> nodes{};
  std::size_t np = 0;
  for (const PieceType& p : model.pieces()) {
    const Scalar wk = p.weight(k);
    typename PieceType::Vec w = -p.weight / wk;  // Eq 5.5 weights over -w_k
    w(k) = Scalar(1) / wk;
    typename PieceType::Vec c = p.centroid;
    c(k) = p.centroid_output;
    pieces[np++].set(w, c, p.centroid(k));
  }
  std::size_t nn = 0;
  for (const auto& n : model.nodes()) {
    auto m = n;
    if (sign > 0 && n.kind == NodeKind::kMin) m.kind = NodeKind::kMax;
    if (sign > 0 && n.kind == NodeKind::kMax) m.kind = NodeKind::kMin;
    nodes[nn++] = m;
  }
  const Range<Scalar> out_range = model.input_range(k);
  const Range<Scalar> in_range = model.output_range();
  const Scalar lo_k = model.weight_lo(k);
  const Scalar hi_k = model.weight_hi(k);
  std::array<Range<Scalar>, static_cast<std::size_t>(N)> ranges{};
  for (int i = 0; i < N; ++i) ranges[static_cast<std::size_t>(i)] = model.input_range(i);
  if (!out.assign({nodes.data(), nn}, {pieces.data(), np})) return false;
  constexpr Scalar kInf = std::numeric_limits<Scalar>::infinity();
  for (int i = 0; i < N; ++i) {
    out.set_input_range(i, ranges[static_cast<std::size_t>(i)].lo,
                        ranges[static_cast<std::size_t>(i)].hi);
    out.set_weight_bounds(i, -kInf, kInf);
  }
  out.set_input_range(k, in_range.lo, in_range.hi);
  out.set_output_range(out_range.lo, out_range.hi);
  if (sign > 0 && lo_k >= Scalar(0)) {
    out.set_weight_bounds(k, Scalar(1) / hi_k, lo_k > Scalar(0) ? Scalar(1) / lo_k : kInf);
  } else if (sign < 0 && hi_k <= Scalar(0)) {
    out.set_weight_bounds(k, hi_k < Scalar(0) ? Scalar(1) / hi_k : -kInf, Scalar(1) / lo_k);
  }
  return true;
}

}  // namespace boticelli::aln
