// Tests of the first-crossing free range (any occupancy ALN, e.g. the belief model) and of the
// belief polygon it gives for the §7.2.3 exploration points.
#include <array>
#include <cmath>
#include <cstddef>
#include <limits>

#include <Eigen/Core>

#include "algo/aln/aln.h"
#include "algo/core/fixed_vector.h"
#include "algo/mapping/aln_first_crossing.h"
#include "algo/mapping/aln_free_range.h"
#include "algo/mapping/extraction.h"
#include "algo/mapping/map_points.h"
#include "polygon_fixtures.h"

#include "CppUTest/TestHarness.h"
#include "alloc_guard.h"

using boticelli::core::FixedVector;
using boticelli::core::Point2;
using boticelli::test::Random;
namespace mapping = boticelli::mapping;
using boticelli::aln::NodeKind;

namespace {

using Model = boticelli::aln::Aln<float, 3, 16>;
using Node = Model::Node;

// A piece m = m0 + a α + b h + c r (through (α, h, r) = (0, 0, 0) at m0).
Model::PieceType plane(float a, float b, float c, float m0) {
  Model::PieceType p;
  p.set(Eigen::Vector3f(a, b, c), Eigen::Vector3f::Zero(), m0);
  return p;
}

// A chain of `count` pieces: kind_0(p0, kind_1(p1, ... p_last)), kinds alternating from
// `first`.
void chain(const Model::PieceType* pieces, std::size_t count, NodeKind first, Model& out) {
  std::array<Node, 31> nodes{};
  NodeKind kind = first;
  for (std::size_t i = 0; i + 1 < count; ++i) {
    nodes[2 * i] = {kind, static_cast<std::uint16_t>(2 * i + 1),
                    static_cast<std::uint16_t>(2 * i + 2)};
    nodes[2 * i + 1] = {NodeKind::kPiece, static_cast<std::uint16_t>(i), 0};
    kind = kind == NodeKind::kMin ? NodeKind::kMax : NodeKind::kMin;
  }
  nodes[2 * count - 2] = {NodeKind::kPiece, static_cast<std::uint16_t>(count - 1), 0};
  CHECK_TRUE(out.assign(std::span<const Node>(nodes.data(), 2 * count - 1),
                        std::span<const Model::PieceType>(pieces, count)));
}

// A belief model of one feature 1 m away in every direction and a wall at 2.5 m:
// MAX(wall rising at 2.5 m, MIN(rising through 0.6 at 1.0 m, falling through `feature_m`
// at 1.1 m)); the bump peaks at 0.6 + (feature_m − 0.2) / 2.
void feature_then_wall(float feature_m, Model& out) {
  const Model::PieceType pieces[3] = {plane(0, 0, 4.0F, 0.6F - 4.0F * 2.5F),
                                      plane(0, 0, 4.0F, 0.6F - 4.0F * 1.0F),
                                      plane(0, 0, -4.0F, feature_m + 4.0F * 1.1F)};
  std::array<Node, 5> nodes{{{NodeKind::kMax, 1, 2},
                             {NodeKind::kPiece, 0, 0},
                             {NodeKind::kMin, 3, 4},
                             {NodeKind::kPiece, 1, 0},
                             {NodeKind::kPiece, 2, 0}}};
  CHECK_TRUE(out.assign(nodes, pieces));
}

float brute_first_crossing(const Model& m, float alpha, float h, float safe, float max_r,
                           float step) {
  for (float r = 0.0F; r <= max_r; r += step) {
    if (m(Model::Vec(alpha, h, r)) >= safe) return r;
  }
  return std::numeric_limits<float>::infinity();
}

}  // namespace

TEST_GROUP(FirstCrossing){};

TEST(FirstCrossing, AFeatureInFrontOfTheWallIsTheFirstCrossingEvenThoughTheModelFallsBehindIt) {
  static Model model;
  feature_then_wall(0.9F, model);
  static mapping::AlnFirstCrossing<float, 16> range;
  CHECK_TRUE(range.set_model(model, 0.6F, 4.0F));
  DOUBLES_EQUAL(1.0, range(0.3F, -0.2F), 1e-5);
  // A feature too weak to reach m_safe (its peak is 0.55) leaves the wall; no wall within
  // range is free.
  feature_then_wall(0.1F, model);
  CHECK_TRUE(range.set_model(model, 0.6F, 4.0F));
  DOUBLES_EQUAL(2.5, range(0.3F, -0.2F), 1e-5);
  CHECK_TRUE(range.set_model(model, 0.6F, 2.0F));
  CHECK_TRUE(std::isinf(range(0.3F, -0.2F)));
  DOUBLES_EQUAL(1.5, mapping::horizontal_free_distance_m(range(0.3F, -0.2F), -0.2F, 1.5F), 0.0);
}

TEST(FirstCrossing, OnAMonotoneModelItIsTheInverse) {
  Random rng(3);
  static Model model;
  Model::PieceType pieces[7];
  for (auto& p : pieces) {
    p = plane(rng.uniform(-0.3F, 0.3F), rng.uniform(-1.0F, 1.0F), rng.uniform(0.5F, 3.0F),
              rng.uniform(-2.0F, 0.5F));
  }
  chain(pieces, 7, NodeKind::kMin, model);
  static mapping::AlnFreeRange<float, 16> inverse;
  CHECK_TRUE(inverse.set_model(model, 0.6F));
  static mapping::AlnFirstCrossing<float, 16> first;
  CHECK_TRUE(first.set_model(model, 0.6F, 100.0F));
  for (int i = 0; i < 500; ++i) {
    const float alpha = rng.uniform(0.0F, 6.28F);
    const float h = rng.uniform(-0.5F, 0.5F);
    const float r = inverse(alpha, h);
    if (r >= 0.0F) {
      DOUBLES_EQUAL(r, first(alpha, h), 1e-4 * (1.0 + static_cast<double>(r)));
    } else {
      DOUBLES_EQUAL(0.0, first(alpha, h), 0.0);  // occupied from the start
    }
  }
}

TEST(FirstCrossing, AgreesWithAFineSearchOnRandomTreesThatRiseAndFall) {
  Random rng(11);
  static Model model;
  static mapping::AlnFirstCrossing<float, 16> first;
  int crossings = 0;
  for (int trial = 0; trial < 40; ++trial) {
    Model::PieceType pieces[9];
    for (auto& p : pieces) {
      p = plane(rng.uniform(-0.5F, 0.5F), rng.uniform(-1.0F, 1.0F), rng.uniform(-2.0F, 2.0F),
                rng.uniform(-1.0F, 2.0F));
    }
    chain(pieces, 9, trial % 2 == 0 ? NodeKind::kMin : NodeKind::kMax, model);
    CHECK_TRUE(first.set_model(model, 0.6F, 4.0F));
    for (int q = 0; q < 20; ++q) {
      const float alpha = rng.uniform(0.0F, 6.28F);
      const float h = rng.uniform(-0.5F, 0.5F);
      const float exact = first(alpha, h);
      const float brute = brute_first_crossing(model, alpha, h, 0.6F, 4.0F, 1e-3F);
      if (std::isinf(brute)) {
        // Only a crossing narrower than the search step can hide from it.
        CHECK_TRUE(std::isinf(exact) || model(Model::Vec(alpha, h, exact)) >= 0.6F - 1e-4F);
        continue;
      }
      ++crossings;
      CHECK_TRUE(exact <= brute + 1e-4F);
      CHECK_TRUE(model(Model::Vec(alpha, h, exact)) >= 0.6F - 1e-4F);
    }
  }
  CHECK_TRUE(crossings > 200);
}

TEST(FirstCrossing, TheBeliefPolygonGivesExplorationPointsWhereItReachesPastThePlausibleOne) {
  // Plausibility: the wall at 2.5 m, and for α < 0.5 rad weak evidence 1 m away that the
  // monotone model carries on behind it (occupancy ≥ m_safe from 1 m on). Belief: the same
  // evidence rises and falls again and peaks at 0.55, below m_safe. So the belief polygon
  // reaches the wall there: space that may be free but is not known to be.
  static Model plausibility;
  static Model belief;
  const Model::PieceType wall = plane(0, 0, 4.0F, 0.6F - 10.0F);           // 0.6 at 2.5 m
  const Model::PieceType near = plane(0, 0, 4.0F, 0.6F - 4.0F);            // 0.6 at 1 m, rising
  const Model::PieceType sector = plane(-8.0F, 0, 1e-3F, 0.6F + 4.0F);     // only for α < 0.5
  const Model::PieceType behind = plane(0, 0, -4.0F, 0.1F + 4.0F * 1.1F);  // falls behind
  const Model::PieceType pl[3] = {wall, near, sector};
  std::array<Node, 5> pl_nodes{{{NodeKind::kMax, 1, 2},
                                {NodeKind::kPiece, 0, 0},
                                {NodeKind::kMin, 3, 4},
                                {NodeKind::kPiece, 1, 0},
                                {NodeKind::kPiece, 2, 0}}};
  CHECK_TRUE(plausibility.assign(pl_nodes, pl));
  const Model::PieceType bel[4] = {wall, near, sector, behind};
  std::array<Node, 7> bel_nodes{{{NodeKind::kMax, 1, 2},
                                 {NodeKind::kPiece, 0, 0},
                                 {NodeKind::kMin, 3, 4},
                                 {NodeKind::kPiece, 1, 0},
                                 {NodeKind::kMin, 5, 6},
                                 {NodeKind::kPiece, 2, 0},
                                 {NodeKind::kPiece, 3, 0}}};
  CHECK_TRUE(belief.assign(bel_nodes, bel));
  static mapping::AlnFreeRange<float, 16> pl_range;
  static mapping::AlnFirstCrossing<float, 16> bel_range;
  mapping::ExtractionParams p;
  p.seam_margin_rad = 0.0F;
  CHECK_TRUE(pl_range.set_model(plausibility, p.safe_occupancy));
  CHECK_TRUE(bel_range.set_model(belief, p.safe_occupancy, 4.0F));
  static mapping::StarPolygon pl_free;
  static mapping::StarPolygon bel_free;
  mapping::extract_slice(pl_range, 0.0F, p, pl_free);
  mapping::extract_slice(bel_range, 0.0F, p, bel_free);
  DOUBLES_EQUAL(1.0, pl_free.rho_m(10), 1e-4);   // beyond the weak evidence: not surely free
  DOUBLES_EQUAL(2.5, bel_free.rho_m(10), 1e-4);  // but possibly free
  DOUBLES_EQUAL(2.5, pl_free.rho_m(90), 1e-4);   // elsewhere both see the wall
  DOUBLES_EQUAL(2.5, bel_free.rho_m(90), 1e-4);
  static FixedVector<Point2, 64> points;
  points.clear();
  CHECK_NO_ALLOCATION({
    mapping::extract_slice(bel_range, 0.0F, p, bel_free);
    CHECK_TRUE(mapping::extract_gap_exploration_points(bel_free, pl_free, p.bounding_radius_m,
                                                       mapping::MapPointParams{}, points));
  });
  CHECK_TRUE(points.size() >= 1);
  for (const Point2& q : points) {
    const float a = std::atan2(q.y_m, q.x_m);
    CHECK_TRUE(a >= 0.0F && a <= 0.5F);
    CHECK_TRUE(pl_free.contains(q));
  }
}
