// Tests of Breadcrumbs: the way back along the robot's own steps.
#include "firmware/mission/drive/breadcrumbs.h"

#include "CppUTest/TestHarness.h"

using boticelli::core::Point2;
using boticelli::firmware::mission::Breadcrumbs;

TEST_GROUP(Breadcrumbs) {
  Breadcrumbs crumbs;
  Point2 out{};
};

TEST(Breadcrumbs, BacksOffToWhereTheLastStepBeganThenOneStepFurther) {
  crumbs.step_started({0.0F, 0.0F});
  crumbs.step_started({1.0F, 0.0F});
  CHECK(crumbs.back_target({1.5F, 0.0F}, 0.05F, out));
  DOUBLES_EQUAL(1.0, out.x_m, 0.0);
  crumbs.reached();
  CHECK(crumbs.back_target({1.0F, 0.0F}, 0.05F, out));
  DOUBLES_EQUAL(0.0, out.x_m, 0.0);
  crumbs.reached();
  CHECK_FALSE(crumbs.back_target({0.0F, 0.0F}, 0.05F, out));
}

TEST(Breadcrumbs, SkipsACrumbTheRobotStandsOnAlready) {
  crumbs.step_started({0.0F, 0.0F});
  crumbs.step_started({1.0F, 0.0F});
  // A step that began at 1 m and was cut after 3 cm: back off to the step before.
  CHECK(crumbs.back_target({1.03F, 0.0F}, 0.05F, out));
  DOUBLES_EQUAL(0.0, out.x_m, 0.0);
  CHECK_EQUAL(1U, crumbs.size());
}

TEST(Breadcrumbs, KeepsTheNewestWhenFull) {
  for (std::size_t i = 0; i < Breadcrumbs::kCapacity + 5; ++i) {
    crumbs.step_started({static_cast<float>(i), 0.0F});
  }
  CHECK_EQUAL(Breadcrumbs::kCapacity, crumbs.size());
  CHECK(crumbs.back_target({1000.0F, 0.0F}, 0.05F, out));
  DOUBLES_EQUAL(static_cast<double>(Breadcrumbs::kCapacity + 4), out.x_m, 0.0);
  std::size_t left = 0;
  while (crumbs.back_target({-1.0F, 0.0F}, 0.05F, out)) {
    ++left;
    crumbs.reached();
  }
  CHECK_EQUAL(Breadcrumbs::kCapacity, left);
  DOUBLES_EQUAL(5.0, out.x_m, 0.0);  // the oldest kept: the first five went
}
