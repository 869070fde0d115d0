// Tests of the synthetic range data of the thesis's simulated rooms (tools/bench/synthetic_rooms).
#include <algorithm>
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

TEST(SyntheticRooms, TheCameraSeesTheBoxFromAboveAndInFrontAndNeverTheFloor) {
  const SyntheticRoom room(*find_environment("cylinder_box_view1"));  // box at x ∈ [0.75, 1.25]
  const std::vector<evidence::Reading> readings =
      room.generate_camera_readings(CameraScan{}, 3000, 3U);
  LONGS_EQUAL(3000, readings.size());
  std::size_t on_top = 0;
  std::size_t on_front = 0;
  for (const evidence::Reading& r : readings) {
    const Vec3 p = room.world_of(r);
    CHECK(p.z > 1e-4);  // the floor has no features
    if (distance_xy(p) < 2.5 - 1e-4) {
      CHECK(p.x >= 0.75 - 1e-4 && p.x <= 1.25 + 1e-4 && p.z <= 0.5 + 1e-4);
      on_top += std::fabs(p.z - 0.5) < 1e-4 ? 1 : 0;
      on_front += std::fabs(p.x - 0.75) < 1e-4 ? 1 : 0;
    } else {
      DOUBLES_EQUAL(2.5, distance_xy(p), 1e-4);
    }
    // The first surface on the line of sight: the way there is free and seen.
    const Vec3 s = room.sensor();
    const Vec3 before{s.x + 0.98 * (p.x - s.x), s.y + 0.98 * (p.y - s.y), s.z + 0.98 * (p.z - s.z)};
    CHECK(room.visible_free(before));
  }
  // The box fills about 1/50 of the 0.5-rad-down images' field: dozens of features each side.
  CHECK(on_top > 20);
  CHECK(on_front > 20);
}

TEST(SyntheticRooms, TheCameraCoversEveryPanDirectionAndTheWallsFromFootToTop) {
  const SyntheticRoom room(*find_environment("rectangle"));
  const std::vector<evidence::Reading> readings =
      room.generate_camera_readings(CameraScan{}, 3000, 9U);
  std::vector<int> sectors(36, 0);
  double z_min = 10.0;
  double z_max = -10.0;
  for (const evidence::Reading& r : readings) {
    const Vec3 p = room.world_of(r);
    z_min = std::min(z_min, p.z);
    z_max = std::max(z_max, p.z);
    ++sectors[static_cast<std::size_t>(static_cast<double>(r.alpha_rad) / (2.0 * 3.14159266) *
                                       36.0) %
              36];
  }
  for (const int count : sectors) {
    CHECK(count > 20);  // 3000 / 36 ≈ 83 on average
  }
  CHECK(z_min < 0.2);
  CHECK(z_max > 1.7);
}

TEST(SyntheticRooms, TheSameSeedGivesTheSameCameraReadingsAndAnotherSeedOthers) {
  const SyntheticRoom room(*find_environment("cylinder_box_view2"));
  const std::vector<evidence::Reading> a = room.generate_camera_readings(CameraScan{}, 200, 42U);
  const std::vector<evidence::Reading> b = room.generate_camera_readings(CameraScan{}, 200, 42U);
  const std::vector<evidence::Reading> c = room.generate_camera_readings(CameraScan{}, 200, 43U);
  LONGS_EQUAL(a.size(), b.size());
  bool differs = false;
  for (std::size_t i = 0; i < a.size(); ++i) {
    DOUBLES_EQUAL(a[i].r_m, b[i].r_m, 0.0);
    DOUBLES_EQUAL(a[i].alpha_rad, b[i].alpha_rad, 0.0);
    differs = differs || a[i].alpha_rad != c[i].alpha_rad;
  }
  CHECK(differs);
}

TEST(SyntheticRooms, TheStereosRangeErrorScalesEachRangeByALaplaceDrawOfItsScale) {
  const SyntheticRoom room(*find_environment("cylinder_centre"));  // walls 2.5 m away
  CameraScan scan;
  scan.range_error_b = kStereoRangeErrorB;
  const std::vector<evidence::Reading> readings =
      room.generate_camera_readings(scan, 4000, 5U, 0.0);
  LONGS_EQUAL(4000, readings.size());
  // Each reading keeps its line of sight; only its range moves: e = r / r_true − 1.
  std::vector<double> abs_error;
  double sum = 0.0;
  for (const evidence::Reading& r : readings) {
    const Vec3 p = room.world_of(r);
    const Vec3 s = room.sensor();
    const double r_m = static_cast<double>(r.r_m);
    const Vec3 dir{(p.x - s.x) / r_m, (p.y - s.y) / r_m, (p.z - s.z) / r_m};
    const double e = r_m / room.cast_from_sensor(dir).distance_m - 1.0;
    sum += e;
    abs_error.push_back(std::fabs(e));
  }
  std::sort(abs_error.begin(), abs_error.end());
  const auto quantile = [&](double q) {
    return abs_error[static_cast<std::size_t>(q * static_cast<double>(abs_error.size() - 1))];
  };
  // Laplace(b): |e| has median b ln 2 and 90th percentile b ln 10; its mean is 0.
  DOUBLES_EQUAL(kStereoRangeErrorB * std::log(2.0), quantile(0.5), 0.1 * kStereoRangeErrorB);
  DOUBLES_EQUAL(kStereoRangeErrorB * std::log(10.0), quantile(0.9), 0.25 * kStereoRangeErrorB);
  DOUBLES_EQUAL(0.0, sum / static_cast<double>(readings.size()), 0.1 * kStereoRangeErrorB);
  // Without it the ranges are exact.
  for (const evidence::Reading& r : room.generate_camera_readings(CameraScan{}, 500, 5U, 0.0)) {
    DOUBLES_EQUAL(2.5, distance_xy(room.world_of(r)), 1e-4);
  }
}
