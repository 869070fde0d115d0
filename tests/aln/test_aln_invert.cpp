// Tests of ALN inversion in a monotone input (thesis §5.4.1).
#include <cmath>
#include <cstddef>
#include <limits>

#include <Eigen/Core>

#include "algo/aln/aln.h"
#include "algo/aln/invert.h"
#include "aln_test_util.h"
#include "alloc_guard.h"
#include "CppUTest/TestHarness.h"

namespace aln = boticelli::aln;

namespace {
using Model = aln::Aln<double, 3, 64>;
Model g_f;
Model g_inv;
Model g_back;
}  // namespace

TEST_GROUP(AlnInvert){};

TEST(AlnInvert, TheInverseUndoesTheFunctionOnRandomInputs) {
  aln_test::Rng rng(13);
  for (int m = 0; m < 5; ++m) {
    aln_test::random_model(g_f, 8 + static_cast<std::size_t>(m) * 12, rng, 2);
    CHECK(aln::invert(g_f, 2, g_inv));
    LONGS_EQUAL(g_f.piece_count(), g_inv.piece_count());
    for (int k = 0; k < 4000; ++k) {
      const auto x = aln_test::random_point<Model::Vec>(rng);
      const double y = g_f.evaluate(x).value;
      // r = F^-1(alpha, h, m): input 2 of the inverse is the former output.
      Model::Vec q = x;
      q(2) = y;
      const double r = g_inv.evaluate(q).value;
      DOUBLES_EQUAL(x(2), r, 1e-9);  // F strictly increasing in x2, so r is x2 itself
      Model::Vec back = x;
      back(2) = r;
      DOUBLES_EQUAL(y, g_f.evaluate(back).value, 1e-9);  // F(x, F^-1(x, m)) = m
    }
  }
}

TEST(AlnInvert, ADecreasingVariableKeepsTheNodeKinds) {
  aln_test::Rng rng(17);
  aln_test::random_model(g_f, 16, rng, 1);
  for (std::size_t p = 0; p < g_f.piece_count(); ++p) {
    aln::Piece<double, 3>& piece = g_f.piece(p);
    Model::Vec w = piece.weight;
    w(1) = -w(1);
    piece.set(w, piece.centroid, piece.centroid_output);
  }
  CHECK(aln::invert(g_f, 1, g_inv));
  for (std::size_t n = 0; n < g_f.node_count(); ++n) {
    CHECK(g_f.node(n).kind == g_inv.node(n).kind);
  }
  for (int k = 0; k < 2000; ++k) {
    const auto x = aln_test::random_point<Model::Vec>(rng);
    Model::Vec q = x;
    q(1) = g_f.evaluate(x).value;
    DOUBLES_EQUAL(x(1), g_inv.evaluate(q).value, 1e-9);
  }
}

TEST(AlnInvert, InvertingTwiceGivesTheSameFunction) {
  aln_test::Rng rng(19);
  aln_test::random_model(g_f, 40, rng, 0);
  CHECK(aln::invert(g_f, 0, g_inv));
  CHECK(aln::invert(g_inv, 0, g_back));
  for (std::size_t p = 0; p < g_f.piece_count(); ++p) {
    CHECK(g_f.piece(p).weight.isApprox(g_back.piece(p).weight, 1e-12));
    CHECK(g_f.piece(p).centroid == g_back.piece(p).centroid);
  }
  for (std::size_t n = 0; n < g_f.node_count(); ++n) {
    CHECK(g_f.node(n).kind == g_back.node(n).kind);
  }
  CHECK(g_back.input_range(0).lo == g_f.input_range(0).lo);
  CHECK(g_back.output_range().hi == g_f.output_range().hi);
  for (int k = 0; k < 5000; ++k) {
    const auto x = aln_test::random_point<Model::Vec>(rng);
    DOUBLES_EQUAL(g_f.evaluate(x).value, g_back.evaluate(x).value, 1e-12);
  }
}

TEST(AlnInvert, RangesAndBoundsMoveWithTheirVariables) {
  Model f;
  f.set_input_range(0, -3.0, 3.0);
  f.set_input_range(1, 0.0, 20.0);
  f.set_input_range(2, 0.0, 100.0);
  f.set_output_range(-0.1, 1.1);
  f.set_weight_bounds(2, 0.01, 0.5);
  aln::Piece<double, 3> p;
  p.set(Model::Vec(0.0, 0.0, 0.02), Model::Vec(0.0, 10.0, 50.0), 0.5);
  f.reset(p);
  CHECK(aln::invert(f, 2, g_inv));
  DOUBLES_EQUAL(-0.1, g_inv.input_range(2).lo, 0.0);
  DOUBLES_EQUAL(1.1, g_inv.input_range(2).hi, 0.0);
  DOUBLES_EQUAL(100.0, g_inv.output_range().hi, 0.0);
  DOUBLES_EQUAL(2.0, g_inv.weight_lo(2), 1e-12);
  DOUBLES_EQUAL(100.0, g_inv.weight_hi(2), 1e-12);
  // m = 0.5 + 0.02 (r - 50) -> r = 50 + 50 (m - 0.5): m = 0.7 gives r = 60 dm.
  DOUBLES_EQUAL(60.0, g_inv.evaluate(Model::Vec(1.0, 5.0, 0.7)).value, 1e-12);
}

TEST(AlnInvert, TheBoundsOfADecreasingVariableAreTheReciprocalsInTheirOrder) {
  // m = 0.5 - 0.02 (r - 50) with the slope bounded to [-0.5, -0.01]: dr/dm = 1 / (dm/dr)
  // lies in [1 / -0.01, 1 / -0.5] = [-100, -2], and with an upper bound of 0, below -2.
  Model f;
  f.set_input_range(2, 0.0, 100.0);
  f.set_weight_bounds(2, -0.5, -0.01);
  aln::Piece<double, 3> p;
  p.set(Model::Vec(0.0, 0.0, -0.02), Model::Vec(0.0, 10.0, 50.0), 0.5);
  f.reset(p);
  CHECK(aln::invert(f, 2, g_inv));
  DOUBLES_EQUAL(-100.0, g_inv.weight_lo(2), 1e-12);
  DOUBLES_EQUAL(-2.0, g_inv.weight_hi(2), 1e-12);
  CHECK(g_inv.pieces_within_bounds());
  DOUBLES_EQUAL(40.0, g_inv.evaluate(Model::Vec(1.0, 5.0, 0.7)).value, 1e-12);
  f.set_weight_bounds(2, -0.5, 0.0);
  CHECK(aln::invert(f, 2, g_inv));
  CHECK(std::isinf(g_inv.weight_lo(2)) && g_inv.weight_lo(2) < 0.0);
  DOUBLES_EQUAL(-2.0, g_inv.weight_hi(2), 1e-12);
  // Inverting back gives the original bounds again.
  f.set_weight_bounds(2, -0.5, -0.01);
  CHECK(aln::invert(f, 2, g_inv));
  CHECK(aln::invert(g_inv, 2, g_back));
  DOUBLES_EQUAL(-0.5, g_back.weight_lo(2), 1e-12);
  DOUBLES_EQUAL(-0.01, g_back.weight_hi(2), 1e-12);
}

TEST(AlnInvert, EveryPieceOfAnInvertedRandomModelIsInsideTheInvertedBounds) {
  aln_test::Rng rng(31);
  for (const double sign : {1.0, -1.0}) {
    aln_test::random_model(g_f, 24, rng, 2);
    double lo = 1e9;
    double hi = -1e9;
    for (std::size_t q = 0; q < g_f.piece_count(); ++q) {
      aln::Piece<double, 3>& piece = g_f.piece(q);
      Model::Vec w = piece.weight;
      w(2) = sign * std::fabs(w(2));
      piece.set(w, piece.centroid, piece.centroid_output);
      lo = std::fmin(lo, w(2));
      hi = std::fmax(hi, w(2));
    }
    g_f.set_weight_bounds(2, lo, hi);
    CHECK(g_f.pieces_within_bounds());
    CHECK(aln::invert(g_f, 2, g_inv));
    CHECK(g_inv.pieces_within_bounds());
    CHECK(g_inv.weight_lo(2) <= g_inv.weight_hi(2));
  }
  g_f.set_weight_bounds(2, -std::numeric_limits<double>::infinity(),
                        std::numeric_limits<double>::infinity());
}

TEST(AlnInvert, ANonMonotoneVariableIsRefused) {
  aln_test::Rng rng(23);
  aln_test::random_model(g_f, 16, rng, 2);
  aln::Piece<double, 3>& piece = g_f.piece(3);
  Model::Vec w = piece.weight;
  w(2) = -0.5;
  piece.set(w, piece.centroid, piece.centroid_output);
  CHECK_FALSE(aln::invert(g_f, 2, g_inv));
  CHECK_FALSE(aln::invert(g_f, 3, g_inv));
  w(2) = 0.0;
  piece.set(w, piece.centroid, piece.centroid_output);
  CHECK_FALSE(aln::invert(g_f, 2, g_inv));
}

TEST(AlnInvert, InversionDoesNotAllocate) {
  aln_test::Rng rng(29);
  aln_test::random_model(g_f, 64, rng, 2);
  bool ok = false;
  CHECK_NO_ALLOCATION(ok = aln::invert(g_f, 2, g_inv));
  CHECK(ok);
}
