// Tests of world_geometry: disc clearance against analytic values, trace reading and checking
// (contacts between rows, malformed files), shortest paths, and the unseen test worlds.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <limits>
#include <numbers>
#include <string>
#include <unistd.h>
#include <vector>

#include "algo/stereo/rig.h"
#include "hal/sim/sim_world.h"
#include "hal/sim/textures.h"
#include "hal/sim/world.h"
#include "hal/sim/world_geometry.h"
#include "sim_test_worlds.h"

#include "CppUTest/TestHarness.h"

using namespace boticelli::hal::sim;
using boticelli::core::Point2;
using boticelli::hal::sim::test::small_world;

namespace {
World g_world;
TextureBank g_bank;
SimWorld g_sim;
char g_error[256];
constexpr float kRadius = 0.25F;
constexpr float kHeight = 0.8F;

bool parse(const std::string& xml) {
  return parse_world(xml.c_str(), xml.size(), "test.sdf", g_world, g_error, sizeof g_error);
}

std::string box(const char* name, const std::string& pose, const std::string& size) {
  return "<model name=\"" + std::string(name) + "\"><pose>" + pose +
         "</pose><link name=\"l\"><visual name=\"v\"><geometry><box><size>" + size +
         "</size></box></geometry></visual></link></model>\n";
}

std::string cylinder(const char* name, const std::string& pose, const char* radius,
                     const char* length) {
  return "<model name=\"" + std::string(name) + "\"><pose>" + pose +
         "</pose><link name=\"l\"><visual name=\"v\"><geometry><cylinder><radius>" + radius +
         "</radius><length>" + length + "</length></cylinder></geometry></visual></link></model>\n";
}

// Writes `text` to a fresh temporary file and returns its path.
std::string temp_file(const std::string& text) {
  char path[] = "/tmp/boticelli_trace_XXXXXX";
  const int fd = mkstemp(path);
  CHECK(fd >= 0);
  CHECK(write(fd, text.data(), text.size()) == static_cast<ssize_t>(text.size()));
  close(fd);
  return path;
}

const char* kHeader = "t_s,x_m,y_m,yaw_rad,pan_rad,tilt_rad,state\n";

std::string row(double t, double x, double y, const char* state = "drive") {
  char line[160];
  std::snprintf(line, sizeof line, "%.3f,%.4f,%.4f,0.0000,0.0000,0.0000,%s\n", t, x, y, state);
  return line;
}

TraceCheck check_text(const std::string& text) {
  const std::string path = temp_file(text);
  std::vector<TraceRow> rows;
  std::string error;
  const bool ok = read_trace(path.c_str(), rows, error);
  unlink(path.c_str());
  CHECK_TEXT(ok, error.c_str());
  return check_trace(g_world, rows, kRadius, kHeight);
}

// Analytic signed distance from (x, y) to a box footprint centred at (cx, cy), turned by yaw.
double box_distance(double x, double y, double cx, double cy, double yaw, double hx, double hy) {
  const double c = std::cos(yaw);
  const double s = std::sin(yaw);
  const double lx = std::fabs(c * (x - cx) + s * (y - cy));
  const double ly = std::fabs(-s * (x - cx) + c * (y - cy));
  if (lx <= hx && ly <= hy) return -std::min(hx - lx, hy - ly);
  return std::hypot(std::max(lx - hx, 0.0), std::max(ly - hy, 0.0));
}

std::string test_world_path(const char* name) {
  // BOTICELLI_WORLDS_DIR is <source>/boards/sim/worlds.
  return std::string(BOTICELLI_WORLDS_DIR) + "/../../../tests/worlds/" + name + ".sdf";
}
}  // namespace

TEST_GROUP(WorldGeometry){void setup() override{g_error[0] = '\0';
}
}
;

TEST(WorldGeometry, ReversalsCountOnlyTheTimesThePathTurnsBackOnItself) {
  std::vector<TraceRow> rows;
  const auto at = [&rows](double x, double y) {
    TraceRow r{};
    r.x_m = x;
    r.y_m = y;
    rows.push_back(r);
  };
  // East 1 m, a right angle north 1 m (no reversal), back south 1 m (one), in 5 cm rows.
  for (int i = 0; i <= 20; ++i) at(0.05 * i, 0.0);
  for (int i = 1; i <= 20; ++i) at(1.0, 0.05 * i);
  for (int i = 1; i <= 20; ++i) at(1.0, 1.0 - 0.05 * i);
  LONGS_EQUAL(1, boticelli::hal::sim::count_reversals(rows));
  // Jitter within a stretch (a turn in place, 1 cm back and forth) is no reversal.
  for (int i = 0; i < 10; ++i) at(1.0 + 0.01 * (i % 2), 0.0);
  LONGS_EQUAL(1, boticelli::hal::sim::count_reversals(rows));
  // Then west along y = 0 (a right angle from south: none), east and west again: two more.
  for (int k = 0; k < 3; ++k) {
    for (int i = 1; i <= 20; ++i) at(k % 2 == 0 ? 1.0 - 0.05 * i : 0.05 * i, 0.0);
  }
  LONGS_EQUAL(3, boticelli::hal::sim::count_reversals(rows));
  LONGS_EQUAL(0, boticelli::hal::sim::count_reversals({}));
}

TEST(WorldGeometry, ClearanceToARotatedBoxIsTheDistanceToItsTurnedOutline) {
  const double yaw = 0.5;
  CHECK_TEXT(parse(small_world(box("crate", "2 1 0.5 0 0 0.5", "1.0 0.4 1"), "-2 -2 0 0 0 0")),
             g_error);
  int inside = 0;
  for (int i = 0; i <= 40; ++i) {
    for (int j = 0; j <= 40; ++j) {
      const double x = 0.5 + 3.0 * i / 40.0;
      const double y = -0.5 + 3.0 * j / 40.0;
      const double expected = box_distance(x, y, 2.0, 1.0, yaw, 0.5, 0.2) - double{kRadius};
      inside += expected < -double{kRadius} ? 1 : 0;
      const float got =
          disc_clearance_m(g_world, static_cast<float>(x), static_cast<float>(y), kRadius, kHeight);
      DOUBLES_EQUAL(expected, got, 2e-5);
    }
  }
  CHECK(inside > 10);  // points inside the box were checked too (negative clearance)
}

TEST(WorldGeometry, ClearanceToACylinderIsTheCentreDistanceMinusBothRadii) {
  CHECK_TEXT(parse(small_world(cylinder("pillar", "1 2 0.5 0 0 0", "0.15", "1"), "-2 -2 0 0 0 0")),
             g_error);
  DOUBLES_EQUAL(std::hypot(2.0, 2.0) - 0.4, disc_clearance_m(g_world, 3.0F, 4.0F, 0.25F, 0.8F),
                1e-5);
  DOUBLES_EQUAL(0.5 - 0.4, disc_clearance_m(g_world, 1.0F, 1.5F, 0.25F, 0.8F), 1e-5);
  // Overlapping: 0.1 m between centres, 0.3 m of penetration.
  DOUBLES_EQUAL(-0.3, disc_clearance_m(g_world, 1.1F, 2.0F, 0.25F, 0.8F), 1e-5);
  // A bigger robot is closer by the radius difference.
  DOUBLES_EQUAL(0.5 - 0.55, disc_clearance_m(g_world, 1.0F, 1.5F, 0.4F, 0.8F), 1e-5);
}

TEST(WorldGeometry, ObstaclesBelowTheFloorClearanceOrAboveTheRobotAreIgnored) {
  // A cable 5 mm high and a lintel from 0.9 m up; the target box (0.85 to 1.15 m) is above
  // a 0.8 m robot too.
  const std::string models =
      box("cable", "1 0 0.0025 0 0 0", "0.05 3 0.005") + box("lintel", "0 1 1 0 0 0", "2 0.2 0.2");
  CHECK_TEXT(parse(small_world(models, "-2 -2 0 0 0 0")), g_error);
  CHECK(std::isinf(disc_clearance_m(g_world, 1.0F, 0.0F, kRadius, kHeight)));
  // A taller robot hits the lintel and the target.
  DOUBLES_EQUAL(0.9 - 0.25, disc_clearance_m(g_world, 0.0F, 0.0F, kRadius, 1.0F), 1e-5);
  CHECK(disc_clearance_m(g_world, -3.9F, 0.0F, kRadius, 1.0F) < 0.0F);
}

TEST(WorldGeometry, ATraceGrazingAPillarBetweenRowsIsCaught) {
  // Pillar of radius 5 cm at (1, 0.5): with the robot's 25 cm the centre must stay 0.30 m
  // away. The robot passes along y = 0.22 (0.28 m from the pillar's centre) with rows 1 m
  // apart on either side: both rows are 0.27 m clear, the segment between them is not.
  CHECK_TEXT(
      parse(small_world(cylinder("pillar", "1 0.5 0.5 0 0 0", "0.05", "1"), "0 0.22 0 0 0 0")),
      g_error);
  const std::string trace = std::string(kHeader) + row(0.0, 0.5, 0.22) + row(1.0, 1.5, 0.22) +
                            row(1.5, 2.0, 0.22, "look");
  CHECK(disc_clearance_m(g_world, 0.5F, 0.22F, kRadius, kHeight) > 0.25F);
  CHECK(disc_clearance_m(g_world, 1.5F, 0.22F, kRadius, kHeight) > 0.25F);
  const TraceCheck check = check_text(trace);
  UNSIGNED_LONGS_EQUAL(3, check.rows);
  UNSIGNED_LONGS_EQUAL(1, check.collisions);
  DOUBLES_EQUAL(-0.02, check.min_clearance_m, 1e-3);
  DOUBLES_EQUAL(1.0, check.max_gap_s, 1e-9);
  DOUBLES_EQUAL(1.5, check.path_length_m, 1e-9);
}

TEST(WorldGeometry, ABumpIsOneEpisodeAndTouchingAgainAfterBackingOffIsAnother) {
  // Wall face at x = 1 (box from 1 to 1.2): the disc touches when its centre is at x = 0.75.
  CHECK_TEXT(parse(small_world(box("wall", "1.1 0 1 0 0 0", "0.2 4 2"))), g_error);
  std::string trace = kHeader;
  double t = 0.0;
  // Approach, stop 0.2 mm short (as the simulator does), jitter within 5 mm, back off 5 cm,
  // come back to 0.1 mm short.
  const double xs[] = {0.5, 0.6, 0.7, 0.7498, 0.7498, 0.746, 0.7499, 0.7, 0.72, 0.7499, 0.6};
  for (double x : xs) {
    trace += row(t, x, 0.0);
    t += 0.1;
  }
  const TraceCheck check = check_text(trace);
  UNSIGNED_LONGS_EQUAL(2, check.collisions);
  DOUBLES_EQUAL(0.0001, check.min_clearance_m, 2e-5);
  // Kept 2 cm away, nothing is counted.
  const TraceCheck clear =
      check_text(std::string(kHeader) + row(0, 0.5, 0) + row(0.1, 0.73, 0) + row(0.2, 0.6, 0));
  UNSIGNED_LONGS_EQUAL(0, clear.collisions);
  DOUBLES_EQUAL(0.02, clear.min_clearance_m, 1e-5);
}

TEST(WorldGeometry, ATraceWithMoreColumnsIsReadRowByRow) {
  const std::string path = temp_file(
      "t_s,x_m,y_m,yaw_rad,pan_rad,tilt_rad,state,odo_x_m,odo_y_m,odo_yaw_rad\n"
      "0.000,1.0000,2.0000,0.5000,-0.1000,0.1344,look,0.0000,0.0000,0.0000\n"
      "0.100,1.0300,2.0000,0.5000,-0.1000,0.0000,drive,0.0300,0.0000,0.0000\n");
  std::vector<TraceRow> rows;
  std::string error;
  CHECK_TEXT(read_trace(path.c_str(), rows, error), error.c_str());
  unlink(path.c_str());
  UNSIGNED_LONGS_EQUAL(2, rows.size());
  DOUBLES_EQUAL(2.0, rows[0].y_m, 1e-12);
  DOUBLES_EQUAL(0.1344, rows[0].tilt_rad, 1e-12);
  STRCMP_EQUAL("drive", rows[1].state);
  DOUBLES_EQUAL(0.1, rows[1].t_s, 1e-12);
  CHECK_FALSE(rows[0].has_pose_columns);  // odometry without the estimate: not read
}

// The firmware's odometry and estimate columns, wherever the header puts them, are read into
// each row; a value there that is not a finite number is refused with its column's name.
TEST(WorldGeometry, ATracesOdometryAndEstimateColumnsAreReadByName) {
  const std::string head =
      "t_s,x_m,y_m,yaw_rad,pan_rad,tilt_rad,state,est_x_m,est_y_m,est_yaw_rad,odo_x_m,odo_y_m,"
      "odo_yaw_rad\n";
  const std::string path =
      temp_file(head + "0.000,1.0000,2.0000,0.5000,0,0,look,0.1000,0.2000,0.3000,0.4,0.5,0.6\n");
  std::vector<TraceRow> rows;
  std::string error;
  CHECK_TEXT(read_trace(path.c_str(), rows, error), error.c_str());
  unlink(path.c_str());
  CHECK(rows[0].has_pose_columns);
  DOUBLES_EQUAL(0.4, rows[0].odo[0], 1e-12);
  DOUBLES_EQUAL(0.5, rows[0].odo[1], 1e-12);
  DOUBLES_EQUAL(0.6, rows[0].odo[2], 1e-12);
  DOUBLES_EQUAL(0.1, rows[0].est[0], 1e-12);
  DOUBLES_EQUAL(0.2, rows[0].est[1], 1e-12);
  DOUBLES_EQUAL(0.3, rows[0].est[2], 1e-12);
  const std::string bad = temp_file(head + "0.000,1,2,0.5,0,0,look,0.1,nan,0.3,0.4,0.5,0.6\n");
  CHECK_FALSE(read_trace(bad.c_str(), rows, error));
  unlink(bad.c_str());
  CHECK_TEXT(error.find(":2: est_y_m 'nan' is not a finite number") != std::string::npos,
             error.c_str());
}

TEST(WorldGeometry, AMalformedTraceIsRejectedWithFileLineAndWhy) {
  struct Bad {
    std::string text;
    int line;
    const char* why;
  };
  const std::string h = kHeader;
  const Bad cases[] = {
      {"", 1, "empty file"},
      {"t_s,x,y_m,yaw_rad,pan_rad,tilt_rad,state\n" + row(0, 0, 0), 1, "expected 'x_m'"},
      {"t_s,x_m,y_m,yaw_rad,pan_rad,tilt_rad\n", 1, "expected 'state'"},
      {h, 2, "no rows"},
      {h + row(0, 0, 0) + "0.1,0.5,abc,0,0,0,drive\n", 3, "y_m 'abc' is not a finite number"},
      {h + row(0, 0, 0) + "0.1,0.5,0,0,0,drive\n", 3, "6 fields, the header has 7"},
      {h + row(0, 0, 0) + "0.1,0.5,0,0,0,0,drive,extra\n", 3, "8 fields"},
      {h + row(0, 0, 0) + "0.1,nan,0,0,0,0,drive\n", 3, "x_m 'nan' is not a finite number"},
      {h + row(0, 0, 0) + "0.1,1e999,0,0,0,0,drive\n", 3, "not a finite number"},
      {h + row(0, 0, 0) + "0.1,0.5,0,0,0,0,\n", 3, "empty state"},
      {h + row(0, 0, 0) + "0.1,0.5,0,0,0,0,a_state_name_far_too_long\n", 3, "longer than 23"},
      {h + row(1.0, 0, 0) + row(0.9, 0, 0), 3, "goes back in time"},
      {h + row(0, 0, 0) + "\n" + row(0.1, 0, 0), 3, "blank line"},
  };
  for (const Bad& bad : cases) {
    const std::string path = temp_file(bad.text);
    std::vector<TraceRow> rows;
    std::string error;
    CHECK_FALSE_TEXT(read_trace(path.c_str(), rows, error), bad.why);
    unlink(path.c_str());
    const std::string expected_prefix = path + ":" + std::to_string(bad.line) + ": ";
    STRNCMP_EQUAL_TEXT(expected_prefix.c_str(), error.c_str(), expected_prefix.size(),
                       error.c_str());
    CHECK_TEXT(error.find(bad.why) != std::string::npos, error.c_str());
    CHECK(rows.empty());
  }
  std::vector<TraceRow> rows;
  std::string error;
  CHECK_FALSE(read_trace("/nonexistent/run.csv", rows, error));
  CHECK_TEXT(error.find("/nonexistent/run.csv:0: cannot open") == 0, error.c_str());
  // A trailing newline (or several) at the end is not an error.
  const std::string path = temp_file(h + row(0, 0, 0) + "\n\n");
  CHECK_TEXT(read_trace(path.c_str(), rows, error), error.c_str());
  unlink(path.c_str());
}

TEST(WorldGeometry, TheShortestPathInTheOpenIsTheStraightLineToTheGoalCircle) {
  CHECK_TEXT(parse(small_world("", "0 0 0 0 0 0")), g_error);
  const struct {
    Point2 goal;
    float radius;
  } cases[] = {
      {{3.0F, 0.0F}, 0.5F}, {{2.0F, 1.3F}, 0.3F}, {{-1.7F, 2.9F}, 0.0F}, {{0.9F, -3.1F}, 1.0F}};
  for (const auto& c : cases) {
    const double expected = std::hypot(c.goal.x_m, c.goal.y_m) - c.radius;
    const double got = shortest_path_m(g_world, {0.0F, 0.0F}, c.goal, c.radius, kRadius, kHeight);
    // In the open the first leg already goes straight to the goal circle: exact, not grid-bound.
    DOUBLES_EQUAL(expected, got, 1e-3 * expected);
    CHECK(got >= expected - 1e-6);  // never shorter than the straight line
  }
  DOUBLES_EQUAL(0.0, shortest_path_m(g_world, {0, 0}, {0.3F, 0}, 0.5F, kRadius, kHeight), 0.0);
}

TEST(WorldGeometry, TheShortestPathAroundAWallHugsItsRoundedEnd) {
  // Wall 0.1 x 2 m centred at the origin, start (-1, 0), goal (1, 0). The disc's centre must
  // keep 0.25 m off the wall: around the wall's top end the path is a tangent to the circle of
  // radius 0.25 m round the corner (-0.05, 1), an arc to its top, 0.1 m straight, and the
  // mirror image.
  CHECK_TEXT(parse(small_world(box("wall", "0 0 1 0 0 0", "0.1 2 2"), "-1 0 0 0 0 0")), g_error);
  const double r = 0.25;
  const double dx = 0.95;
  const double dy = 1.0;
  const double d = std::hypot(dx, dy);
  const double tangent = std::sqrt(d * d - r * r);
  // Angle at the corner between the direction to the start and the tangent point, and the
  // arc from the tangent point to the top of the circle.
  const double to_start = std::atan2(-dy, -dx);              // direction corner → start
  const double tangent_angle = to_start - std::acos(r / d);  // clockwise of it: the left side
  const double arc = (tangent_angle + 2.0 * std::numbers::pi) - std::numbers::pi / 2.0;
  const double expected = 2.0 * (tangent + r * arc) + 0.1;
  const double got = shortest_path_m(g_world, {-1.0F, 0.0F}, {1.0F, 0.0F}, 0.0F, kRadius, kHeight);
  DOUBLES_EQUAL(expected, got, 0.01 * expected);
  CHECK(got > expected - 1e-3);  // a grid path cannot beat the true optimum
  // With a goal radius of 0.4 m, the path ends on the goal circle.
  const double shorter =
      shortest_path_m(g_world, {-1.0F, 0.0F}, {1.0F, 0.0F}, 0.4F, kRadius, kHeight);
  CHECK(shorter < got - 0.2);
}

TEST(WorldGeometry, AGoalBehindAGapNarrowerThanTheRobotOrInsideAClosedBoxIsUnreachable) {
  // A closed 2 x 2 m pen around the goal (walls 0.1 m thick), with a 0.45 m gap in one wall:
  // too narrow for a 0.5 m robot, wide enough for a 0.2 m one.
  const std::string pen = box("north", "5 1 0.5 0 0 0", "2.1 0.1 1") +
                          box("south", "5 -1 0.5 0 0 0", "2.1 0.1 1") +
                          box("east", "6 0 0.5 0 0 0", "0.1 2.1 1") +
                          box("west_a", "4 0.6375 0.5 0 0 0", "0.1 0.825 1") +
                          box("west_b", "4 -0.6375 0.5 0 0 0", "0.1 0.825 1");
  CHECK_TEXT(parse(small_world(pen, "1 0 0 0 0 0")), g_error);
  CHECK(std::isinf(shortest_path_m(g_world, {1.0F, 0.0F}, {5.0F, 0.0F}, 0.3F, kRadius, kHeight)));
  const double small = shortest_path_m(g_world, {1.0F, 0.0F}, {5.0F, 0.0F}, 0.3F, 0.1F, kHeight);
  DOUBLES_EQUAL(4.0 - 0.3, small, 0.02 * 3.7);
  // A gap 4 mm wider than the robot is found, one 4 mm narrower is not.
  const double wide = shortest_path_m(g_world, {1.0F, 0.0F}, {5.0F, 0.0F}, 0.3F, 0.223F, kHeight);
  DOUBLES_EQUAL(4.0 - 0.3, wide, 0.02 * 3.7);
  CHECK(std::isinf(shortest_path_m(g_world, {1.0F, 0.0F}, {5.0F, 0.0F}, 0.3F, 0.227F, kHeight)));
  // A start that overlaps an obstacle has no collision-free path at all.
  CHECK(std::isinf(shortest_path_m(g_world, {4.1F, 1.0F}, {1.0F, 0.0F}, 0.3F, kRadius, kHeight)));
}

TEST(WorldGeometry, NoGridMoveJumpsAWallThinnerThanAMove) {
  // A 1 cm thick closed pen and a 5 mm robot: its obstacle is 2 cm wide, less than a diagonal
  // or knight move of the 2.5 cm grid, which must not step across it.
  const std::string pen =
      box("north", "5 1 0.5 0 0 0", "2.01 0.01 1") + box("south", "5 -1 0.5 0 0 0", "2.01 0.01 1") +
      box("east", "6 0 0.5 0 0 0", "0.01 2.01 1") + box("west", "4 0 0.5 0 0 0", "0.01 2.01 1");
  CHECK_TEXT(parse(small_world(pen, "1 0 0 0 0 0")), g_error);
  CHECK(std::isinf(shortest_path_m(g_world, {1.0F, 0.3F}, {5.0F, 0.0F}, 0.3F, 0.005F, kHeight)));
  CHECK(std::isinf(shortest_path_m(g_world, {5.0F, 0.3F}, {1.0F, 0.0F}, 0.3F, 0.005F, kHeight)));
}

TEST(WorldGeometry, EveryUnseenTestWorldIsClosedWithAFreeStartAndAReachableTarget) {
  const boticelli::stereo::RigModel rig;
  const char* const worlds[] = {"two_rooms_far_target",
                                "l_corridor",
                                "round_room_pillars",
                                "cluttered_low_boxes_table",
                                "featureless_wall",
                                "partition_gap_west",
                                "long_hall_far_target",
                                "patterned_floor",
                                "skewed_pentagon_crates",
                                "gallery_alcove",
                                "rug_room",
                                "wood_floor_boxes"};
  for (const char* name : worlds) {
    const std::string path = test_world_path(name);
    CHECK_TEXT(load_world(path.c_str(), g_world, g_error, sizeof g_error), g_error);
    CHECK_TEXT(g_bank.build(g_world, g_error, sizeof g_error), g_error);
    CHECK_TEXT(g_sim.init(g_world, rig, SimParams{}, g_error, sizeof g_error), g_error);
    const Point2 start{g_world.start.x_m, g_world.start.y_m};
    CHECK_TEXT(disc_clearance_m(g_world, start.x_m, start.y_m, kRadius, kHeight) >= 0.35F, name);
    const Point2 target{g_world.target_point_m.x(), g_world.target_point_m.y()};
    CHECK_TEXT(g_world.target_point_m.z() > 0.3F && g_world.target_point_m.z() < 2.0F, name);
    // Reachable: the robot's centre gets within 0.5 m of the target (the wall is 5 mm behind
    // the paper, the disc 0.25 m wide).
    const double path_m = shortest_path_m(g_world, start, target, 0.5F, kRadius, kHeight);
    CHECK_TEXT(std::isfinite(path_m), name);
    const double straight_m =
        std::hypot(double{target.x_m} - double{start.x_m}, double{target.y_m} - double{start.y_m});
    CHECK_TEXT(path_m >= straight_m - 0.5 - 1e-3, name);
    // Closed: from the start, no point 1 m beyond the walls' outline can be reached.
    float max_x = -1e9F;
    for (std::size_t i = 0; i < g_world.collider_count; ++i) {
      const Collider& c = g_world.colliders[i];
      if (c.circle) max_x = std::max(max_x, c.centre_x_m + c.radius_m);
      for (std::size_t k = 0; k < c.hull_size; ++k) max_x = std::max(max_x, c.hull[k].x_m);
    }
    CHECK_TEXT(std::isinf(shortest_path_m(g_world, start, {max_x + 1.0F, start.y_m}, 0.1F, kRadius,
                                          kHeight)),
               name);
  }
}
