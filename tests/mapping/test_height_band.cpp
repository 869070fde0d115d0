// Tests of the height-band extraction: the band's free range never passes a crossing at any
// height inside the band, where the thesis's slices can.
#include <algorithm>
#include <array>
#include <cmath>
#include <cstddef>
#include <cstdint>

#include <Eigen/Core>

#include "algo/aln/aln.h"
#include "algo/mapping/aln_free_range.h"
#include "algo/mapping/extraction.h"
#include "algo/mapping/star_polygon.h"

#include "CppUTest/TestHarness.h"
#include "alloc_guard.h"

namespace mapping = boticelli::mapping;
namespace aln = boticelli::aln;

namespace {

using Occupancy = aln::Aln<float, 3, 16>;
using FreeRange = mapping::AlnFreeRange<float, 16>;

// The robot of the sim board: PTU 0.6 m up, slices from 0.03 m to 0.8 m above the floor.
mapping::ExtractionParams robot_params() {
  mapping::ExtractionParams p;
  p.ptu_height_m = 0.6F;
  p.lowest_height_m = 0.03F;
  p.robot_height_m = 0.8F;
  p.height_count = 5;
  p.bounding_radius_m = 3.0F;
  p.seam_margin_rad = 0.2F;
  return p;
}

// Uniform in [0, 1), from a fixed linear congruential sequence.
struct Uniform {
  std::uint32_t state;
  float next() {
    state = state * 1664525U + 1013904223U;
    return static_cast<float>(state >> 8) / 16777216.0F;
  }
  float in(float lo, float hi) { return lo + (hi - lo) * next(); }
};

// A random occupancy model of `pieces` planes (monotone in r, |∂F/∂h| ≤ 10 /m as the mission
// bounds it) under a random MIN/MAX tree: each inner node joins two subtrees.
void random_model(Uniform& u, std::size_t pieces, Occupancy& model) {
  std::array<Occupancy::PieceType, 8> piece{};
  for (std::size_t j = 0; j < pieces; ++j) {
    piece[j].set(Eigen::Vector3f(u.in(-0.5F, 0.5F), u.in(-10.0F, 10.0F), u.in(0.5F, 4.0F)),
                 Eigen::Vector3f(u.in(0.0F, 6.28F), u.in(-0.6F, 0.3F), u.in(0.5F, 3.0F)), 0.6F);
  }
  // Nodes in preorder: a left-deep chain of MIN/MAX nodes over the pieces, each joining the
  // subtree so far (left) with the next piece (right): node 2i is an operator whose left
  // child is node 2i + 2 (or the first piece), its right child node 2i + 1.
  std::array<Occupancy::Node, 15> nodes{};
  const std::size_t ops = pieces - 1;
  for (std::size_t i = 0; i < ops; ++i) {
    const auto kind = u.next() < 0.5F ? aln::NodeKind::kMin : aln::NodeKind::kMax;
    const auto op = static_cast<std::uint16_t>(2 * i);
    nodes[op] = {kind, static_cast<std::uint16_t>(op + 2), static_cast<std::uint16_t>(op + 1)};
    nodes[op + 1] = {aln::NodeKind::kPiece, static_cast<std::uint16_t>(ops - i), 0};
  }
  nodes[2 * ops] = {aln::NodeKind::kPiece, 0, 0};
  CHECK_TRUE(model.assign(std::span(nodes.data(), 2 * ops + 1), std::span(piece.data(), pieces)));
  model.set_weight_bounds(2, 1e-4F, 100.0F);
}

// A wall 2.5 m away and, at h0, a thin ledge 1 m away: occupancy MAX(wall, MIN(up, down))
// with up and down rising 10 /m with h on either side of h0 (the mission's slope bound).
void ledge_model(float h0, Occupancy& model) {
  std::array<Occupancy::PieceType, 3> piece{};
  piece[0].set(Eigen::Vector3f(0.0F, 0.0F, 2.0F), Eigen::Vector3f(0.0F, 0.0F, 2.5F), 0.6F);
  piece[1].set(Eigen::Vector3f(0.0F, 10.0F, 2.0F), Eigen::Vector3f(0.0F, h0, 1.0F), 0.6F);
  piece[2].set(Eigen::Vector3f(0.0F, -10.0F, 2.0F), Eigen::Vector3f(0.0F, h0, 1.0F), 0.6F);
  const std::array<Occupancy::Node, 5> nodes = {{{aln::NodeKind::kMax, 1, 2},
                                                 {aln::NodeKind::kPiece, 0, 0},
                                                 {aln::NodeKind::kMin, 3, 4},
                                                 {aln::NodeKind::kPiece, 1, 0},
                                                 {aln::NodeKind::kPiece, 2, 0}}};
  CHECK_TRUE(model.assign(nodes, piece));
  model.set_weight_bounds(2, 1e-4F, 100.0F);
}

// The nearest horizontal distance at which the model reaches m_safe at some height of
// [h_lo, h_hi], by a fine search over 400 heights.
float fine_band_rho(const FreeRange& f, float alpha, float h_lo, float h_hi, float bound_m) {
  float rho = bound_m;
  for (int i = 0; i <= 400; ++i) {
    const float h = h_lo + (h_hi - h_lo) * static_cast<float>(i) / 400.0F;
    rho = std::min(rho, mapping::horizontal_free_distance_m(f(alpha, h), h, bound_m));
  }
  return rho;
}

Occupancy g_model;
FreeRange g_range;

}  // namespace

TEST_GROUP(HeightBand){};

TEST(HeightBand, ABandThinAsASliceGivesTheSlicesRanges) {
  Uniform u{7U};
  random_model(u, 6, g_model);
  CHECK_TRUE(g_range.set_model(g_model, 0.6F));
  std::array<float, 360> slice{};
  std::array<float, 360> band{};
  for (const float h : {-0.57F, -0.2F, 0.1F}) {
    g_range.ranges_at_height(h, 0.01745F, 0, 360, 0.0F, slice.data());
    g_range.ranges_over_band(h, h, 0.01745F, 0, 360, 0.0F, band.data());
    for (std::size_t k = 0; k < 360; ++k) CHECK_EQUAL(slice[k], band[k]);
  }
}

TEST(HeightBand, OnRandomModelsTheBandPolygonNeverPassesACrossingAnywhereInTheBand) {
  Uniform u{12345U};
  const mapping::ExtractionParams p = robot_params();
  mapping::StarPolygon band(360);
  std::size_t tight = 0;
  std::size_t vertices = 0;
  for (int trial = 0; trial < 40; ++trial) {
    random_model(u, 2 + static_cast<std::size_t>(trial % 7), g_model);
    if (!g_range.set_model(g_model, 0.6F)) continue;
    const float h_lo = u.in(-0.57F, 0.0F);
    const float h_hi = h_lo + u.in(0.0F, 0.4F);
    mapping::extract_band(g_range, h_lo, h_hi, p, band);
    for (std::size_t k = 0; k < band.vertex_count(); k += 3) {
      const float alpha = band.angle_rad(k);
      float fine = fine_band_rho(g_range, alpha, h_lo, h_hi, p.bounding_radius_m);
      if (alpha < p.seam_margin_rad) {
        fine = std::min(
            fine, fine_band_rho(g_range, alpha + 6.2831853F, h_lo, h_hi, p.bounding_radius_m));
      } else if (alpha > 6.2831853F - p.seam_margin_rad) {
        fine = std::min(
            fine, fine_band_rho(g_range, alpha - 6.2831853F, h_lo, h_hi, p.bounding_radius_m));
      }
      CHECK_TEXT(band.rho_m(k) <= fine + 1e-4F, "the band passes a crossing inside it");
      tight += band.rho_m(k) >= fine - 0.05F ? 1U : 0U;
      ++vertices;
    }
  }
  // A bound, but not a useless one: most vertices within 5 cm of the fine search.
  CHECK(vertices > 2000U);
  CHECK(tight * 2 > vertices);
}

// Finding of the Think-stage review: with |∂F/∂h| ≤ 10 /m and 0.19 m between slices, F can
// exceed m_safe between two slices that are both below it.
TEST(HeightBand, ALedgeBetweenTwoSlicesIsMissedBySlicesAndKeptByTheBands) {
  mapping::ExtractionParams p = robot_params();
  const float h0 = 0.5F * (mapping::slice_height_m(p, 1) + mapping::slice_height_m(p, 2));
  ledge_model(h0, g_model);
  CHECK_TRUE(g_range.set_model(g_model, 0.6F));
  const float ledge_rho = std::sqrt(1.0F - h0 * h0);  // the ledge's edge, 1 m along the ray
  static mapping::StarPolygon free;
  static mapping::StarPolygon scratch;
  mapping::extract_free_polygon(g_range, p, free, scratch);
  CHECK(free.rho_m(0) > ledge_rho + 0.3F);  // the slices see past the ledge
  p.band_count = 16;
  CHECK_NO_ALLOCATION(mapping::extract_free_polygon(g_range, p, free, scratch));
  for (std::size_t k = 0; k < free.vertex_count(); ++k) {
    CHECK(free.rho_m(k) <= ledge_rho);
    CHECK(free.rho_m(k) >= ledge_rho - 0.15F);  // 16 bands: about 5 cm of band at the ledge
  }
}
