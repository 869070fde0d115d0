// Tests of the synthetic range data of the thesis's simulated rooms (tools/bench/synthetic_rooms).
#include <cmath>
#include <cstddef>
#include <vector>

#include "synthetic_rooms.h"
#include "CppUTest/TestHarness.h"

using namespace boticelli;
using namespace boticelli::bench;

namespace {
double distance_xy(const Vec3& p) {
  return std::hypot(p.x, p.y);
}
}  // namespace

TEST_GROUP(SyntheticRooms){};

TEST(SyntheticRooms, TheTenRowsOfTheThesisTableAreThereInItsOrder) {
  LONGS_EQUAL(10, thesis_environments().size());
  STRCMP_EQUAL("cylinder_centre", thesis_environments()[0].name);
  LONGS_EQUAL(252, thesis_environments()[9].thesis_pieces);
  CHECK(find_environment("corridor") != nullptr);
  CHECK(find_environment("no_such_room") == nullptr);
}

TEST(SyntheticRooms, ReadingsOfTheCentredCylinderLieOnItsWallWithTheThesisEvidence) {
  const SyntheticRoom room(*find_environment("cylinder_centre"));
  const std::vector<evidence::Reading> readings = room.generate_readings(2000, 7U);
  LONGS_EQUAL(2000, readings.size());
  for (const evidence::Reading& r : readings) {
    const Vec3 p = room.world_of(r);
    DOUBLES_EQUAL(2.5, distance_xy(p), 1e-4);
    CHECK(p.z >= -1e-5 && p.z <= 2.0 + 1e-5);
    DOUBLES_EQUAL(0.9, r.m, 1e-6);
    CHECK(r.alpha_rad >= 0.0F && r.alpha_rad < 6.2832F);
  }
}

TEST(SyntheticRooms, OutlierRowsMoveAboutFivePercentOfTheFeaturesToHalfTheirDistance) {
  const SyntheticRoom room(*find_environment("cylinder_centre_outliers"));
  const std::vector<evidence::Reading> readings = room.generate_readings(4000, 11U);
  std::size_t halves = 0;
  for (const evidence::Reading& r : readings) {
    const double rho = distance_xy(room.world_of(r));
    if (std::fabs(rho - 1.25) < 1e-4) {
      ++halves;
    } else {
      DOUBLES_EQUAL(2.5, rho, 1e-4);
    }
  }
  CHECK(halves > 140 && halves < 260);  // 5% of 4000 = 200
}

TEST(SyntheticRooms, TheBoxHidesWhatIsBehindItAndCarriesFeatures) {
  const SyntheticRoom room(*find_environment("cylinder_box_view1"));  // box at x ∈ [0.75, 1.25]
  CHECK(room.visible_free({0.5, 0.0, 0.3}));
  CHECK_FALSE(room.visible_free({1.0, 0.0, 0.3}));  // inside the box
  CHECK(room.solid({1.0, 0.0, 0.3}));
  CHECK_FALSE(room.visible_free({2.0, 0.0, 0.1}));  // occluded: unknown to the sensor
  CHECK_FALSE(room.solid({2.0, 0.0, 0.1}));
  CHECK(room.solid({2.6, 0.0, 1.0}));         // beyond the wall
  CHECK(room.visible_free({2.0, 0.0, 1.5}));  // above the box's shadow
  std::size_t on_box = 0;
  for (const evidence::Reading& r : room.generate_readings(3000, 3U)) {
    const Vec3 p = room.world_of(r);
    if (distance_xy(p) < 2.4) {
      CHECK(p.x >= 0.75 - 1e-4 && p.x <= 1.25 + 1e-4 && p.z <= 0.5 + 1e-4);
      ++on_box;
    }
  }
  CHECK(on_box > 0);
}

TEST(SyntheticRooms, RectangleReadingsLieOnOneOfTheFourWalls) {
  const SyntheticRoom room(*find_environment("rectangle"));
  for (const evidence::Reading& r : room.generate_readings(1000, 5U)) {
    const Vec3 p = room.world_of(r);
    const bool on_wall = std::fabs(p.x + 2.5) < 1e-4 || std::fabs(p.x - 2.5) < 1e-4 ||
                         std::fabs(p.y + 2.0) < 1e-4 || std::fabs(p.y - 2.5) < 1e-4;
    CHECK(on_wall);
  }
  const SyntheticRoom::Hit down = room.cast_from_sensor({0.0, 0.0, -1.0});
  DOUBLES_EQUAL(1.0, down.distance_m, 1e-12);  // the PTU centre is 1 m above the floor
  CHECK_FALSE(down.featured);
}

TEST(SyntheticRooms, TheSameSeedGivesTheSameReadings) {
  const SyntheticRoom room(*find_environment("cylinder_offcentre"));
  const std::vector<evidence::Reading> a = room.generate_readings(100, 42U);
  const std::vector<evidence::Reading> b = room.generate_readings(100, 42U);
  for (std::size_t i = 0; i < a.size(); ++i) {
    DOUBLES_EQUAL(a[i].r_m, b[i].r_m, 0.0);
    DOUBLES_EQUAL(a[i].alpha_rad, b[i].alpha_rad, 0.0);
  }
}
