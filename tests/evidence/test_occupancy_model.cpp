// Tests of the occupancy model's domain and constraints (Eqs 4.27–4.28 in SI units).
#include <cmath>
#include <numbers>

#include "algo/aln/aln.h"
#include "algo/evidence/occupancy_model.h"
#include "CppUTest/TestHarness.h"

using namespace boticelli;

TEST_GROUP(OccupancyModel){};

TEST(OccupancyModel, IsMonotoneInRangeWithTheThesisSlopeBoundsInMetres) {
  aln::Aln<float, 3, 8> model;
  evidence::configure_occupancy_model(model, -1.0F, 1.0F, 5.0F);
  DOUBLES_EQUAL(-1.0, model.weight_lo(0), 1e-6);
  DOUBLES_EQUAL(1.0, model.weight_hi(0), 1e-6);
  // 1 per dm of height is 10 per m.
  DOUBLES_EQUAL(-10.0, model.weight_lo(1), 1e-6);
  DOUBLES_EQUAL(10.0, model.weight_hi(1), 1e-6);
  CHECK(model.weight_lo(2) > 0.0F);
  CHECK(std::isinf(model.weight_hi(2)));
}

TEST(OccupancyModel, CoversTheSeamCopiesAndTheRangeAsked) {
  aln::Aln<float, 3, 8> model;
  evidence::configure_occupancy_model(model, -0.6F, 1.4F, 4.5F);
  DOUBLES_EQUAL(-evidence::kSeamMarginRad, model.input_range(0).lo, 1e-6);
  DOUBLES_EQUAL(2.0 * std::numbers::pi + double{evidence::kSeamMarginRad}, model.input_range(0).hi,
                1e-5);
  DOUBLES_EQUAL(-0.6, model.input_range(1).lo, 1e-6);
  DOUBLES_EQUAL(1.4, model.input_range(1).hi, 1e-6);
  DOUBLES_EQUAL(4.5, model.input_range(2).hi, 1e-6);
}

TEST(OccupancyModel, ASharperSensorModelWidensThePanSlopeBoundByTheSameFactor) {
  // The thesis's 1 per rad for δr = 0.1 r; half the δr, twice the bound (the m_safe surface
  // may tilt as far per radian as the thesis's does).
  DOUBLES_EQUAL(1.0, evidence::alpha_slope_bound_per_rad(0.1F), 0.0);
  DOUBLES_EQUAL(2.0, evidence::alpha_slope_bound_per_rad(0.05F), 1e-6);
  DOUBLES_EQUAL(1.0, evidence::alpha_slope_bound_per_rad(0.0F), 0.0);
  aln::Aln<float, 3, 8> model;
  evidence::RaySampleParams rays;
  rays.delta_r_fraction = 0.025F;
  evidence::configure_occupancy_model(model, evidence::make_reading_limits(0.35F), rays);
  DOUBLES_EQUAL(-4.0, model.weight_lo(0), 1e-5);
  DOUBLES_EQUAL(4.0, model.weight_hi(0), 1e-5);
  DOUBLES_EQUAL(10.0, model.weight_hi(1), 1e-6);  // the height bound stays the thesis's
}
