// Tests of a look's registration against the world memory (ScanMatcher): shifts recovered,
// a featureless wall constrained only across itself, no allocation.
#include <array>
#include <cmath>
#include <cstdint>
#include <limits>
#include <random>

#include "algo/core/angles.h"
#include "algo/mapping/star_polygon.h"
#include "algo/worldmap/grid_map.h"
#include "algo/worldmap/look_fusion.h"
#include "algo/worldmap/scan_matcher.h"

#include "CppUTest/TestHarness.h"
#include "alloc_guard.h"

using boticelli::core::Point2;
using boticelli::core::Pose2;
namespace mapping = boticelli::mapping;
namespace wm = boticelli::worldmap;

namespace {

wm::GridMap g_grid;
wm::LookFusion g_fuse;
wm::ScanMatcher g_matcher;
mapping::StarPolygon g_free(360);
mapping::StarPolygon g_evidence(360);

struct Segment {
  Point2 a;
  Point2 b;
};

// A room of our own, not one the mission is measured on: an irregular pentagon (5.6 × 4.4 m)
// with a pillar and a short partition.
constexpr std::array<Segment, 10> kRoom = {{
    {{-2.6F, -2.0F}, {3.0F, -2.2F}},
    {{3.0F, -2.2F}, {3.1F, 1.2F}},
    {{3.1F, 1.2F}, {1.4F, 2.3F}},
    {{1.4F, 2.3F}, {-2.5F, 2.2F}},
    {{-2.5F, 2.2F}, {-2.6F, -2.0F}},
    {{0.9F, -0.9F}, {1.3F, -0.9F}},  // pillar
    {{1.3F, -0.9F}, {1.3F, -0.5F}},
    {{1.3F, -0.5F}, {0.9F, -0.5F}},
    {{0.9F, -0.5F}, {0.9F, -0.9F}},
    {{-2.5F, 0.6F}, {-1.3F, 0.7F}},  // partition
}};

// One long straight wall along x at y = 1.5 m, its ends beyond the camera's range.
constexpr std::array<Segment, 1> kWall = {{{{-30.0F, 1.5F}, {30.0F, 1.5F}}}};

// The distance along the ray from `o` at heading `a` to the nearest segment (∞ when none).
template <std::size_t N>
float cast(const std::array<Segment, N>& segments, Point2 o, float a) {
  const float dx = std::cos(a);
  const float dy = std::sin(a);
  float best = std::numeric_limits<float>::infinity();
  for (const Segment& s : segments) {
    const float ex = s.b.x_m - s.a.x_m;
    const float ey = s.b.y_m - s.a.y_m;
    const float den = dx * ey - dy * ex;
    if (std::fabs(den) < 1e-9F) continue;
    const float wx = s.a.x_m - o.x_m;
    const float wy = s.a.y_m - o.y_m;
    const float t = (wx * ey - wy * ex) / den;
    const float u = (wx * dy - wy * dx) / den;
    if (t > 0.0F && u >= 0.0F && u <= 1.0F) best = std::min(best, t);
  }
  return best;
}

// The look a robot truly at `pose` takes of `segments`: the evidence per vertex ray (range
// noise of `noise_m` × (r / 2 m)², the stereo error's growth) and a free polygon that stops
// 0.1 m short of it (3 m where nothing was seen).
template <std::size_t N>
void take_look(const std::array<Segment, N>& segments, const Pose2& pose, float noise_m,
               std::mt19937& rng) {
  std::normal_distribution<float> gauss(0.0F, 1.0F);
  for (std::size_t k = 0; k < g_free.vertex_count(); ++k) {
    const float a = g_free.angle_rad(k);
    const float r = cast(segments, {pose.x_m, pose.y_m}, pose.yaw_rad + a);
    if (!std::isfinite(r) || r > 5.0F) {
      g_evidence.set_rho_m(k, std::numeric_limits<float>::infinity());
      g_free.set_rho_m(k, 3.0F);
      continue;
    }
    const float e = std::max(0.2F, r + noise_m * (r / 2.0F) * (r / 2.0F) * gauss(rng));
    g_evidence.set_rho_m(k, e);
    g_free.set_rho_m(k, std::max(0.1F, e - 0.1F));
  }
}

// The map a look at `pose` makes, fused twice (two looks from the same place).
void map_from_look(const Pose2& pose) {
  for (int i = 0; i < 2; ++i) {
    g_fuse.start(g_grid, pose, g_free, g_evidence, {});
    g_fuse.run();
  }
}

}  // namespace

TEST_GROUP(ScanMatcher){void setup() override{g_grid.configure({});
}
}
;

TEST(ScanMatcher, ALookRegisteredAgainstAMapOfAShiftedAndRotatedCopyOfItselfRecoversTheShift) {
  std::mt19937 rng(48);
  std::uniform_real_distribution<float> shift(-0.27F, 0.27F);
  std::uniform_real_distribution<float> turn(-0.16F, 0.16F);  // ±9°
  std::uniform_real_distribution<float> place(-0.5F, 0.5F);
  for (int trial = 0; trial < 12; ++trial) {
    g_grid.configure({});
    // The map: this look, seen from where the robot truly stands.
    const Pose2 truth{-0.5F + place(rng), 0.3F + place(rng), place(rng) * 6.0F};
    take_look(kRoom, truth, 0.02F, rng);
    map_from_look(truth);
    // The same look again (new noise), registered from a shifted and rotated odometry pose.
    take_look(kRoom, truth, 0.02F, rng);
    const Pose2 odometry{truth.x_m + shift(rng), truth.y_m + shift(rng),
                         boticelli::core::wrap_pi(truth.yaw_rad + turn(rng))};
    g_matcher.start(g_grid, odometry, g_free, g_evidence, {});
    CHECK_NO_ALLOCATION(g_matcher.run());
    const wm::Registration& r = g_matcher.result();
    CHECK_TEXT(r.matched, "registered");
    LONGS_EQUAL(3, r.constrained);
    const float dx = r.pose.x_m - truth.x_m;
    const float dy = r.pose.y_m - truth.y_m;
    const float dyaw = boticelli::core::wrap_pi(r.pose.yaw_rad - truth.yaw_rad);
    CHECK_TEXT(std::hypot(dx, dy) < 0.03F, "within 3 cm");
    CHECK_TEXT(std::fabs(dyaw) < 0.0175F, "within 1 degree");
    CHECK(r.units > 10);  // in units of work, not one call
  }
}

TEST(ScanMatcher, AFeaturelessWallConstrainsTheLookOnlyAcrossItAndOdometryStandsAlongIt) {
  std::mt19937 rng(7);
  const Pose2 truth{0.0F, 0.0F, 0.4F};
  take_look(kWall, truth, 0.01F, rng);
  map_from_look(truth);
  take_look(kWall, truth, 0.01F, rng);
  const Pose2 odometry{truth.x_m + 0.2F, truth.y_m - 0.15F, truth.yaw_rad + 0.05F};
  g_matcher.start(g_grid, odometry, g_free, g_evidence, {});
  g_matcher.run();
  const wm::Registration& r = g_matcher.result();
  CHECK_TEXT(r.matched, "registered");
  LONGS_EQUAL(2, r.constrained);  // across the wall and the heading, not along it
  const wm::ScanMatcherParams params;
  CHECK(r.information_along(1.0F, 0.0F) < 0.1F * params.min_information);
  CHECK(r.information_along(0.0F, 1.0F) > 4.0F * params.min_information);
  // Across the wall and in heading the truth is recovered; along it the odometry stands.
  DOUBLES_EQUAL(truth.y_m, r.pose.y_m, 0.02);
  DOUBLES_EQUAL(truth.yaw_rad, r.pose.yaw_rad, 0.0175);
  DOUBLES_EQUAL(odometry.x_m, r.pose.x_m, 0.02);
}

TEST(ScanMatcher, AnEmptyMapOrAnEmptyLookLeavesTheOdometrysPose) {
  std::mt19937 rng(1);
  const Pose2 odometry{0.3F, -0.2F, 0.1F};
  take_look(kRoom, odometry, 0.0F, rng);
  g_matcher.start(g_grid, odometry, g_free, g_evidence, {});
  g_matcher.run();
  CHECK_FALSE(g_matcher.result().matched);
  DOUBLES_EQUAL(odometry.x_m, g_matcher.result().pose.x_m, 0.0);
  map_from_look(odometry);
  g_evidence.fill(std::numeric_limits<float>::infinity());
  g_matcher.start(g_grid, odometry, g_free, g_evidence, {});
  g_matcher.run();
  CHECK_FALSE(g_matcher.result().matched);
  LONGS_EQUAL(0, g_matcher.result().points);
}
