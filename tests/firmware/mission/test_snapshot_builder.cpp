// Tests of the snapshot builder: the cycle's picture put together in the mission frame (the
// look's readings from the look's pose, the true walls from the world, the view around the
// robot and its path), read back from the writer's canvas.
#include <unistd.h>

#include <array>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <memory>
#include <span>
#include <string>

#include <Eigen/Core>

#include "algo/core/angles.h"
#include "algo/core/geometry.h"
#include "algo/evidence/reading.h"
#include "algo/mapping/local_model_builder.h"
#include "algo/mapping/map_points.h"
#include "algo/planning/planner.h"
#include "algo/planning/value_iteration.h"
#include "firmware/mission/look/look_processor.h"
#include "firmware/mission/snapshot_builder.h"
#include "firmware/telemetry/snapshot.h"
#include "firmware/telemetry/truth_source.h"

#include "CppUTest/TestHarness.h"

using boticelli::core::kPi;
using boticelli::core::Point2;
using boticelli::core::Pose2;
using boticelli::firmware::SnapshotExtent;
using boticelli::firmware::SnapshotPixel;
using boticelli::firmware::SnapshotWriter;
using boticelli::firmware::TruthSource;
using namespace boticelli::firmware::mission;

namespace {

SnapshotWriter g_writer;  // ~3.1 MB: static storage, as on the robot

using Colour = std::array<int, 3>;
constexpr Colour kTruth{255, 0, 255};
constexpr Colour kWhite{255, 255, 255};

// A box on the world's floor, 1 m wide, its near face 1.5 m ahead of the world's origin.
constexpr std::array<Point2, 4> kBox{{{1.5F, -0.5F}, {2.5F, -0.5F}, {2.5F, 0.5F}, {1.5F, 0.5F}}};
constexpr std::array<std::span<const Point2>, 1> kOutlines{{std::span<const Point2>(kBox)}};

class BoxTruth final : public TruthSource {
 public:
  Pose2 robot_pose() const override { return {}; }
  Pose2 odometry_origin() const override { return {}; }
  Eigen::Vector3f target_m() const override { return Eigen::Vector3f::Zero(); }
  std::span<const std::span<const Point2>> outlines() const override { return kOutlines; }
};

Colour colour_at(SnapshotPixel p) {
  const std::uint8_t* px =
      g_writer.pixels() +
      (static_cast<std::size_t>(p.y) * SnapshotWriter::kWidthPx + static_cast<std::size_t>(p.x)) *
          3U;
  return {px[0], px[1], px[2]};
}

// Whether a pixel of `colour` lies within `reach` pixels of the world point `p` in `panel`.
bool colour_near(const SnapshotExtent& view, int panel, Point2 p, const Colour& colour, int reach) {
  const SnapshotPixel c = SnapshotWriter::pixel_of(view, panel, p);
  for (int dy = -reach; dy <= reach; ++dy) {
    for (int dx = -reach; dx <= reach; ++dx) {
      if (colour_at({c.x + dx, c.y + dy}) == colour) return true;
    }
  }
  return false;
}

}  // namespace

TEST_GROUP(SnapshotBuilder) {
  std::string dir;
  char error[256] = {};
  std::unique_ptr<LookReadings> readings;
  std::unique_ptr<boticelli::mapping::LocalModelBuilder> builder;
  std::unique_ptr<boticelli::mapping::GlobalMap> map;
  std::unique_ptr<boticelli::planning::ValueIteration> value;
  boticelli::planning::StepDecision decision;
  BoxTruth truth;

  void setup() override {
    char pattern[] = "/tmp/boticelli-snapshot-builder-XXXXXX";
    CHECK(mkdtemp(pattern) != nullptr);
    dir = pattern;
    readings = std::make_unique<LookReadings>();
    builder = std::make_unique<boticelli::mapping::LocalModelBuilder>();
    map = std::make_unique<boticelli::mapping::GlobalMap>();
    value = std::make_unique<boticelli::planning::ValueIteration>();
  }
  void teardown() override {
    (void)std::remove((dir + "/cycle-000007.png").c_str());
    (void)rmdir(dir.c_str());
    readings.reset();
    builder.reset();
    map.reset();
    value.reset();
  }

  SnapshotInputs inputs() {
    SnapshotInputs in;
    in.cycle = 7;
    in.state = "think";
    in.readings = readings.get();
    in.builder = builder.get();
    in.map = map.get();
    in.value = value.get();
    in.decision = &decision;
    return in;
  }
  void draw(const SnapshotInputs& in) {
    CHECK_TRUE_TEXT(g_writer.open(dir.c_str(), error, sizeof error), error);
    begin_snapshot(in, g_writer);
    while (!g_writer.run_unit()) {
    }
    CHECK_TRUE_TEXT(g_writer.ok(), g_writer.error());
  }
};

TEST(SnapshotBuilder, TheTrueWallsAreDrawnWhereTheyLieInTheMissionFrame) {
  SnapshotInputs in = inputs();
  in.truth = &truth;
  // The mission frame's origin stands at the world's origin, turned a quarter turn left: the
  // box's near face (x = 1.5 m in the world) lies across y = -1.5 m in the mission frame.
  in.frame_origin_in_world = {0.0F, 0.0F, kPi<float> / 2.0F};
  draw(in);
  const SnapshotExtent view{-3.5F, -3.5F, 3.5F, 3.5F};  // 3.5 m around the robot at (0, 0)
  for (int panel = 0; panel < 4; ++panel) {
    CHECK(colour_near(view, panel, {0.2F, -1.5F}, kTruth, 1));
    CHECK(colour_near(view, panel, {-0.3F, -1.5F}, kTruth, 1));
    CHECK_FALSE(colour_near(view, panel, {1.5F, 0.2F}, kTruth, 3));  // where it is in the world
  }
}

TEST(SnapshotBuilder, TheLooksReadingsAreDrawnFromTheLooksPoseInAViewThatHoldsThePath) {
  SnapshotInputs in = inputs();
  // A reading 1 m ahead of the look, with full evidence; the look faced +y from (1, 1).
  (void)readings->features.push_back(boticelli::evidence::reading_at(1.0F, 0.0F, -0.2F, 1.0F));
  in.look_pose = {1.0F, 1.0F, kPi<float> / 2.0F};
  // The robot ended the cycle at (0.5, 0); its path went out to (5, 0) before.
  in.robot = {0.5F, 0.0F, 0.0F};
  const std::array<Point2, 2> path{{{5.0F, 0.0F}, {0.5F, 0.0F}}};
  in.path = path;
  draw(in);
  // The view: 3.5 m around the robot, and 1 m around every point of the path.
  const SnapshotExtent view{-3.0F, -3.5F, 6.0F, 3.5F};
  CHECK(colour_near(view, 0, {1.0F, 2.0F}, kWhite, 1));
  CHECK_FALSE(colour_near(view, 0, {2.0F, 1.0F}, kWhite, 2));  // as if the look faced +x
}
