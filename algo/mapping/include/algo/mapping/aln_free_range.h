// The inverted occupancy ALN as the free-range function of the extraction: r = F⁻¹(α, h, m_safe)
// (§5.4.1).
#pragma once

#include <algorithm>
#include <array>
#include <cstddef>
#include <cstdint>

#include "algo/aln/aln.h"
#include "algo/aln/invert.h"

namespace boticelli::mapping {

// Holds F⁻¹ of an occupancy model m = F(α, h, r) (inputs 0, 1, 2; monotone increasing in r)
// and answers r for (α, h) at the safe occupancy. Build it once per fitted model; the
// inversion swaps MIN and MAX and solves each piece for r (aln::invert).
template <typename Scalar, std::size_t MaxPieces>
class AlnFreeRange {
 public:
  using Model = aln::Aln<Scalar, 3, MaxPieces>;

  // False if the model is not monotone in r (some piece has c_l ≤ 0, Eq 4.24).
  bool set_model(const Model& occupancy, float safe_occupancy) {
    safe_occupancy_ = static_cast<Scalar>(safe_occupancy);
    valid_ = false;
    for (const auto& piece : occupancy.pieces()) {
      if (!(piece.weight(2) > Scalar(0))) {
        return false;  // occupancy must grow with r (Eq 4.24)
      }
    }
    valid_ = aln::invert(occupancy, 2, inverse_);
    return valid_;
  }
  [[nodiscard]] bool valid() const { return valid_; }
  [[nodiscard]] const Model& inverse() const { return inverse_; }

  // r [m] at pan angle α [rad] and height h [m] (relative to the PTU centre). Without a
  // valid model nothing is known to be free: 0.
  float operator()(float alpha_rad, float h_m) const {
    if (!valid_) {
      return 0.0F;
    }
    typename Model::Vec x;
    x << static_cast<Scalar>(alpha_rad), static_cast<Scalar>(h_m), safe_occupancy_;
    // Successive calls walk along α at one height: the last responsible piece is a good
    // first guess (alpha-beta with a hint; same value as without).
    const aln::EvalResult<Scalar> e = inverse_.evaluate_alpha_beta(x, hint_);
    hint_ = e.piece;
    return static_cast<float>(e.value);
  }

  // r [m] at height h [m] and the pan angles α_i = (first + i)·step_rad + offset_rad,
  // i < count, into out[0 .. count): the vertex angles of a StarPolygon computed the same
  // way (offset ±2π for the seam). The same function as operator(), evaluated for kBlock
  // angles at a time: at one height each piece of the inverse is a line in α (its h and m
  // terms fold into the constant), and the MIN/MAX tree combines whole blocks, children
  // before parents, with no branches per angle. The values agree with operator() to float
  // rounding (the terms are summed in another order).
  void ranges_at_height(float h_m, float step_rad, std::size_t first_index, std::size_t count,
                        float offset_rad, float* out) const {
    ranges_over_band(h_m, h_m, step_rad, first_index, count, offset_rad, out);
  }

  // A lower bound on min { r(α, h) : h ∈ [h_lo_m, h_hi_m] } at the same pan angles as
  // ranges_at_height (equal to it when h_lo_m = h_hi_m): the nearest range at which the
  // occupancy reaches m_safe anywhere in the height band, never overestimated. Interval
  // arithmetic over the MIN/MAX tree of the inverse: each piece is linear in h, so its
  // minimum over the band is at the end its h-slope points away from (exact); a MIN node's
  // minimum is the smaller of its children's (exact), a MAX node's is at least the larger of
  // its children's minima (a bound: the children may take their minima at different h). So
  // no crossing between two slices is missed, whatever the slope bounds (issue of §5.4.2's
  // finite set of heights); the bound is tight where one piece answers across the band.
  void ranges_over_band(float h_lo_m, float h_hi_m, float step_rad, std::size_t first_index,
                        std::size_t count, float offset_rad, float* out) const {
    if (!valid_) {
      std::fill(out, out + count, 0.0F);
      return;
    }
    const auto lo = static_cast<Scalar>(std::min(h_lo_m, h_hi_m));
    const auto hi = static_cast<Scalar>(std::max(h_lo_m, h_hi_m));
    const std::size_t pieces = inverse_.piece_count();
    for (std::size_t p = 0; p < pieces; ++p) {
      const auto& piece = inverse_.piece(p);
      const Scalar w_h = piece.weight(1);
      constant_[p] =
          piece.bias + w_h * (w_h > Scalar(0) ? lo : hi) + piece.weight(2) * safe_occupancy_;
      slope_[p] = piece.weight(0);
    }
    for (std::size_t k0 = 0; k0 < count; k0 += kBlock) {
      std::array<Scalar, kBlock> alpha{};
      for (std::size_t i = 0; i < kBlock; ++i) {
        alpha[i] =
            static_cast<Scalar>(static_cast<float>(first_index + k0 + i) * step_rad + offset_rad);
      }
      std::size_t top = 0;
      for (const typename Model::Op op : inverse_.ops()) {
        if (op.kind == aln::NodeKind::kPiece) {
          const Scalar c = constant_[op.piece];
          const Scalar a = slope_[op.piece];
          Block& v = stack_[top++];
          for (std::size_t i = 0; i < kBlock; ++i) v[i] = c + a * alpha[i];
        } else {
          --top;
          const Block& second = stack_[top];
          Block& first = stack_[top - 1];
          if (op.kind == aln::NodeKind::kMax) {
            for (std::size_t i = 0; i < kBlock; ++i) first[i] = std::max(first[i], second[i]);
          } else {
            for (std::size_t i = 0; i < kBlock; ++i) first[i] = std::min(first[i], second[i]);
          }
        }
      }
      const std::size_t end = std::min(count, k0 + kBlock);
      for (std::size_t k = k0; k < end; ++k) out[k] = static_cast<float>(stack_[0][k - k0]);
    }
  }

 private:
  Model inverse_{};
  Scalar safe_occupancy_ = Scalar(0.6);
  static constexpr std::size_t kBlock = 16;
  using Block = std::array<Scalar, kBlock>;
  // Working memory of ranges_at_height (the evaluation stack holds at most one block per
  // piece): part of the object, so nothing is allocated.
  mutable std::array<Scalar, MaxPieces> constant_{};
  mutable std::array<Scalar, MaxPieces> slope_{};
  mutable std::array<Block, MaxPieces> stack_{};
  mutable std::uint16_t hint_ = 0;
  bool valid_ = false;
};

}  // namespace boticelli::mapping
