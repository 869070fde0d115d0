// The block evaluation of an ALN training pass: samples evaluated kBlock at a time, then visited.
#pragma once

#include <algorithm>
#include <array>
#include <cstddef>
#include <cstdint>
#include <span>

#include <Eigen/Core>

#include "algo/aln/aln.h"
#include "algo/aln/samples.h"

namespace boticelli::aln {
namespace train_detail {

// Visits [begin, end) of a pass over `samples` (sample k·stride for visit k): `model`
// evaluated a block of samples at a time (Aln::evaluate_block), then visit(sample, the
// model's value at it, its responsible piece) for each sample of the block in turn.
template <typename Scalar, int N, std::size_t MaxPieces, typename Visit>
inline void visit_in_blocks(const Aln<Scalar, N, MaxPieces>& model, SampleSet<Scalar, N> samples,
                            std::size_t stride, std::size_t begin, std::size_t end, Visit&& visit) {
  using Vec = Eigen::Matrix<Scalar, N, 1>;
  constexpr std::size_t kBlock = Aln<Scalar, N, MaxPieces>::kBlock;
  std::array<Vec, kBlock> x;
  std::array<Scalar, kBlock> value;
  std::array<std::uint16_t, kBlock> piece;
  for (std::size_t k = begin; k < end; k += kBlock) {
    const std::size_t n = std::min(kBlock, end - k);
    for (std::size_t i = 0; i < n; ++i) x[i] = samples[(k + i) * stride].x;
    model.evaluate_block(std::span<const Vec>(x.data(), n), value, piece);
    for (std::size_t i = 0; i < n; ++i) visit(samples[(k + i) * stride], value[i], piece[i]);
  }
}

}  // namespace train_detail
}  // namespace boticelli::aln
