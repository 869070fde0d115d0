// Tests of the angle helpers.
#include "algo/core/angles.h"
#include "algo/core/units.h"
#include "CppUTest/TestHarness.h"

using namespace boticelli::core;

TEST_GROUP(Angles){};

TEST(Angles, WrapTwoPiMapsEveryAngleIntoZeroToTwoPi) {
  DOUBLES_EQUAL(0.5, wrap_two_pi(0.5 + 4.0 * kPi<double>), 1e-12);
  DOUBLES_EQUAL(2.0 * kPi<double> - 0.5, wrap_two_pi(-0.5), 1e-12);
  DOUBLES_EQUAL(0.0, wrap_two_pi(2.0 * kPi<double>), 1e-12);
  CHECK(wrap_two_pi(-1e-18) < 2.0 * kPi<double>);
}

TEST(Angles, WrapPiMapsIntoMinusPiToPi) {
  DOUBLES_EQUAL(-0.5, wrap_pi(2.0 * kPi<double> - 0.5), 1e-12);
  DOUBLES_EQUAL(kPi<double>, wrap_pi(kPi<double>), 1e-12);
}

TEST(Angles, DecimetreSlopeBoundsBecomeTenTimesSteeperPerMetre) {
  DOUBLES_EQUAL(10.0, slope_per_dm_to_per_m(1.0), 1e-12);
  DOUBLES_EQUAL(0.21, dm_to_m(2.1), 1e-12);
  DOUBLES_EQUAL(deg_to_rad(7.7), 0.134390352, 1e-9);
}
