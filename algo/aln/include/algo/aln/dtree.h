// DTREE: an ALN compiled into axis-aligned blocks, each keeping only the pieces that can be active
// there (thesis §4.7.2).
#pragma once

#include <algorithm>
#include <array>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <limits>

#include <Eigen/Core>

#include "algo/aln/aln.h"

namespace boticelli::aln {

// compile() first cuts the model's input box into a regular grid (at most MaxGridCells
// cells, found by arithmetic, no branches), then partitions each cell by thresholds on one
// input at a time. In each block, a MIN/MAX child that is dominated over the whole block (its
// bounds over the block cannot win, with a rounding margin) is dropped, so the block keeps a
// small MIN/MAX tree of the pieces that can be active there. A block is split further (at the
// midpoint of the input that leaves the fewest pieces in the two halves) while it has more
// pieces than compile()'s block_pieces and the depth limit allows. evaluate() walks the
// thresholds and evaluates the block's small tree: one piece, or the MIN or MAX of two without
// a branch, or the block's ops in post order. Thesis §4.7.2 stops at N + 1 pieces a block;
// the default stops at 2, which costs more thresholds but evaluates most blocks without
// branches (docs/benchmarks.md, aln suite). Exact (same value and piece as Aln::evaluate) for
// inputs inside the model's input box; callers clamp inputs to it.
// Storage: MaxBlocks blocks (and as many thresholds), MaxBlockNodes ops over all blocks
// (blocks with the same ops share them), MaxGridCells grid cells: about 1 MB with the
// defaults for <float, 3, 256>: make it static.
template <typename Scalar, int N, std::size_t MaxPieces, std::size_t MaxBlocks = 32768,
          std::size_t MaxBlockNodes = 65536, std::size_t MaxGridCells = 4096>
class Dtree {
 public:
  using Model = Aln<Scalar, N, MaxPieces>;
  using Vec = Eigen::Matrix<Scalar, N, 1>;
  static constexpr std::size_t kMaxSplits = MaxBlocks - 1;
  static constexpr std::size_t kGridPerAxis = [] {
    std::size_t g = 1;
    while (true) {
      std::size_t cells = 1;
      for (int i = 0; i < N; ++i) cells *= g + 1;
      if (cells > MaxGridCells) return g;
      ++g;
    }
  }();
  static constexpr std::size_t kGridCells = [] {
    std::size_t cells = 1;
    for (int i = 0; i < N; ++i) cells *= kGridPerAxis;
    return cells;
  }();
  static constexpr Scalar kLastCell = static_cast<Scalar>(kGridPerAxis - 1);
  static_assert(MaxBlocks >= 1 && MaxBlocks < (1U << 30), "block capacity");
  static_assert(MaxBlockNodes < (1U << 31), "block node capacity");
  static_assert(kGridCells <= MaxBlocks, "every grid cell needs a block");
  // A block's code: -(1 + (first op << kCountBits | ops)); a block has at most 2P - 1 ops.
  static constexpr std::uint32_t kCountBits = [] {
    std::uint32_t bits = 0;
    while ((std::size_t{1} << bits) <= 2 * MaxPieces - 1) ++bits;
    return bits;
  }();
  static constexpr std::uint32_t kCountMask = (std::uint32_t{1} << kCountBits) - 1;
  static_assert(MaxBlockNodes <= (std::size_t{1} << (31 - kCountBits)) &&
                    MaxPieces <= (std::size_t{1} << (31 - kCountBits)),
                "a block's code must hold its first op and its op count");

  // Compiles `model`; max_depth bounds the number of thresholds below a grid cell on a
  // query's path (and the compiler's recursion). If the capacities are too small for that
  // depth, compiles again with less depth. False if even depth 0 does not fit: then
  // evaluate() returns NaN until a compile succeeds.
  // block_pieces: a block with at most this many pieces is not split further (2 by default;
  // N + 1 is the thesis's, §4.7.2; more gives fewer thresholds per query).
  bool compile(const Model& model, std::size_t max_depth = 10, std::size_t block_pieces = 2) {
    target_ = block_pieces > 0 ? block_pieces : 1;
    for (std::size_t depth = max_depth;; --depth) {
      if (compile_at(model, depth)) return true;
      if (depth == 0) return false;
    }
  }

  [[nodiscard]] bool valid() const { return ok_; }
  // The depth the last successful compile used.
  [[nodiscard]] std::size_t depth_used() const { return depth_used_; }

 private:
  bool compile_at(const Model& model, std::size_t max_depth) {
    model_ = &model;
    depth_used_ = max_depth;
    splits_used_ = 0;
    blocks_used_ = 0;
    pool_used_ = 0;
    ok_ = true;
    for (int i = 0; i < N; ++i) {
      const Range<Scalar> r = model.input_range(i);
      lo_(i) = static_cast<double>(r.lo);
      hi_(i) = static_cast<double>(r.hi);
    }
    block_pieces_max_ = 0;
    block_pieces_sum_ = 0;
    share_.fill(0);
    shared_ = 0;
    for (std::size_t p = 0; p < model.piece_count(); ++p) {
      coef_[p].template head<N>() = model.piece(p).weight;
      coef_[p](N) = model.piece(p).bias;
    }
    std::size_t stride = 1;
    for (int i = 0; i < N; ++i) {
      cell_stride_[static_cast<std::size_t>(i)] = static_cast<std::uint32_t>(stride);
      stride *= kGridPerAxis;
      const double w = hi_(i) - lo_(i);
      cell_scale_(i) =
          w > 0.0 ? static_cast<Scalar>(static_cast<double>(kGridPerAxis) / w) : Scalar(0);
      cell_origin_(i) = static_cast<Scalar>(lo_(i));
    }
    for (std::size_t cell = 0; cell < kGridCells && ok_; ++cell) {
      // The cell's box, widened a little so rounding in the cell index cannot route a
      // query to a cell whose pruning did not consider it.
      VecD lo = lo_;
      VecD hi = hi_;
      std::size_t rest = cell;
      for (int i = 0; i < N; ++i) {
        const std::size_t c = rest % kGridPerAxis;
        rest /= kGridPerAxis;
        const double w = (hi_(i) - lo_(i)) / static_cast<double>(kGridPerAxis);
        lo(i) = lo_(i) + w * static_cast<double>(c) - 1e-3 * w;
        hi(i) = lo_(i) + w * static_cast<double>(c + 1) + 1e-3 * w;
      }
      cell_root_[cell] = build(lo, hi, 0, max_depth);
    }
    if (!ok_) {
      splits_used_ = 0;
      blocks_used_ = 0;
      pool_used_ = 0;
      block_pieces_max_ = 0;
      block_pieces_sum_ = 0;
    }
    model_ = nullptr;
    return ok_;
  }

 public:
  // Small enough to inline into the caller's loop; blocks of three or more pieces take
  // evaluate_ops().
  [[nodiscard, gnu::always_inline]] EvalResult<Scalar> evaluate(const Vec& x) const {
    if (!ok_) return {std::numeric_limits<Scalar>::quiet_NaN(), 0, 0};
    // The grid cell by arithmetic, without branches (NaN goes to cell 0).
    std::uint32_t cell = 0;
    for (int i = 0; i < N; ++i) {
      const Scalar u = (x(i) - cell_origin_(i)) * cell_scale_(i);
      const Scalar clamped = std::min(std::max(Scalar(0), u), kLastCell);
      cell += static_cast<std::uint32_t>(static_cast<int>(clamped)) *
              cell_stride_[static_cast<std::size_t>(i)];
    }
    std::int32_t c = cell_root_[cell];
    while (c >= 0) {
      const Split& s = splits_[static_cast<std::size_t>(c)];
      c = x(s.axis) < s.threshold ? s.below : s.above;
    }
    // The leaf's code holds its ops (first, count) itself: no block record is loaded.
    const auto leaf = static_cast<std::uint32_t>(-(c + 1));
    const std::uint32_t count = leaf & kCountMask;
    const std::uint32_t first = leaf >> kCountBits;
    if (count == 1) {  // a one-piece block's code holds the piece itself
      const auto piece = static_cast<std::uint16_t>(first);
      return {value(piece, x), piece, 1};
    }
    const Op* op = &pool_[first];
    if (count == 3) {  // two pieces and their MIN or MAX, without branches
      const Scalar va = value(op[0].piece, x);
      const Scalar vb = value(op[1].piece, x);
      const Scalar sign = op[2].kind == NodeKind::kMax ? Scalar(1) : Scalar(-1);
      const bool take_second = sign * (vb - va) > Scalar(0);  // exactly vb > va for MAX
      return {take_second ? vb : va, take_second ? op[1].piece : op[0].piece, 2};
    }
    return evaluate_ops(op, count, x);
  }

  [[nodiscard]] std::size_t block_count() const { return blocks_used_; }
  [[nodiscard]] std::size_t split_count() const { return splits_used_; }
  // Ops stored over all blocks (blocks with the same ops share them).
  [[nodiscard]] std::size_t node_count() const { return pool_used_; }
  // Largest number of pieces kept in one block, and the mean over blocks.
  [[nodiscard]] std::size_t max_block_pieces() const { return block_pieces_max_; }
  [[nodiscard]] double mean_block_pieces() const {
    return blocks_used_ > 0
               ? static_cast<double>(block_pieces_sum_) / static_cast<double>(blocks_used_)
               : 0.0;
  }

 private:
  using VecD = Eigen::Matrix<double, N, 1>;
  struct Split {
    Scalar threshold = Scalar(0);
    int axis = 0;
    std::int32_t below = 0;  // >= 0 a split, < 0 block -(code + 1)
    std::int32_t above = 0;
  };
  struct Op {
    NodeKind kind = NodeKind::kPiece;
    std::uint16_t piece = 0;
  };
  enum Keep : std::uint8_t { kBoth, kFirst, kSecond };

  // A piece's weights and bias side by side: one load of 16 bytes for <float, 3>.
  using Coef = Eigen::Matrix<Scalar, N + 1, 1>;
  Scalar value(std::uint16_t p, const Vec& x) const {
    const Coef& k = coef_[p];
    return k(N) + k.template head<N>().dot(x);
  }

  // A block's ops in post order on a small stack (ties keep the first child, as
  // Aln::evaluate does).
  [[gnu::noinline]] EvalResult<Scalar> evaluate_ops(const Op* op, std::uint32_t count,
                                                    const Vec& x) const {
    std::array<Scalar, MaxPieces> v;  // a stack; only entries below `top` are read
    std::array<std::uint16_t, MaxPieces> who;
    std::size_t top = 0;
    for (std::uint32_t k = 0; k < count; ++k, ++op) {
      if (op->kind == NodeKind::kPiece) {
        v[top] = value(op->piece, x);
        who[top] = op->piece;
        ++top;
      } else {
        --top;
        const bool take_second =
            op->kind == NodeKind::kMax ? v[top] > v[top - 1] : v[top] < v[top - 1];
        if (take_second) {
          v[top - 1] = v[top];
          who[top - 1] = who[top];
        }
      }
    }
    return {v[0], who[0], static_cast<std::uint16_t>((count + 1) / 2)};
  }

  // Bottom-up bounds of every node over the box [lo, hi]; returns the kept piece count.
  std::size_t analyse(const VecD& lo, const VecD& hi) {
    const Model& m = *model_;
    for (const std::uint16_t n : m.post_order()) {
      const auto& node = m.node(n);
      if (node.kind == NodeKind::kPiece) {
        const auto& p = m.piece(node.a);
        double mn = static_cast<double>(p.bias);
        double mx = mn;
        double mag = std::fabs(mn);
        for (int i = 0; i < N; ++i) {
          const double w = static_cast<double>(p.weight(i));
          mn += w > 0.0 ? w * lo(i) : w * hi(i);
          mx += w > 0.0 ? w * hi(i) : w * lo(i);
          mag += std::fabs(w) * std::max(std::fabs(lo(i)), std::fabs(hi(i)));
        }
        // Margin for rounding in Scalar evaluation.
        const double margin =
            16.0 * static_cast<double>(std::numeric_limits<Scalar>::epsilon()) * mag;
        min_[n] = mn - margin;
        max_[n] = mx + margin;
        keep_[n] = kBoth;
        pieces_[n] = 1;
        continue;
      }
      const double amin = min_[node.a];
      const double amax = max_[node.a];
      const double bmin = min_[node.b];
      const double bmax = max_[node.b];
      if (node.kind == NodeKind::kMax) {
        if (amin >= bmax) {
          keep_[n] = kFirst;
        } else if (bmin > amax) {
          keep_[n] = kSecond;
        } else {
          keep_[n] = kBoth;
        }
        min_[n] = std::max(amin, bmin);
        max_[n] = std::max(amax, bmax);
      } else {
        if (amax <= bmin) {
          keep_[n] = kFirst;
        } else if (bmax < amin) {
          keep_[n] = kSecond;
        } else {
          keep_[n] = kBoth;
        }
        min_[n] = std::min(amin, bmin);
        max_[n] = std::min(amax, bmax);
      }
      pieces_[n] = keep_[n] == kFirst    ? pieces_[node.a]
                   : keep_[n] == kSecond ? pieces_[node.b]
                                         : pieces_[node.a] + pieces_[node.b];
    }
    return pieces_[0];
  }

  // Emits the kept tree (after analyse) as a block in post order; false if out of room.
  // The block's code holds where its ops start and how many there are; a one-piece block
  // holds its piece instead and takes no ops. Blocks with the same ops share them.
  bool emit_block(std::int32_t& code) {
    if (blocks_used_ >= MaxBlocks) return false;
    const Model& m = *model_;
    const std::size_t pieces = pieces_[0];
    std::uint32_t payload = 0;
    if (pieces == 1) {
      std::uint16_t n = 0;
      while (m.node(n).kind != NodeKind::kPiece) {
        n = keep_[n] == kFirst ? m.node(n).a : m.node(n).b;
      }
      payload = (std::uint32_t{m.node(n).a} << kCountBits) | 1U;
    } else {
      std::size_t count = 0;
      struct Frame {
        std::uint16_t node;
        bool expanded;
      };
      std::array<Frame, Model::kMaxNodes> stack;
      std::size_t top = 0;
      stack[top++] = Frame{0, false};
      while (top > 0) {
        Frame& f = stack[top - 1];
        std::uint16_t n = f.node;
        while (m.node(n).kind != NodeKind::kPiece && keep_[n] != kBoth) {
          n = keep_[n] == kFirst ? m.node(n).a : m.node(n).b;
        }
        f.node = n;
        const auto& node = m.node(n);
        if (node.kind == NodeKind::kPiece || f.expanded) {
          ops_[count++] = Op{node.kind, node.kind == NodeKind::kPiece ? node.a : std::uint16_t{0}};
          --top;
          continue;
        }
        f.expanded = true;
        stack[top++] = Frame{node.b, false};
        stack[top++] = Frame{node.a, false};
      }
      if (!share_ops(count, payload)) return false;
    }
    code = -static_cast<std::int32_t>(payload) - 1;
    ++blocks_used_;
    block_pieces_max_ = pieces > block_pieces_max_ ? pieces : block_pieces_max_;
    block_pieces_sum_ += pieces;
    return true;
  }

  // Finds ops_[0, count) among the ops already stored (by hash) or stores them; false if the
  // pool is full.
  bool share_ops(std::size_t count, std::uint32_t& payload) {
    std::uint32_t h = 2166136261U;  // FNV-1a over the ops
    for (std::size_t k = 0; k < count; ++k) {
      h = (h ^ static_cast<std::uint32_t>(ops_[k].kind)) * 16777619U;
      h = (h ^ ops_[k].piece) * 16777619U;
    }
    std::size_t slot = h & (kShareSlots - 1);
    for (; share_[slot] != 0; slot = (slot + 1) & (kShareSlots - 1)) {
      const std::uint32_t stored = share_[slot] - 1;
      if ((stored & kCountMask) != count) continue;
      const Op* at = &pool_[stored >> kCountBits];
      bool same = true;
      for (std::size_t k = 0; k < count && same; ++k) {
        same = at[k].kind == ops_[k].kind && at[k].piece == ops_[k].piece;
      }
      if (same) {
        payload = stored;
        return true;
      }
    }
    if (pool_used_ + count > MaxBlockNodes || shared_ + 1 > kMaxShared) return false;
    payload = static_cast<std::uint32_t>((pool_used_ << kCountBits) | count);
    for (std::size_t k = 0; k < count; ++k) pool_[pool_used_++] = ops_[k];
    share_[slot] = payload + 1;
    ++shared_;
    return true;
  }

  // Blocks = grid cells + splits, so a split is allowed only while a block is left for it.
  std::int32_t build(const VecD& lo, const VecD& hi, std::size_t depth, std::size_t max_depth,
                     std::size_t stale = 0) {
    if (!ok_) return -1;
    const std::size_t here = analyse(lo, hi);
    const std::size_t target = target_;
    if (here > target && depth < max_depth &&
        (splits_used_ >= kMaxSplits || kGridCells + splits_used_ + 1 > MaxBlocks)) {
      ok_ = false;  // out of blocks: compile() tries again with less depth
      return -1;
    }
    if (here <= target || depth >= max_depth) {
      std::int32_t code = -1;
      if (!emit_block(code)) ok_ = false;
      return code;
    }
    // The input whose midpoint split leaves the fewest pieces in the two halves.
    int axis = -1;
    std::size_t best = 0;
    for (int i = 0; i < N; ++i) {
      if (!(hi(i) > lo(i))) continue;
      const double mid = 0.5 * (lo(i) + hi(i));
      VecD h1 = hi;
      h1(i) = mid;
      VecD l2 = lo;
      l2(i) = mid;
      const std::size_t cost = analyse(lo, h1) + analyse(l2, hi);
      if (axis < 0 || cost < best) {
        axis = i;
        best = cost;
      }
    }
    // A split that drops nothing is allowed twice in a row (the next one may), no more.
    const bool reduced = best < 2 * here;
    if (axis < 0 || (!reduced && stale >= 2)) {
      analyse(lo, hi);
      std::int32_t code = -1;
      if (!emit_block(code)) ok_ = false;
      return code;
    }
    const double mid = 0.5 * (lo(axis) + hi(axis));
    const std::size_t s = splits_used_++;
    splits_[s].axis = axis;
    splits_[s].threshold = static_cast<Scalar>(mid);
    // Route by the Scalar threshold exactly as evaluate() does.
    const double t = static_cast<double>(splits_[s].threshold);
    VecD h1 = hi;
    h1(axis) = t;
    VecD l2 = lo;
    l2(axis) = t;
    const std::size_t next_stale = reduced ? 0 : stale + 1;
    const std::int32_t below = build(lo, h1, depth + 1, max_depth, next_stale);
    const std::int32_t above = build(l2, hi, depth + 1, max_depth, next_stale);
    splits_[s].below = below;
    splits_[s].above = above;
    return static_cast<std::int32_t>(s);
  }

  const Model* model_ = nullptr;
  bool ok_ = false;
  std::size_t depth_used_ = 0;
  std::size_t target_ = static_cast<std::size_t>(N) + 1;
  std::array<std::int32_t, kGridCells> cell_root_{};
  Vec cell_origin_ = Vec::Zero();
  Vec cell_scale_ = Vec::Zero();
  std::array<std::uint32_t, static_cast<std::size_t>(N)> cell_stride_{};
  VecD lo_ = VecD::Zero();
  VecD hi_ = VecD::Zero();
  std::array<Split, kMaxSplits> splits_{};
  std::array<Op, MaxBlockNodes> pool_{};
  std::array<Coef, MaxPieces> coef_{};
  std::size_t splits_used_ = 0;
  std::size_t blocks_used_ = 0;
  std::size_t pool_used_ = 0;
  std::size_t block_pieces_max_ = 0;
  std::size_t block_pieces_sum_ = 0;
  // Compile-time scratch: the ops of the block being emitted, the table that finds blocks with
  // the same ops (at most half full: a stored block has at least three ops), and per model
  // node bounds.
  static constexpr std::size_t kShareSlots = [] {
    std::size_t n = 1;
    while (n < MaxBlockNodes / 2 + 1) n *= 2;
    return n;
  }();
  static constexpr std::size_t kMaxShared = kShareSlots / 2;
  std::array<Op, Model::kMaxNodes> ops_{};
  std::array<std::uint32_t, kShareSlots> share_{};
  std::size_t shared_ = 0;
  std::array<double, Model::kMaxNodes> min_{};
  std::array<double, Model::kMaxNodes> max_{};
  std::array<Keep, Model::kMaxNodes> keep_{};
  std::array<std::size_t, Model::kMaxNodes> pieces_{};
};

}  // namespace boticelli::aln
