// Shared helpers of the ALN tests: deterministic random numbers and random MIN/MAX models.
#pragma once

#include <cstddef>
#include <cstdint>

#include <Eigen/Core>

#include "algo/aln/aln.h"

namespace aln_test {

// xorshift64*: deterministic on every platform.
class Rng {
 public:
  explicit Rng(std::uint64_t seed) : s_(seed * 0x9E3779B97F4A7C15ULL + 1) {}
  std::uint64_t next() {
    s_ ^= s_ >> 12;
    s_ ^= s_ << 25;
    s_ ^= s_ >> 27;
    return s_ * 0x2545F4914F6CDD1DULL;
  }
  // Uniform in [lo, hi).
  double uniform(double lo, double hi) {
    return lo + (hi - lo) * static_cast<double>(next() >> 11) / 9007199254740992.0;
  }
  std::size_t below(std::size_t n) { return static_cast<std::size_t>(next() % n); }

 private:
  std::uint64_t s_;
};

// A random model with `pieces` pieces on the box [0, 1]^N (inputs) and output [-2, 2]:
// splits a random piece into MIN or MAX of two random planes. If `monotone_input` >= 0,
// every piece's weight on that input lies in [0.2, 2] (strictly increasing).
template <typename Model>
void random_model(Model& model, std::size_t pieces, Rng& rng, int monotone_input = -1) {
  using Scalar = typename Model::ScalarType;
  constexpr int N = Model::kInputs;
  const auto random_piece = [&]() {
    boticelli::aln::Piece<Scalar, N> p;
    typename Model::Vec w;
    typename Model::Vec c;
    for (int i = 0; i < N; ++i) {
      w(i) = static_cast<Scalar>(rng.uniform(-1.0, 1.0));
      c(i) = static_cast<Scalar>(rng.uniform(0.0, 1.0));
    }
    if (monotone_input >= 0) w(monotone_input) = static_cast<Scalar>(rng.uniform(0.2, 2.0));
    p.set(w, c, static_cast<Scalar>(rng.uniform(-0.5, 0.5)));
    return p;
  };
  for (int i = 0; i < N; ++i) model.set_input_range(i, Scalar(0), Scalar(1));
  model.set_output_range(Scalar(-2), Scalar(2));
  model.reset(random_piece());
  while (model.piece_count() < pieces) {
    const std::size_t p = rng.below(model.piece_count());
    const auto kind =
        (rng.next() & 1U) != 0 ? boticelli::aln::NodeKind::kMin : boticelli::aln::NodeKind::kMax;
    (void)model.split_piece(p, kind, random_piece(), random_piece());
  }
}

template <typename Vec>
Vec random_point(Rng& rng) {
  Vec x;
  for (int i = 0; i < x.size(); ++i)
    x(i) = static_cast<typename Vec::Scalar>(rng.uniform(0.0, 1.0));
  return x;
}

}  // namespace aln_test
