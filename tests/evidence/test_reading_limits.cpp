// Tests of the reading limits: which readings are believed, and the pads' region and the
// occupancy model's input box derived from the same limits.
#include <cmath>
#include <cstddef>
#include <limits>
#include <numbers>

#include "algo/aln/aln.h"
#include "algo/core/fixed_vector.h"
#include "algo/evidence/occupancy_model.h"
#include "algo/evidence/ray_samples.h"
#include "algo/evidence/reading_limits.h"
#include "alloc_guard.h"
#include "CppUTest/TestHarness.h"

using namespace boticelli;
using namespace boticelli::evidence;

TEST_GROUP(ReadingLimits) {
  // PTU centre 0.6 m above the floor, ceiling 2.5 m, visibility 4.5 m, floor tolerance 0.1 m.
  const ReadingLimits limits = make_reading_limits(0.6F);
};

TEST(ReadingLimits, PutTheFloorAndTheCeilingRelativeToThePtuCentre) {
  DOUBLES_EQUAL(-0.7, limits.min_h_m, 1e-6);  // 0.1 m below the floor
  DOUBLES_EQUAL(1.9, limits.max_h_m, 1e-6);
  DOUBLES_EQUAL(4.5, limits.max_range_m, 1e-6);
  DOUBLES_EQUAL(0.0, limits.min_range_m, 0.0);
  const ReadingLimits tall = make_reading_limits(1.0F, 3.0F, 6.0F, 0.05F);
  DOUBLES_EQUAL(-1.05, tall.min_h_m, 1e-6);
  DOUBLES_EQUAL(2.0, tall.max_h_m, 1e-6);
  DOUBLES_EQUAL(6.0, tall.max_range_m, 1e-6);
}

TEST(ReadingLimits, AcceptTheirEdgesAndRefuseWhatLiesBeyondOrIsNotANumber) {
  CHECK_TRUE(limits.within({1.0F, -0.7F, 2.0F, 0.9F}));  // on the floor tolerance
  CHECK_TRUE(limits.within({1.0F, 1.9F, 4.5F, 0.9F}));   // at the ceiling, at the range
  CHECK_FALSE(limits.within({1.0F, -0.71F, 2.0F, 0.9F}));
  CHECK_FALSE(limits.within({1.0F, 1.91F, 2.0F, 0.9F}));
  CHECK_FALSE(limits.within({1.0F, 0.0F, 4.51F, 0.9F}));
  CHECK_FALSE(limits.within({1.0F, 0.0F, 0.0F, 0.9F}));  // r = 0 is never a reading
  const float nan = std::numeric_limits<float>::quiet_NaN();
  CHECK_FALSE(limits.within({1.0F, nan, 2.0F, 0.9F}));
  CHECK_FALSE(limits.within({1.0F, 0.0F, nan, 0.9F}));
  ReadingLimits near = limits;
  near.min_range_m = 0.3F;
  CHECK_FALSE(near.within({1.0F, 0.0F, 0.3F, 0.9F}));
  CHECK_TRUE(near.within({1.0F, 0.0F, 0.31F, 0.9F}));
}

TEST(ReadingLimits, FilteringRemovesTheReadingsOutsideInPlaceAndKeepsTheOrder) {
  static core::FixedVector<Reading, 16> readings;
  readings.clear();
  for (int i = 0; i < 10; ++i) {
    const float fi = static_cast<float>(i);
    const bool bad = i % 3 == 1;  // 1, 4, 7: below the floor
    (void)readings.push_back({0.1F * fi, bad ? -0.9F : 0.1F * fi, 1.0F + fi * 0.1F, 0.5F});
  }
  (void)readings.push_back({2.0F, 0.0F, 5.0F, 0.9F});  // beyond the range
  std::size_t removed = 0;
  CHECK_NO_ALLOCATION({ removed = filter_readings(readings, limits); });
  LONGS_EQUAL(4, removed);
  LONGS_EQUAL(7, readings.size());
  const int expected[7] = {0, 2, 3, 5, 6, 8, 9};
  for (std::size_t k = 0; k < 7; ++k) {
    DOUBLES_EQUAL(0.1 * expected[k], readings[k].alpha_rad, 1e-6);
    CHECK_TRUE(limits.within(readings[k]));
  }
  LONGS_EQUAL(0, filter_readings(readings, limits));
}

// A reading on the line of sight from a view `view_z` above the PTU centre through the floor
// point at horizontal distance rho (the floor 0.6 m below the PTU centre), whose range is the
// floor point's distance divided by t: the floor lies at t times the reading's range (t = 1:
// on the floor; t < 1: deeper than the floor).
Reading along_sight_to_floor(float rho, float t, float view_z, float m = 0.8F) {
  const float floor_z = -0.6F;
  const float x = rho / t;
  const float z = view_z + (floor_z - view_z) / t;
  Reading r{0.3F, z, std::hypot(x, z), m};
  r.view_z_m = view_z;
  return r;
}

TEST(ReadingLimits, AReadingOnTheFloorWithinItsRangeErrorBecomesFreeAndADeeperOneIsRefused) {
  ReadingLimits floor = limits;
  floor.floor_h_m = -0.6F;
  floor.floor_range_fraction = 0.05F;
  static core::FixedVector<Reading, 16> readings;
  readings.clear();
  // From the PTU centre and from a camera 0.1 m above it: the floor exactly, the range error's
  // two ends (just inside), just beyond them (deeper than the floor: refused; nearer, above
  // it: kept as it is), a wall point level with the camera, one above it.
  for (const float view_z : {0.0F, 0.1F}) {
    (void)readings.push_back(along_sight_to_floor(2.0F, 1.0F, view_z));
    (void)readings.push_back(along_sight_to_floor(2.0F, 0.951F, view_z));
    (void)readings.push_back(along_sight_to_floor(2.0F, 1.049F, view_z));
    (void)readings.push_back(along_sight_to_floor(2.0F, 0.94F, view_z));
    (void)readings.push_back(along_sight_to_floor(2.0F, 1.06F, view_z));
  }
  Reading level{0.5F, 0.1F, 2.0F, 0.9F};
  level.view_z_m = 0.1F;
  (void)readings.push_back(level);
  (void)readings.push_back({0.6F, 0.5F, 2.0F, 0.9F});
  FloorReadings out;
  CHECK_NO_ALLOCATION({ out = floor_readings(readings, floor); });
  LONGS_EQUAL(6, out.floor);
  LONGS_EQUAL(2, out.below);
  LONGS_EQUAL(10, readings.size());
  const float expected_m[10] = {0.0F, 0.0F, 0.0F, 0.8F, 0.0F, 0.0F, 0.0F, 0.8F, 0.9F, 0.9F};
  for (std::size_t k = 0; k < readings.size(); ++k) {
    DOUBLES_EQUAL(expected_m[k], readings[k].m, 0.0);
  }
  DOUBLES_EQUAL(0.1, readings[4].view_z_m, 1e-6);  // the order kept: the second view's first
  DOUBLES_EQUAL(0.5, readings[8].alpha_rad, 1e-6);
  // Off (the thesis's readings): nothing changes.
  static core::FixedVector<Reading, 16> copy;
  copy.clear();
  (void)copy.push_back(along_sight_to_floor(2.0F, 1.0F, 0.0F));
  (void)copy.push_back(along_sight_to_floor(2.0F, 1.2F, 0.0F));
  const FloorReadings off = floor_readings(copy, limits);
  LONGS_EQUAL(0, off.floor + off.below);
  LONGS_EQUAL(2, copy.size());
  DOUBLES_EQUAL(0.8, copy[0].m, 1e-6);
}

TEST(ReadingLimits, PadsAreDrawnExactlyWithinTheLimits) {
  const PadRegion region = pad_region(limits);
  DOUBLES_EQUAL(0.0, region.alpha_min_rad, 0.0);
  DOUBLES_EQUAL(2.0 * std::numbers::pi, region.alpha_max_rad, 1e-6);
  DOUBLES_EQUAL(limits.min_h_m, region.h_min_m, 0.0);
  DOUBLES_EQUAL(limits.max_h_m, region.h_max_m, 0.0);
  DOUBLES_EQUAL(limits.min_range_m, region.r_min_m, 0.0);
  DOUBLES_EQUAL(limits.max_range_m, region.r_max_m, 0.0);
  static core::FixedVector<RaySample, 1000> pads;
  pads.clear();
  PadRandom random{7U};
  LONGS_EQUAL(1000, append_zero_pads(region, 1000, random, pads));
  for (const RaySample& s : pads) {
    CHECK_TRUE(s.h_m >= limits.min_h_m && s.h_m <= limits.max_h_m);
    CHECK_TRUE(s.r_m >= limits.min_range_m && s.r_m <= limits.max_range_m);
  }
}

namespace {

// Readings at the corners of the limits: farthest, highest, lowest, straight up and down.
void corner_readings(const ReadingLimits& l, core::FixedVectorBase<Reading>& out) {
  (void)out.push_back({0.5F, l.min_h_m, l.max_range_m, 0.9F});
  (void)out.push_back({1.5F, l.max_h_m, l.max_range_m, 0.9F});
  (void)out.push_back({2.5F, 0.0F, l.max_range_m, 0.9F});
  (void)out.push_back({3.5F, l.max_h_m, l.max_h_m, 0.9F});
  (void)out.push_back({4.5F, l.min_h_m, -l.min_h_m, 0.9F});
}

// True if sample s lies in the model's input box (h, r).
template <typename Model>
bool in_box(const Model& model, const RaySample& s) {
  return s.h_m >= model.input_range(1).lo && s.h_m <= model.input_range(1).hi &&
         s.r_m >= model.input_range(2).lo && s.r_m <= model.input_range(2).hi;
}

}  // namespace

TEST(ReadingLimits, TheModelsInputBoxHoldsEveryRaySampleOfEveryReadingWithinThem) {
  core::FixedVector<Reading, 8> readings;
  corner_readings(limits, readings);
  const RaySampleParams rays;
  for (const OccupancyBound bound : {OccupancyBound::kPlausibility, OccupancyBound::kBelief}) {
    aln::Aln<float, 3, 8> model;
    configure_occupancy_model(model, limits, rays, bound);
    core::FixedVector<RaySample, 128> samples;
    LONGS_EQUAL(readings.size(), append_ray_samples(readings, rays, samples, bound));
    float farthest = 0.0F;
    float lowest = 0.0F;
    for (const RaySample& s : samples) {
      CHECK_TRUE(in_box(model, s));
      farthest = std::fmax(farthest, s.r_m);
      lowest = std::fmin(lowest, s.h_m);
    }
    // The box is no larger than it must be: the farthest samples lie on its edges.
    DOUBLES_EQUAL(model.input_range(2).hi, farthest, 1e-4);
    DOUBLES_EQUAL(model.input_range(1).lo, lowest, 1e-4);
  }
  // Plausibility samples reach δr = 0.1 r beyond the reading: 4.95 m for 4.5 m.
  aln::Aln<float, 3, 8> model;
  configure_occupancy_model(model, limits);
  DOUBLES_EQUAL(4.95, model.input_range(2).hi, 1e-4);
  DOUBLES_EQUAL(-0.77, model.input_range(1).lo, 1e-4);
  DOUBLES_EQUAL(2.09, model.input_range(1).hi, 1e-4);
  // The slope bounds are those of the plain overload.
  DOUBLES_EQUAL(10.0, model.weight_hi(1), 1e-6);
}
