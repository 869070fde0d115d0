// The inverted occupancy ALN as the free-range function of the extraction: r = F⁻¹(α, h, m_safe)
// (§5.4.1).
#pragma once

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

 private:
  Model inverse_{};
  Scalar safe_occupancy_ = Scalar(0.6);
  mutable std::uint16_t hint_ = 0;
  bool valid_ = false;
};

}  // namespace boticelli::mapping
