// The free range of any occupancy ALN, monotone in r or not (the belief model, §4.3, §7.2.3):
// the first r along the ray where the occupancy reaches m_safe.
#pragma once

#include <algorithm>
#include <array>
#include <cstddef>
#include <cstdint>
#include <limits>

#include "algo/aln/aln.h"

namespace boticelli::mapping {

// Answers r = min { r ∈ [0, r_max] : F(α, h, r) ≥ m_safe } for an occupancy model
// m = F(α, h, r) (inputs 0, 1, 2), or +infinity if the ray never gets that occupied within
// r_max (free to the bounding circle for the extraction). For a model monotone in r this
// is F⁻¹(α, h, m_safe), as AlnFreeRange gives it; a belief model rises at a feature and
// falls again behind it (the evidence behind an observed point is zero, §3.7.3), so it has
// no inverse, and this is the free range the extraction needs from it.
// Exact, no search: at one (α, h) each piece is a line in r, so {r : piece ≥ m} is an
// interval; a MAX node is the union of its children's sets, a MIN node their intersection,
// evaluated children before parents on sorted interval lists in fixed storage (a subtree
// of p pieces gives at most p intervals). Build once per fitted model; the object holds a
// copy of the model and about 32 bytes per piece of working memory, and allocates nothing.
template <typename Scalar, std::size_t MaxPieces>
class AlnFirstCrossing {
 public:
  using Model = aln::Aln<Scalar, 3, MaxPieces>;

  // Keeps a copy of the model. False (and nothing is free) if the range is not
  // positive.
  bool set_model(const Model& occupancy, float safe_occupancy, float max_range_m) {
    model_ = occupancy;
    safe_ = static_cast<Scalar>(safe_occupancy);
    max_range_ = static_cast<Scalar>(max_range_m);
    valid_ = max_range_ > Scalar(0);
    return valid_;
  }
  [[nodiscard]] bool valid() const { return valid_; }

  // r [m] at pan angle α [rad] and height h [m] (relative to the PTU centre): the first
  // range at which the model reaches m_safe, +infinity if it never does within r_max, and
  // 0 without a valid model (nothing is known to be free).
  float operator()(float alpha_rad, float h_m) const {
    if (!valid_) {
      return 0.0F;
    }
    const auto alpha = static_cast<Scalar>(alpha_rad);
    const auto h = static_cast<Scalar>(h_m);
    std::size_t top = 0;   // lists on the stack
    std::size_t used = 0;  // intervals in the pool
    for (const typename Model::Op op : model_.ops()) {
      if (op.kind == aln::NodeKind::kPiece) {
        const auto& piece = model_.piece(op.piece);
        // m(r) = c + w r ≥ m_safe on one interval of [0, r_max] (or none).
        const Scalar c = piece.bias + piece.weight(0) * alpha + piece.weight(1) * h;
        const Scalar w = piece.weight(2);
        Scalar lo = Scalar(0);
        Scalar hi = max_range_;
        if (w > Scalar(0)) {
          lo = std::max(lo, (safe_ - c) / w);
        } else if (w < Scalar(0)) {
          hi = std::min(hi, (safe_ - c) / w);
        } else if (!(c >= safe_)) {
          hi = Scalar(-1);  // never
        }
        lists_[top] = List{used, 0};
        if (lo <= hi) {
          pool_[used++] = Interval{lo, hi};
          lists_[top].count = 1;
        }
        ++top;
        continue;
      }
      // Combine the top two lists (adjacent at the end of the pool) into scratch, then
      // copy back in place of the first.
      const List b = lists_[--top];
      const List a = lists_[top - 1];
      const std::size_t n = op.kind == aln::NodeKind::kMax ? unite(a, b) : intersect(a, b);
      std::copy(scratch_.begin(), scratch_.begin() + static_cast<std::ptrdiff_t>(n),
                pool_.begin() + static_cast<std::ptrdiff_t>(a.first));
      lists_[top - 1] = List{a.first, n};
      used = a.first + n;
    }
    const List root = lists_[0];
    if (root.count == 0) {
      return std::numeric_limits<float>::infinity();
    }
    return static_cast<float>(pool_[root.first].lo);
  }

 private:
  struct Interval {
    Scalar lo;
    Scalar hi;
  };
  struct List {
    std::size_t first;
    std::size_t count;
  };

  // Union of two sorted disjoint lists into scratch_; returns its length.
  std::size_t unite(List a, List b) const {
    std::size_t i = 0;
    std::size_t j = 0;
    std::size_t n = 0;
    while (i < a.count || j < b.count) {
      const bool take_a =
          j == b.count || (i < a.count && pool_[a.first + i].lo <= pool_[b.first + j].lo);
      const Interval next = take_a ? pool_[a.first + i++] : pool_[b.first + j++];
      if (n > 0 && next.lo <= scratch_[n - 1].hi) {
        scratch_[n - 1].hi = std::max(scratch_[n - 1].hi, next.hi);
      } else {
        scratch_[n++] = next;
      }
    }
    return n;
  }

  // Intersection of two sorted disjoint lists into scratch_; returns its length.
  std::size_t intersect(List a, List b) const {
    std::size_t i = 0;
    std::size_t j = 0;
    std::size_t n = 0;
    while (i < a.count && j < b.count) {
      const Interval x = pool_[a.first + i];
      const Interval y = pool_[b.first + j];
      const Scalar lo = std::max(x.lo, y.lo);
      const Scalar hi = std::min(x.hi, y.hi);
      if (lo <= hi) {
        scratch_[n++] = Interval{lo, hi};
      }
      (x.hi < y.hi ? i : j) += 1;
    }
    return n;
  }

  Model model_{};
  Scalar safe_ = Scalar(0.6);
  Scalar max_range_ = Scalar(0);
  // Evaluation memory: a stack of lists over one pool (the lists on the stack belong to
  // disjoint subtrees, so together they hold at most MaxPieces intervals).
  mutable std::array<Interval, MaxPieces> pool_{};
  mutable std::array<Interval, MaxPieces> scratch_{};
  mutable std::array<List, MaxPieces> lists_{};
  bool valid_ = false;
};

}  // namespace boticelli::mapping
