// Fixed-point (Q16.16) ALN evaluator for boards without an FPU, compiled from a float/double ALN.
#pragma once

#include <array>
#include <cmath>
#include <cstddef>
#include <cstdint>

#include "algo/aln/aln.h"

namespace boticelli::aln {

// Inputs and output are Q16.16 (value * 65536 in an int32: range +-32768, step 1.5e-5).
// Weights are stored with as many fraction bits as the model allows (weight_frac_bits(),
// chosen so no product or sum can overflow an int64 for inputs inside the model's ranges);
// biases are Q16.16. Evaluation uses only integer adds, multiplies and shifts.
// Error against the float model: about (|bias| rounding 2^-17) + sum_i |w_i| 2^-17 (input
// rounding) + sum_i |x_i| 2^-(f+1) (weight rounding) per piece, i.e. ~1e-4 for the
// occupancy model; the MIN/MAX picks can differ only where pieces are that close.
template <int N, std::size_t MaxPieces>
class FixedPointAln {
 public:
  static constexpr int kFracBits = 16;
  using Input = std::array<std::int32_t, static_cast<std::size_t>(N)>;
  struct Result {
    std::int32_t value = 0;  // Q16.16
    std::uint16_t piece = 0;
    std::uint16_t pieces_evaluated = 0;
  };

  static std::int32_t to_fixed(double v) {
    return static_cast<std::int32_t>(std::llround(v * 65536.0));
  }
  static double to_double(std::int32_t q) { return static_cast<double>(q) / 65536.0; }

  // False if the model does not fit Q16.16 (a range or bias beyond +-32767).
  template <typename Scalar>
  bool compile(const Aln<Scalar, N, MaxPieces>& model) {
    double max_w = 0.0;
    double max_sum = 0.0;  // bound on |sum_i w_i x_i| over the input box
    for (int i = 0; i < N; ++i) {
      const Range<Scalar> r = model.input_range(i);
      if (!(std::fabs(static_cast<double>(r.lo)) < 32767.0 &&
            std::fabs(static_cast<double>(r.hi)) < 32767.0)) {
        return false;
      }
    }
    for (const auto& p : model.pieces()) {
      double sum = 0.0;
      for (int i = 0; i < N; ++i) {
        const Range<Scalar> r = model.input_range(i);
        const double w = std::fabs(static_cast<double>(p.weight(i)));
        const double x =
            std::fmax(std::fabs(static_cast<double>(r.lo)), std::fabs(static_cast<double>(r.hi)));
        max_w = std::fmax(max_w, w);
        sum += w * (x + 1.0);
      }
      max_sum = std::fmax(max_sum, sum);
      if (!(std::fabs(static_cast<double>(p.bias)) < 32767.0)) return false;
    }
    // Largest f with max_w 2^f < 2^31 and max_sum 2^(16+f) < 2^61.
    int f = 30;
    while (f > 0 && (max_w * std::ldexp(1.0, f) >= 2147483647.0 ||
                     max_sum * std::ldexp(1.0, 16 + f) >= std::ldexp(1.0, 61))) {
      --f;
    }
    if (max_w * std::ldexp(1.0, f) >= 2147483647.0) return false;
    frac_ = f;
    count_ = model.piece_count();
    for (std::size_t p = 0; p < count_; ++p) {
      const auto& piece = model.piece(p);
      for (int i = 0; i < N; ++i) {
        weight_[p][static_cast<std::size_t>(i)] = static_cast<std::int32_t>(
            std::llround(std::ldexp(static_cast<double>(piece.weight(i)), f)));
      }
      bias_[p] = static_cast<std::int64_t>(to_fixed(static_cast<double>(piece.bias))) *
                 (std::int64_t{1} << f);
    }
    nodes_ = model.node_count();
    for (std::size_t k = 0; k < nodes_; ++k) {
      const auto& n = model.node(model.post_order()[k]);
      op_[k] = Op{n.kind, n.kind == NodeKind::kPiece ? n.a : std::uint16_t{0}};
    }
    return true;
  }

  [[nodiscard]] Result evaluate(const Input& x) const {
    std::array<std::int32_t, MaxPieces> v;  // a stack; only entries below `top` are read
    std::array<std::uint16_t, MaxPieces> who;
    std::size_t top = 0;
    for (std::size_t k = 0; k < nodes_; ++k) {
      const Op& op = op_[k];
      if (op.kind == NodeKind::kPiece) {
        v[top] = piece_value(op.piece, x);
        who[top] = op.piece;
        ++top;
      } else {
        --top;
        const bool take_second =
            op.kind == NodeKind::kMax ? v[top] > v[top - 1] : v[top] < v[top - 1];
        if (take_second) {
          v[top - 1] = v[top];
          who[top - 1] = who[top];
        }
      }
    }
    return {v[0], who[0], static_cast<std::uint16_t>(count_)};
  }

  [[nodiscard]] int weight_frac_bits() const { return frac_; }
  [[nodiscard]] std::size_t piece_count() const { return count_; }

 private:
  struct Op {
    NodeKind kind = NodeKind::kPiece;
    std::uint16_t piece = 0;
  };

  std::int32_t piece_value(std::uint16_t p, const Input& x) const {
    std::int64_t acc = bias_[p];
    for (std::size_t i = 0; i < static_cast<std::size_t>(N); ++i) {
      acc += static_cast<std::int64_t>(weight_[p][i]) * x[i];
    }
    // Round to nearest: Q(16+f) -> Q16.16.
    const std::int64_t half = frac_ > 0 ? (std::int64_t{1} << (frac_ - 1)) : 0;
    return static_cast<std::int32_t>((acc + half) >> frac_);
  }

  int frac_ = 0;
  std::size_t count_ = 0;
  std::size_t nodes_ = 0;
  std::array<std::array<std::int32_t, static_cast<std::size_t>(N)>, MaxPieces> weight_{};
  std::array<std::int64_t, MaxPieces> bias_{};
  std::array<Op, 2 * MaxPieces - 1> op_{};
};

}  // namespace boticelli::aln
