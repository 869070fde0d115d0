// Adaptive Logic Network: a MIN/MAX tree over linear pieces, y = F(x), x in R^N (thesis Eq 4.26).
#pragma once

#include <algorithm>
#include <array>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <span>

#include <Eigen/Core>

namespace boticelli::aln {

// What a tree node does: hold a linear piece, or take the MIN or MAX of its two children.
enum class NodeKind : std::uint8_t { kPiece = 0, kMin = 1, kMax = 2 };

// A closed interval of one variable, in that variable's own units.
template <typename Scalar>
struct Range {
  Scalar lo = Scalar(0);
  Scalar hi = Scalar(1);
};

// One linear piece (thesis Eq 5.5 form): y = centroid_output + sum_i weight_i (x_i - centroid_i).
// The centroid is a point on the piece (roughly the middle of the samples it fits); the
// bias is derived from it, bias = centroid_output - weight . centroid, so a piece read back
// from text is bit-identical to the one written.
template <typename Scalar, int N>
struct Piece {
  using Vec = Eigen::Matrix<Scalar, N, 1>;
  Vec weight = Vec::Zero();    // dy/dx_i, output units per input unit
  Vec centroid = Vec::Zero();  // input part of a point on the piece
  Scalar centroid_output = Scalar(0);
  Scalar bias = Scalar(0);  // derived, see set()

  void set(const Vec& w, const Vec& c, Scalar cy) {
    weight = w;
    centroid = c;
    centroid_output = cy;
    bias = cy - w.dot(c);
  }
  [[nodiscard]] Scalar value(const Vec& x) const { return bias + weight.dot(x); }
};

// The result of an evaluation: the value, the responsible (active) piece, and how many
// pieces were evaluated to get it (the cost measure of alpha-beta and DTREE).
template <typename Scalar>
struct EvalResult {
  Scalar value = Scalar(0);
  std::uint16_t piece = 0;
  std::uint16_t pieces_evaluated = 0;
};

// The ALN function. Scalar is float or double, N the input dimension (1..4 tested),
// MaxPieces the capacity. All storage is inside the object: nothing allocates, ever.
// The tree has node 0 as root; a kPiece node's `a` is a piece index, a kMin/kMax node's
// `a` and `b` are its children's node indices. Every piece is used by exactly one node.
// Input ranges (a box per input) and the output range are part of the function
// (thesis Figure 5.4); weight bounds are the training constraints (Eqs 4.27-4.28).
template <typename Scalar, int N, std::size_t MaxPieces>
class Aln {
  static_assert(N >= 1 && N <= 8, "ALN input dimension 1..8");
  static_assert(MaxPieces >= 1 && MaxPieces <= 16384, "piece capacity 1..16384");
  static_assert(std::numeric_limits<Scalar>::is_iec559, "float or double");

 public:
  static constexpr int kInputs = N;
  static constexpr std::size_t kMaxPieces = MaxPieces;
  static constexpr std::size_t kMaxNodes = 2 * MaxPieces - 1;
  using ScalarType = Scalar;
  using Vec = Eigen::Matrix<Scalar, N, 1>;
  using PieceType = Piece<Scalar, N>;
  struct Node {
    NodeKind kind = NodeKind::kPiece;
    std::uint16_t a = 0;
    std::uint16_t b = 0;
  };
  // One step of evaluating the tree children before parents: push a piece's value, or
  // replace the top two values by their MIN or MAX.
  struct Op {
    NodeKind kind = NodeKind::kPiece;
    std::uint16_t piece = 0;  // for kPiece
  };

  // One flat piece y = 0, inputs and output on [0, 1], weights unbounded.
  Aln() {
    for (int i = 0; i < N; ++i) {
      weight_lo_[static_cast<std::size_t>(i)] = -std::numeric_limits<Scalar>::infinity();
      weight_hi_[static_cast<std::size_t>(i)] = std::numeric_limits<Scalar>::infinity();
    }
    reset(PieceType{});
  }

  // --- Ranges and constraints -------------------------------------------------------
  void set_input_range(int i, Scalar lo, Scalar hi) { input_range_[idx(i)] = {lo, hi}; }
  void set_output_range(Scalar lo, Scalar hi) { output_range_ = {lo, hi}; }
  [[nodiscard]] Range<Scalar> input_range(int i) const { return input_range_[idx(i)]; }
  [[nodiscard]] Range<Scalar> output_range() const { return output_range_; }
  // Every piece's weight on input i must lie in [lo, hi] (Eqs 4.27-4.28: monotone
  // increasing in r is lo > 0, e.g. 1e-4; |a| < 1 is [-1, 1]). Infinite means unbounded.
  void set_weight_bounds(int i, Scalar lo, Scalar hi) {
    weight_lo_[idx(i)] = lo;
    weight_hi_[idx(i)] = hi;
  }
  [[nodiscard]] Scalar weight_lo(int i) const { return weight_lo_[idx(i)]; }
  [[nodiscard]] Scalar weight_hi(int i) const { return weight_hi_[idx(i)]; }
  // True if every piece's weights are inside their bounds.
  [[nodiscard]] bool pieces_within_bounds() const {
    for (std::size_t p = 0; p < piece_count_; ++p) {
      for (int i = 0; i < N; ++i) {
        const Scalar w = pieces_[p].weight(i);
        if (!(w >= weight_lo_[idx(i)] && w <= weight_hi_[idx(i)])) return false;
      }
    }
    return true;
  }

  // --- Structure ----------------------------------------------------------------------
  // Makes the function a single piece.
  void reset(const PieceType& piece) {
    pieces_[0] = piece;
    piece_count_ = 1;
    nodes_[0] = Node{NodeKind::kPiece, 0, 0};
    node_count_ = 1;
    piece_node_[0] = 0;
    post_order_[0] = 0;
    ops_[0] = Op{NodeKind::kPiece, 0};
    depth_ = 1;
  }
  // Replaces the leaf holding piece `p` by kind(first, second): `first` keeps index p,
  // `second` gets index piece_count()-1. False (nothing changed) if full or bad arguments.
  bool split_piece(std::size_t p, NodeKind kind, const PieceType& first, const PieceType& second) {
    if (p >= piece_count_ || kind == NodeKind::kPiece || piece_count_ >= MaxPieces) {
      return false;
    }
    const std::size_t leaf = piece_node_[p];
    const std::size_t n1 = node_count_;
    const std::size_t n2 = node_count_ + 1;
    const std::size_t q = piece_count_;
    pieces_[p] = first;
    pieces_[q] = second;
    nodes_[n1] = Node{NodeKind::kPiece, static_cast<std::uint16_t>(p), 0};
    nodes_[n2] = Node{NodeKind::kPiece, static_cast<std::uint16_t>(q), 0};
    nodes_[leaf] = Node{kind, static_cast<std::uint16_t>(n1), static_cast<std::uint16_t>(n2)};
    piece_node_[p] = n1;
    piece_node_[q] = n2;
    node_count_ += 2;
    piece_count_ += 1;
    return finish_structure();
  }
  // Sets the whole tree at once (reader, inversion, pruning). Checks that the nodes form
  // one tree rooted at node 0 that uses every piece exactly once; false (and the function
  // unchanged) otherwise. Never recurses, so hostile input cannot exhaust the stack.
  bool assign(std::span<const Node> nodes, std::span<const PieceType> pieces) {
    if (nodes.empty() || nodes.size() > kMaxNodes || pieces.empty() || pieces.size() > MaxPieces ||
        nodes.size() != 2 * pieces.size() - 1) {
      return false;
    }
    // Validate before touching our own storage.
    std::array<std::uint8_t, kMaxNodes> seen_node{};
    std::array<std::uint8_t, MaxPieces> seen_piece{};
    std::array<std::uint16_t, kMaxNodes> stack{};
    std::size_t top = 0;
    stack[top++] = 0;
    std::size_t visited = 0;
    while (top > 0) {
      const std::size_t n = stack[--top];
      if (seen_node[n] != 0) return false;
      seen_node[n] = 1;
      ++visited;
      const Node& node = nodes[n];
      if (node.kind == NodeKind::kPiece) {
        if (node.a >= pieces.size() || seen_piece[node.a] != 0) return false;
        seen_piece[node.a] = 1;
      } else if (node.kind == NodeKind::kMin || node.kind == NodeKind::kMax) {
        if (node.a >= nodes.size() || node.b >= nodes.size() || top + 2 > kMaxNodes) {
          return false;
        }
        stack[top++] = node.a;
        stack[top++] = node.b;
      } else {
        return false;
      }
    }
    if (visited != nodes.size()) return false;
    for (std::size_t i = 0; i < nodes.size(); ++i) nodes_[i] = nodes[i];
    for (std::size_t i = 0; i < pieces.size(); ++i) pieces_[i] = pieces[i];
    node_count_ = nodes.size();
    piece_count_ = pieces.size();
    for (std::size_t i = 0; i < node_count_; ++i) {
      if (nodes_[i].kind == NodeKind::kPiece) piece_node_[nodes_[i].a] = i;
    }
    return finish_structure();
  }

  [[nodiscard]] std::size_t piece_count() const { return piece_count_; }
  [[nodiscard]] std::size_t node_count() const { return node_count_; }
  // Longest root-to-piece path, counted in nodes.
  [[nodiscard]] std::size_t depth() const { return depth_; }
  [[nodiscard]] const PieceType& piece(std::size_t i) const { return pieces_[i]; }
  PieceType& piece(std::size_t i) { return pieces_[i]; }
  [[nodiscard]] const Node& node(std::size_t i) const { return nodes_[i]; }
  [[nodiscard]] std::span<const Node> nodes() const { return {nodes_.data(), node_count_}; }
  [[nodiscard]] std::span<const PieceType> pieces() const { return {pieces_.data(), piece_count_}; }
  // Node indices, children before their parent (root last).
  [[nodiscard]] std::span<const std::uint16_t> post_order() const {
    return {post_order_.data(), node_count_};
  }
  // The tree as evaluation steps in post order (what evaluate() runs), for evaluators that
  // work on many inputs at once.
  [[nodiscard]] std::span<const Op> ops() const { return {ops_.data(), node_count_}; }
  // Node index of the leaf holding piece p.
  [[nodiscard]] std::size_t node_of_piece(std::size_t p) const { return piece_node_[p]; }

  // --- Evaluation ---------------------------------------------------------------------
  // Plain evaluation: every piece, children before parents (post order), no recursion.
  // Ties go to the first child, so all evaluators agree on the responsible piece.
  [[nodiscard]] EvalResult<Scalar> evaluate(const Vec& x) const {
    std::array<Scalar, MaxPieces> value;  // a stack; only entries below `top` are read
    std::array<std::uint16_t, MaxPieces> who;
    std::size_t top = 0;
    for (std::size_t k = 0; k < node_count_; ++k) {
      const Op op = ops_[k];
      if (op.kind == NodeKind::kPiece) {
        value[top] = pieces_[op.piece].value(x);
        who[top] = op.piece;
        ++top;
      } else {
        --top;
        const Scalar second = value[top];
        const Scalar first = value[top - 1];
        const bool take_second = op.kind == NodeKind::kMax ? second > first : second < first;
        value[top - 1] = take_second ? second : first;
        who[top - 1] = take_second ? who[top] : who[top - 1];
      }
    }
    return {value[0], who[0], static_cast<std::uint16_t>(piece_count_)};
  }

  // Alpha-beta evaluation: same value and piece as evaluate(), but a MAX node skips its
  // second child once the first reaches the bound of a MIN ancestor (and vice versa).
  // Recursion depth is at most depth() <= piece capacity.
  [[nodiscard]] EvalResult<Scalar> evaluate_alpha_beta(const Vec& x) const {
    EvalResult<Scalar> r{};
    std::uint16_t touched = 0;
    r.value = ab(0, x, -std::numeric_limits<Scalar>::infinity(),
                 std::numeric_limits<Scalar>::infinity(), r.piece, touched);
    r.pieces_evaluated = touched;
    return r;
  }

  // Alpha-beta with a hint: the piece responsible for a nearby earlier query (e.g. the
  // previous point on a ray). The hint's branch is evaluated first at every node on its
  // path, so when the hint is still responsible most other branches are cut off.
  // Same value as evaluate(); at an exact tie between two pieces it may name the other one.
  // An out-of-range hint means no hint.
  [[nodiscard]] EvalResult<Scalar> evaluate_alpha_beta(const Vec& x, std::uint16_t hint) const {
    if (hint >= piece_count_) return evaluate_alpha_beta(x);
    std::array<std::uint16_t, MaxPieces> path;  // path[0] the hint's leaf ... root
    std::size_t len = 0;
    std::size_t n = piece_node_[hint];
    while (len < MaxPieces) {
      path[len++] = static_cast<std::uint16_t>(n);
      if (n == 0) break;
      n = parent_[n];
    }
    EvalResult<Scalar> r{};
    std::uint16_t touched = 0;
    r.value = ab_hint(len - 1, path.data(), x, -std::numeric_limits<Scalar>::infinity(),
                      std::numeric_limits<Scalar>::infinity(), r.piece, touched);
    r.pieces_evaluated = touched;
    return r;
  }

  [[nodiscard]] Scalar operator()(const Vec& x) const { return evaluate_alpha_beta(x).value; }

  // Block evaluation: kBlock inputs at once, every piece on every lane in fixed-size Eigen
  // arrays (SSE on x86-64, NEON on aarch64 through the same code), children before parents
  // with branch-free MIN/MAX per lane. Same values and pieces as evaluate() (ties to the first
  // child; each piece's value summed in the order Piece::value sums it). For passes over
  // many samples (training) and rays; a lone query is cheaper by evaluate_alpha_beta().
  static constexpr std::size_t kBlock = 16;
  using Lanes = Eigen::Array<Scalar, static_cast<int>(kBlock), 1>;
  // Writes value[k] and piece[k] for k < count = min(x.size(), kBlock, value.size(),
  // piece.size()); returns count. Its stack holds 2 x MaxPieces x kBlock Scalars (32 KB for
  // 256 float pieces).
  std::size_t evaluate_block(std::span<const Vec> x, std::span<Scalar> value,
                             std::span<std::uint16_t> piece) const {
    const std::size_t count =
        std::min(std::min(x.size(), kBlock), std::min(value.size(), piece.size()));
    if (count == 0) return 0;
    std::array<Lanes, static_cast<std::size_t>(N)> in;
    for (int i = 0; i < N; ++i) {
      for (std::size_t k = 0; k < kBlock; ++k) {
        in[idx(i)](static_cast<Eigen::Index>(k)) = k < count ? x[k](i) : Scalar(0);
      }
    }
    // A stack, as in evaluate(); piece indices are carried as Scalar (exact below 2^24) so
    // the selects are one type.
    std::array<Lanes, MaxPieces> val;
    std::array<Lanes, MaxPieces> who;
    std::size_t top = 0;
    for (std::size_t k = 0; k < node_count_; ++k) {
      const Op op = ops_[k];
      if (op.kind == NodeKind::kPiece) {
        const PieceType& p = pieces_[op.piece];
        val[top] = p.bias + dot_lanes<0, N>(p.weight, in);
        who[top] = Lanes::Constant(static_cast<Scalar>(op.piece));
        ++top;
        continue;
      }
      --top;
      if (op.kind == NodeKind::kMax) {
        take_second<true>(val[top - 1], who[top - 1], val[top], who[top]);
      } else {
        take_second<false>(val[top - 1], who[top - 1], val[top], who[top]);
      }
    }
    for (std::size_t k = 0; k < count; ++k) {
      value[k] = val[0](static_cast<Eigen::Index>(k));
      piece[k] = static_cast<std::uint16_t>(who[0](static_cast<Eigen::Index>(k)));
    }
    return count;
  }

 private:
  static std::size_t idx(int i) { return static_cast<std::size_t>(i); }

  // first = MAX (or MIN) of first and second per lane, who following; ties (and NaN) keep
  // first, as evaluate(). Eigen's packet compare and bitwise select (SSE, NEON; a scalar
  // fallback where Eigen does not vectorise), so no lane branches.
  template <bool kMaxNode>
  static void take_second(Lanes& first, Lanes& who_first, const Lanes& second,
                          const Lanes& who_second) {
    namespace ei = Eigen::internal;
    using Packet = typename ei::packet_traits<Scalar>::type;
    constexpr auto kStep = static_cast<std::size_t>(ei::packet_traits<Scalar>::size);
    static_assert(kBlock % kStep == 0, "whole packets per block");
    for (std::size_t k = 0; k < kBlock; k += kStep) {
      const Packet f = ei::ploadu<Packet>(first.data() + k);
      const Packet s = ei::ploadu<Packet>(second.data() + k);
      const Packet take = kMaxNode ? ei::pcmp_lt(f, s) : ei::pcmp_lt(s, f);
      ei::pstoreu(first.data() + k, ei::pselect(take, s, f));
      ei::pstoreu(who_first.data() + k, ei::pselect(take, ei::ploadu<Packet>(who_second.data() + k),
                                                    ei::ploadu<Packet>(who_first.data() + k)));
    }
  }

  // sum_i w_i x_i over inputs [Start, Start + Len) on every lane, halves summed as Eigen's
  // fixed-size dot product sums them (w_0 x_0 + (w_1 x_1 + w_2 x_2) for N = 3), so a lane's
  // value is bit-identical to Piece::value where the compiler contracts neither into FMAs.
  template <int Start, int Len>
  static auto dot_lanes(const Vec& w, const std::array<Lanes, static_cast<std::size_t>(N)>& in) {
    if constexpr (Len == 1) {
      return w(Start) * in[static_cast<std::size_t>(Start)];
    } else {
      constexpr int kHalf = Len / 2;
      return dot_lanes<Start, kHalf>(w, in) + dot_lanes<Start + kHalf, Len - kHalf>(w, in);
    }
  }

  // Value of the subtree at node n, exact if it lies in (lo, hi), else some value on the
  // same side of the window (which the ancestors then ignore). Leaf children are
  // evaluated in place rather than by a call.
  Scalar child(std::uint16_t n, const Vec& x, Scalar lo, Scalar hi, std::uint16_t& piece,
               std::uint16_t& touched) const {
    const Node& node = nodes_[n];
    if (node.kind == NodeKind::kPiece) {
      piece = node.a;
      ++touched;
      return pieces_[node.a].value(x);
    }
    return ab(n, x, lo, hi, piece, touched);
  }

  Scalar ab(std::size_t n, const Vec& x, Scalar lo, Scalar hi, std::uint16_t& piece,
            std::uint16_t& touched) const {
    const Node& node = nodes_[n];
    if (node.kind == NodeKind::kPiece) {
      piece = node.a;
      ++touched;
      return pieces_[node.a].value(x);
    }
    std::uint16_t p1 = 0;
    const Scalar v1 = child(node.a, x, lo, hi, p1, touched);
    std::uint16_t p2 = 0;
    if (node.kind == NodeKind::kMax) {
      // A MIN ancestor will not take anything >= hi.
      if (v1 < hi) {
        const Scalar v2 = child(node.b, x, v1 > lo ? v1 : lo, hi, p2, touched);
        if (v2 > v1) {
          piece = p2;
          return v2;
        }
      }
    } else {
      // A MAX ancestor will not take anything <= lo.
      if (v1 > lo) {
        const Scalar v2 = child(node.b, x, lo, v1 < hi ? v1 : hi, p2, touched);
        if (v2 < v1) {
          piece = p2;
          return v2;
        }
      }
    }
    piece = p1;
    return v1;
  }

  // Like ab() for node path[i], whose child path[i - 1] is evaluated first.
  Scalar ab_hint(std::size_t i, const std::uint16_t* path, const Vec& x, Scalar lo, Scalar hi,
                 std::uint16_t& piece, std::uint16_t& touched) const {
    const Node& node = nodes_[path[i]];
    if (node.kind == NodeKind::kPiece || i == 0) return ab(path[i], x, lo, hi, piece, touched);
    const bool first_is_a = path[i - 1] == node.a;
    const std::uint16_t other = first_is_a ? node.b : node.a;
    std::uint16_t p1 = 0;
    const Scalar v1 = ab_hint(i - 1, path, x, lo, hi, p1, touched);
    std::uint16_t p2 = 0;
    if (node.kind == NodeKind::kMax) {
      if (v1 < hi) {
        const Scalar v2 = child(other, x, v1 > lo ? v1 : lo, hi, p2, touched);
        if (v2 > v1) {
          piece = p2;
          return v2;
        }
      }
    } else {
      if (v1 > lo) {
        const Scalar v2 = child(other, x, lo, v1 < hi ? v1 : hi, p2, touched);
        if (v2 < v1) {
          piece = p2;
          return v2;
        }
      }
    }
    piece = p1;
    return v1;
  }

  // Recomputes the post order and the depth (iteratively).
  bool finish_structure() {
    struct Frame {
      std::uint16_t node;
      std::uint16_t depth;
      bool expanded;
    };
    std::array<Frame, kMaxNodes> stack{};
    std::size_t top = 0;
    std::size_t k = 0;
    depth_ = 0;
    stack[top++] = Frame{0, 1, false};
    while (top > 0) {
      Frame& f = stack[top - 1];
      const Node& n = nodes_[f.node];
      if (f.depth > depth_) depth_ = f.depth;
      if (n.kind == NodeKind::kPiece || f.expanded) {
        ops_[k] = Op{n.kind, n.kind == NodeKind::kPiece ? n.a : std::uint16_t{0}};
        post_order_[k++] = f.node;
        --top;
        continue;
      }
      f.expanded = true;
      const auto d = static_cast<std::uint16_t>(f.depth + 1);
      parent_[n.a] = f.node;
      parent_[n.b] = f.node;
      stack[top++] = Frame{n.b, d, false};
      stack[top++] = Frame{n.a, d, false};
    }
    return k == node_count_;
  }

  std::array<PieceType, MaxPieces> pieces_{};
  std::array<Node, kMaxNodes> nodes_{};
  std::array<std::size_t, MaxPieces> piece_node_{};
  std::array<std::uint16_t, kMaxNodes> post_order_{};
  std::array<std::uint16_t, kMaxNodes> parent_{};  // parent_[0] = 0
  std::array<Op, kMaxNodes> ops_{};                // post order, for evaluate()
  std::array<Range<Scalar>, static_cast<std::size_t>(N)> input_range_{};
  Range<Scalar> output_range_{};
  std::array<Scalar, static_cast<std::size_t>(N)> weight_lo_{};
  std::array<Scalar, static_cast<std::size_t>(N)> weight_hi_{};
  std::size_t piece_count_ = 1;
  std::size_t node_count_ = 1;
  std::size_t depth_ = 1;
};

}  // namespace boticelli::aln
