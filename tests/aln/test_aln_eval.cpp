// Tests of ALN evaluation: plain, alpha-beta, block, DTREE and fixed point agree, without
// allocating.
#include <array>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <span>

#include <Eigen/Core>

#include "algo/aln/aln.h"
#include "algo/aln/dtree.h"
#include "algo/aln/fixed_point.h"
#include "aln_test_util.h"
#include "alloc_guard.h"
#include "CppUTest/TestHarness.h"

namespace aln = boticelli::aln;

namespace {
using Model3 = aln::Aln<float, 3, 128>;
// A smaller grid and block capacity than the defaults keep the compile quick in Debug+ASan.
using Dtree3 = aln::Dtree<float, 3, 128, 2048, 32768, 64>;
Model3 g_model;
Dtree3 g_dtree;
aln::FixedPointAln<3, 128> g_fixed;
}  // namespace

TEST_GROUP(AlnEval){};

TEST(AlnEval, ASinglePieceIsTheLinearFunctionThroughItsCentroid) {
  aln::Aln<float, 2, 8> f;
  aln::Piece<float, 2> p;
  p.set(Eigen::Vector2f(1.0F, 2.0F), Eigen::Vector2f(1.0F, 0.5F), 3.0F);
  f.reset(p);
  // 3 + 1 (2 - 1) + 2 (1 - 0.5) = 5
  DOUBLES_EQUAL(5.0, f.evaluate(Eigen::Vector2f(2.0F, 1.0F)).value, 1e-6);
  DOUBLES_EQUAL(5.0, f.evaluate_alpha_beta(Eigen::Vector2f(2.0F, 1.0F)).value, 1e-6);
}

TEST(AlnEval, MinOfTwoMaxesPicksTheRightPiece) {
  // F(x) = MIN(MAX(x, -x), MAX(1 - x, 0.25)) on [-1, 1]
  aln::Aln<double, 1, 4> f;
  aln::Piece<double, 1> p0, p1, p2, p3;
  using V = Eigen::Matrix<double, 1, 1>;
  p0.set(V(1.0), V(0.0), 0.0);
  p1.set(V(-1.0), V(0.0), 0.0);
  p2.set(V(-1.0), V(0.0), 1.0);
  p3.set(V(0.0), V(0.0), 0.25);
  f.reset(p0);
  CHECK(f.split_piece(0, aln::NodeKind::kMin, p0, p2));  // MIN(p0, p2): p2 is piece 1
  CHECK(f.split_piece(0, aln::NodeKind::kMax, p0, p1));  // MIN(MAX(p0, p1'), p2)
  CHECK(f.split_piece(1, aln::NodeKind::kMax, p2, p3));
  LONGS_EQUAL(4, f.piece_count());
  // Pieces now: 0 = x, 1 = 1 - x, 2 = -x, 3 = 0.25.
  const auto at = [&](double x) { return f.evaluate(V(x)); };
  DOUBLES_EQUAL(0.8, at(-0.8).value, 1e-12);  // MIN(0.8, MAX(1.8, .25)) = 0.8 from -x
  LONGS_EQUAL(2, at(-0.8).piece);
  DOUBLES_EQUAL(0.3, at(0.3).value, 1e-12);  // MIN(0.3, 0.7)
  LONGS_EQUAL(0, at(0.3).piece);
  DOUBLES_EQUAL(0.25, at(0.9).value, 1e-12);  // MIN(0.9, MAX(0.1, 0.25))
  LONGS_EQUAL(3, at(0.9).piece);
  LONGS_EQUAL(3, f.depth());
}

TEST(AlnEval, AlphaBetaAndDtreeEqualPlainEvaluationOnManyRandomInputs) {
  aln_test::Rng rng(7);
  std::size_t total_ab = 0;
  std::size_t total_dt = 0;
  std::size_t total_plain = 0;
  constexpr int kModels = 4;
  constexpr int kPoints = 25000;  // 10^5 in all
  for (int m = 0; m < kModels; ++m) {
    static constexpr std::size_t kPieces[kModels] = {8, 16, 32, 48};
    aln_test::random_model(g_model, kPieces[m], rng);
    CHECK(g_dtree.compile(g_model));
    for (int k = 0; k < kPoints; ++k) {
      const auto x = aln_test::random_point<Model3::Vec>(rng);
      const auto plain = g_model.evaluate(x);
      const auto ab = g_model.evaluate_alpha_beta(x);
      const auto dt = g_dtree.evaluate(x);
      if (plain.value != ab.value || plain.piece != ab.piece || plain.value != dt.value ||
          plain.piece != dt.piece) {
        FAIL("alpha-beta or DTREE differs from plain evaluation");
      }
      total_plain += plain.pieces_evaluated;
      total_ab += ab.pieces_evaluated;
      total_dt += dt.pieces_evaluated;
    }
  }
  CHECK(total_ab < total_plain);
  CHECK(total_dt < total_ab);
}

namespace {
// Checks every lane of evaluate_block() against evaluate() over blocks of 1..kBlock random
// points: the lane's value, and its piece, which must give that value there and, unless
// another piece gives it within the tolerance (a tie the two summations may break apart), be
// plain evaluation's piece. Lanes beyond the block's count are not written.
template <typename Model>
void check_block_against_plain(Model& model, aln_test::Rng& rng, int blocks, double tol) {
  using Scalar = typename Model::ScalarType;
  constexpr std::size_t kB = Model::kBlock;
  for (int b = 0; b < blocks; ++b) {
    const std::size_t count = 1 + static_cast<std::size_t>(b) % kB;
    std::array<typename Model::Vec, kB> x;
    for (auto& xi : x) xi = aln_test::random_point<typename Model::Vec>(rng);
    std::array<Scalar, kB> value;
    std::array<std::uint16_t, kB> piece;
    value.fill(Scalar(-99));
    piece.fill(0xFFFF);
    LONGS_EQUAL(count, model.evaluate_block(std::span<const typename Model::Vec>(x.data(), count),
                                            value, piece));
    for (std::size_t k = 0; k < kB; ++k) {
      if (k >= count) {
        CHECK(value[k] == Scalar(-99) && piece[k] == 0xFFFF);
        continue;
      }
      const auto plain = model.evaluate(x[k]);
      DOUBLES_EQUAL(plain.value, value[k], tol);
      CHECK(piece[k] < model.piece_count());
      DOUBLES_EQUAL(plain.value, model.piece(piece[k]).value(x[k]), tol);
      const bool tie = piece[k] != plain.piece &&
                       std::fabs(static_cast<double>(model.piece(plain.piece).value(x[k]) -
                                                     model.piece(piece[k]).value(x[k]))) <= tol;
      if (piece[k] != plain.piece && !tie) FAIL("block evaluation names another piece");
    }
  }
}
}  // namespace

TEST(AlnEval, BlockEvaluationGivesEveryLaneThePlainValueAndItsPiece) {
  aln_test::Rng rng(21);
  for (const std::size_t pieces :
       {std::size_t{1}, std::size_t{2}, std::size_t{9}, std::size_t{32}, std::size_t{100}}) {
    aln_test::random_model(g_model, pieces, rng);
    check_block_against_plain(g_model, rng, 2000, 1e-5);
  }
  aln::Aln<double, 1, 16> one;
  aln_test::random_model(one, 16, rng);
  check_block_against_plain(one, rng, 500, 1e-12);
  aln::Aln<float, 4, 16> four;
  aln_test::random_model(four, 16, rng);
  check_block_against_plain(four, rng, 500, 1e-5);
  // An empty block writes nothing.
  std::array<float, Model3::kBlock> v{};
  std::array<std::uint16_t, Model3::kBlock> p{};
  LONGS_EQUAL(0, g_model.evaluate_block(std::span<const Model3::Vec>(), v, p));
}

TEST(AlnEval, AlphaBetaWithAHintGivesTheSameValueAndCutsMoreOnARay) {
  aln_test::Rng rng(31);
  aln_test::random_model(g_model, 48, rng);
  std::size_t with_hint = 0;
  std::size_t without = 0;
  std::size_t same_piece = 0;
  constexpr int kRays = 200;
  constexpr int kSteps = 50;
  for (int ray = 0; ray < kRays; ++ray) {
    Model3::Vec x = aln_test::random_point<Model3::Vec>(rng);
    std::uint16_t hint = 0xFFFF;  // no hint for the first point
    for (int k = 0; k < kSteps; ++k) {
      x(2) = static_cast<float>(k) / kSteps;
      const auto plain = g_model.evaluate(x);
      const auto hinted = g_model.evaluate_alpha_beta(x, hint);
      CHECK(plain.value == hinted.value);
      if (plain.piece == hinted.piece) ++same_piece;
      with_hint += hinted.pieces_evaluated;
      without += g_model.evaluate_alpha_beta(x).pieces_evaluated;
      hint = hinted.piece;
    }
  }
  LONGS_EQUAL(kRays * kSteps, same_piece);  // no exact ties on random inputs
  CHECK(with_hint < without);
}

TEST(AlnEval, DtreeKeepsAboutTwoPiecesPerBlockOrNPlusOneWithTheThesisSetting) {
  aln_test::Rng rng(11);
  aln_test::random_model(g_model, 32, rng);
  CHECK(g_dtree.compile(g_model));
  CHECK(g_dtree.block_count() > 1);
  CHECK(g_dtree.mean_block_pieces() <= 2.5);
  CHECK(g_dtree.compile(g_model, 10, 4));
  CHECK(g_dtree.mean_block_pieces() > 2.5);
  CHECK(g_dtree.mean_block_pieces() <= 4.5);
}

TEST(AlnEval, DtreeBlocksWithTheSameOpsShareThem) {
  aln_test::Rng rng(19);
  aln_test::random_model(g_model, 32, rng);
  // Few ops for this many blocks: it compiles at full depth only because blocks share ops.
  static aln::Dtree<float, 3, 128, 2048, 1024, 64> d;
  CHECK(d.compile(g_model, 8));
  LONGS_EQUAL(8, d.depth_used());
  // Unshared, every block of p > 1 pieces would take 2p - 1 ops.
  const double pieces = d.mean_block_pieces() * static_cast<double>(d.block_count());
  const double unshared_at_least = 2.0 * (pieces - static_cast<double>(d.block_count()));
  CHECK(static_cast<double>(d.node_count()) * 4.0 < unshared_at_least);
  for (int k = 0; k < 20000; ++k) {
    const auto x = aln_test::random_point<Model3::Vec>(rng);
    const auto plain = g_model.evaluate(x);
    const auto dt = d.evaluate(x);
    if (plain.value != dt.value || plain.piece != dt.piece) FAIL("DTREE differs from plain");
  }
}

TEST(AlnEval, DtreeGivesNaNForANaNInput) {
  aln_test::Rng rng(19);
  aln_test::random_model(g_model, 32, rng);
  CHECK(g_dtree.compile(g_model));
  const float nan = std::numeric_limits<float>::quiet_NaN();
  for (int i = 0; i < 3; ++i) {
    Model3::Vec x(0.5F, 0.5F, 0.5F);
    x(i) = nan;
    CHECK(std::isnan(g_dtree.evaluate(x).value));
  }
}

TEST(AlnEval, DtreeWithSmallCapacityCompilesShallowerAndStaysExact) {
  aln_test::Rng rng(13);
  aln_test::random_model(g_model, 48, rng);
  static aln::Dtree<float, 3, 128, 100, 8192, 64> small;
  CHECK(small.compile(g_model, 10));
  CHECK(small.depth_used() < 10);
  for (int k = 0; k < 5000; ++k) {
    const auto x = aln_test::random_point<Model3::Vec>(rng);
    const auto plain = g_model.evaluate(x);
    const auto dt = small.evaluate(x);
    CHECK(plain.value == dt.value);
    LONGS_EQUAL(plain.piece, dt.piece);
  }
  // Too few block nodes for even one block per cell: refused, and evaluation says so.
  static aln::Dtree<float, 3, 128, 100, 64, 64> tiny;
  CHECK_FALSE(tiny.compile(g_model));
  CHECK_FALSE(tiny.valid());
  CHECK(std::isnan(tiny.evaluate(Model3::Vec(0.5F, 0.5F, 0.5F)).value));
}

TEST(AlnEval, DtreeAndAlphaBetaWorkInDoubleAndOneDimension) {
  aln_test::Rng rng(3);
  static aln::Aln<double, 1, 16> f;
  static aln::Dtree<double, 1, 16> d;
  aln_test::random_model(f, 16, rng);
  CHECK(d.compile(f));
  for (int k = 0; k < 5000; ++k) {
    const auto x = aln_test::random_point<Eigen::Matrix<double, 1, 1>>(rng);
    const auto plain = f.evaluate(x);
    CHECK(plain.value == f.evaluate_alpha_beta(x).value);
    CHECK(plain.value == d.evaluate(x).value);
    LONGS_EQUAL(plain.piece, d.evaluate(x).piece);
  }
}

TEST(AlnEval, FixedPointMatchesFloatWithinItsResolution) {
  aln_test::Rng rng(5);
  aln_test::random_model(g_model, 32, rng);
  CHECK(g_fixed.compile(g_model));
  CHECK(g_fixed.weight_frac_bits() >= 20);
  double worst = 0.0;
  for (int k = 0; k < 20000; ++k) {
    const auto x = aln_test::random_point<Model3::Vec>(rng);
    aln::FixedPointAln<3, 128>::Input xq{};
    for (int i = 0; i < 3; ++i) {
      xq[static_cast<std::size_t>(i)] = aln::FixedPointAln<3, 128>::to_fixed(x(i));
    }
    const double fixed = aln::FixedPointAln<3, 128>::to_double(g_fixed.evaluate(xq).value);
    const double ref = static_cast<double>(g_model.evaluate(x).value);
    worst = std::fmax(worst, std::fabs(fixed - ref));
  }
  CHECK_TEXT(worst < 1e-4, "fixed point differs from float by more than 1e-4");
}

TEST(AlnEval, FixedPointRefusesAModelBeyondQ16Range) {
  aln::Aln<float, 1, 2> f;
  f.set_input_range(0, 0.0F, 1e6F);
  CHECK_FALSE((aln::FixedPointAln<1, 2>{}.compile(f)));
}

TEST(AlnEval, EvaluationDoesNotAllocate) {
  aln_test::Rng rng(9);
  aln_test::random_model(g_model, 64, rng);
  CHECK(g_dtree.compile(g_model));
  CHECK(g_fixed.compile(g_model));
  float sum = 0.0F;
  std::array<Model3::Vec, 3> xs;  // a block of three
  std::array<float, Model3::kBlock> v{};
  std::array<std::uint16_t, Model3::kBlock> p{};
  CHECK_NO_ALLOCATION({
    for (int k = 0; k < 1000; ++k) {
      const auto x = aln_test::random_point<Model3::Vec>(rng);
      sum += g_model.evaluate(x).value + g_model.evaluate_alpha_beta(x).value +
             g_dtree.evaluate(x).value;
      sum += static_cast<float>(g_fixed.evaluate({0, 65536, 32768}).value);
      xs.fill(x);
      sum += static_cast<float>(g_model.evaluate_block(xs, v, p)) * v[2];
    }
  });
  CHECK_NO_ALLOCATION(CHECK(g_dtree.compile(g_model)));
  CHECK(std::isfinite(sum));
}

TEST(AlnEval, AssignRejectsNodesThatAreNotOneTree) {
  aln::Aln<float, 1, 4> f;
  using Node = aln::Aln<float, 1, 4>::Node;
  aln::Piece<float, 1> pieces[2];
  const Node cycle[3] = {
      {aln::NodeKind::kMin, 1, 0}, {aln::NodeKind::kPiece, 0, 0}, {aln::NodeKind::kPiece, 1, 0}};
  CHECK_FALSE(f.assign(cycle, pieces));
  const Node reused[3] = {
      {aln::NodeKind::kMin, 1, 2}, {aln::NodeKind::kPiece, 0, 0}, {aln::NodeKind::kPiece, 0, 0}};
  CHECK_FALSE(f.assign(reused, pieces));
  const Node good[3] = {
      {aln::NodeKind::kMin, 1, 2}, {aln::NodeKind::kPiece, 0, 0}, {aln::NodeKind::kPiece, 1, 0}};
  CHECK(f.assign(good, pieces));
  LONGS_EQUAL(2, f.piece_count());
}
