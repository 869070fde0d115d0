// Tests of the snapshot writer: PNG size and colours read back, atomic files, no heap, the arena.
#include <dirent.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <span>
#include <string>
#include <vector>

#include "firmware/telemetry/snapshot.h"

#include "alloc_guard.h"
#include "png_image.h"
#include "CppUTest/TestHarness.h"

using boticelli::core::Point2;
using boticelli::firmware::kGridFree;
using boticelli::firmware::kGridOccupied;
using boticelli::firmware::kGridUnknown;
using boticelli::firmware::SnapshotCircle;
using boticelli::firmware::SnapshotExtent;
using boticelli::firmware::SnapshotFrame;
using boticelli::firmware::SnapshotPixel;
using boticelli::firmware::SnapshotReading;
using boticelli::firmware::SnapshotWriter;

namespace {

SnapshotWriter g_writer;  // ~3.1 MB: static storage, as on the robot

// A synthetic room: walls from (-1.5,-1.5) to (2.5,2.5), a cylinder at (1.5,1.5), the robot at the
// origin. Panels are laid out in a 5 m square view, 80 px/m.
constexpr std::array<Point2, 4> kWalls{
    {{-1.5F, -1.5F}, {2.5F, -1.5F}, {2.5F, 2.5F}, {-1.5F, 2.5F}}};
constexpr std::array<std::span<const Point2>, 1> kTruthPolygons{{std::span<const Point2>(kWalls)}};
constexpr std::array<SnapshotCircle, 1> kTruthCircles{{{{1.5F, 1.5F}, 0.3F}}};
constexpr std::array<SnapshotReading, 3> kReadings{
    {{0.5F, 2.5F, 1.0F}, {0.0F, 2.5F, 0.0F}, {2.5F, 0.5F, 0.5F}}};
constexpr std::array<Point2, 4> kFree{{{-1.3F, -1.3F}, {2.3F, -1.3F}, {2.3F, 2.3F}, {-1.3F, 2.3F}}};
constexpr std::array<Point2, 4> kNavigable{
    {{-1.1F, -1.1F}, {2.1F, -1.1F}, {2.1F, 2.1F}, {-1.1F, 2.1F}}};
constexpr std::array<Point2, 1> kObstacles{{{2.0F, -1.0F}}};
constexpr std::array<Point2, 1> kExploration{{{-1.0F, 1.8F}}};
constexpr std::array<Point2, 2> kPath{{{-1.0F, -1.0F}, {0.0F, 0.0F}}};

// Occupancy: 0 inside the walls, 1 outside.
float room_occupancy(const void* /*context*/, float x_m, float y_m) {
  return x_m > -1.5F && x_m < 2.5F && y_m > -1.5F && y_m < 2.5F ? 0.0F : 1.0F;
}
// V: highest at the goal (1, 2).
float goal_value(const void* context, float x_m, float y_m) {
  const auto* goal = static_cast<const Point2*>(context);
  return -((x_m - goal->x_m) * (x_m - goal->x_m) + (y_m - goal->y_m) * (y_m - goal->y_m));
}
constexpr Point2 kGoal{1.0F, 2.0F};
// The world memory: free inside the walls, occupied on a band along the right wall (x 2.5 to
// 2.9), unknown beyond.
float room_grid(const void* /*context*/, float x_m, float y_m) {
  if (y_m < -1.5F || y_m > 2.5F || x_m < -1.5F || x_m > 2.9F) return kGridUnknown;
  return x_m > 2.5F ? kGridOccupied : kGridFree;
}

SnapshotFrame synthetic_frame(std::uint32_t cycle) {
  SnapshotFrame f;
  f.cycle = cycle;
  f.state = "DRIVE";
  f.robot = {0.0F, 0.0F, 0.5F};
  f.robot_radius_m = 0.2F;
  f.view = SnapshotExtent{-2.0F, -2.0F, 3.0F, 3.0F};
  f.readings = kReadings;
  f.occupancy = room_occupancy;
  f.free_polygon = kFree;
  f.navigable_polygon = kNavigable;
  f.obstacle_points = kObstacles;
  f.exploration_points = kExploration;
  f.goal = kGoal;
  f.path = kPath;
  f.value = goal_value;
  f.value_context = &kGoal;
  f.step_end = Point2{0.3F, 0.4F};
  f.grid = room_grid;
  f.grid_goal = Point2{-0.5F, 2.2F};
  f.truth_polygons = kTruthPolygons;
  f.truth_circles = kTruthCircles;
  return f;
}

using Image = boticelli::test::RgbImage;
using boticelli::test::read_png;

std::array<int, 3> at(const Image& image, SnapshotPixel p) {
  return image.at(p.x, p.y);
}

std::vector<std::string> list_dir(const std::string& dir) {
  std::vector<std::string> names;
  if (DIR* d = opendir(dir.c_str())) {
    while (dirent* e = readdir(d)) {
      if (std::strcmp(e->d_name, ".") != 0 && std::strcmp(e->d_name, "..") != 0) {
        names.emplace_back(e->d_name);
      }
    }
    closedir(d);
  }
  std::sort(names.begin(), names.end());
  return names;
}

void remove_tree(const std::string& path) {
  struct stat st {};
  if (lstat(path.c_str(), &st) != 0) return;
  if (S_ISDIR(st.st_mode)) {
    for (const std::string& name : list_dir(path)) remove_tree(path + "/" + name);
    rmdir(path.c_str());
  } else {
    unlink(path.c_str());
  }
}

SnapshotPixel pixel(int panel, Point2 p) {
  return SnapshotWriter::pixel_of(SnapshotExtent{-2.0F, -2.0F, 3.0F, 3.0F}, panel, p);
}

using Colour = std::array<int, 3>;

}  // namespace

TEST_GROUP(SnapshotWriter) {
  std::string dir;
  char error[256] = {};

  void setup() override {
    char pattern[] = "/tmp/boticelli-snapshot-XXXXXX";
    CHECK(mkdtemp(pattern) != nullptr);
    dir = pattern;
    g_writer.limit_arena(0);
  }
  void teardown() override {
    g_writer.limit_arena(0);
    chmod(dir.c_str(), 0755);
    remove_tree(dir);
  }
};

TEST(SnapshotWriter, AWrittenFrameReadsBackAsAPngOfTheCanvasSize) {
  CHECK_TRUE_TEXT(g_writer.open(dir.c_str(), error, sizeof error), error);
  CHECK_TRUE_TEXT(g_writer.write(synthetic_frame(12), error, sizeof error), error);
  const std::vector<std::string> expected{"cycle-000012.png"};
  CHECK(expected == list_dir(dir));
  Image image;
  CHECK_TRUE(read_png(dir + "/cycle-000012.png", image));
  LONGS_EQUAL(SnapshotWriter::kWidthPx, image.width);
  LONGS_EQUAL(SnapshotWriter::kHeightPx, image.height);
  CHECK(std::equal(image.rgb.begin(), image.rgb.end(), g_writer.pixels()));
}

TEST(SnapshotWriter, TheRobotObstacleGoalAndTruthWallHaveTheirColoursInThePicture) {
  CHECK_TRUE_TEXT(g_writer.open(dir.c_str(), error, sizeof error), error);
  CHECK_TRUE_TEXT(g_writer.write(synthetic_frame(3), error, sizeof error), error);
  Image image;
  CHECK_TRUE(read_png(dir + "/cycle-000003.png", image));
  // Panel 3 (navigation): robot disc, obstacle point, exploration point, goal, polygon fills.
  CHECK((Colour{255, 140, 0}) == at(image, pixel(2, {0.05F, -0.1F})));
  CHECK((Colour{220, 0, 0}) == at(image, pixel(2, {2.0F, -1.0F})));
  CHECK((Colour{0, 90, 255}) == at(image, pixel(2, {-1.0F, 1.8F})));
  CHECK((Colour{0, 200, 200}) == at(image, pixel(2, {1.0F, 2.0F})));
  CHECK((Colour{170, 220, 170}) == at(image, pixel(2, {1.0F, -0.5F})));
  CHECK((Colour{225, 240, 225}) == at(image, pixel(2, {-1.2F, 0.5F})));
  // Under the polygons the world memory: free pale, occupied dark, unknown white, and the
  // plan's goal on it a cross.
  CHECK((Colour{232, 232, 232}) == at(image, pixel(2, {2.4F, 0.0F})));
  CHECK((Colour{70, 70, 70}) == at(image, pixel(2, {2.7F, 0.0F})));
  CHECK((Colour{255, 255, 255}) == at(image, pixel(2, {2.95F, -1.8F})));
  CHECK((Colour{150, 0, 200}) == at(image, pixel(2, {-0.5F, 2.2F})));
  // The true wall, thin, in every panel (here the left wall at y = 0.7 m).
  for (int panel = 0; panel < 4; ++panel) {
    CHECK((Colour{255, 0, 255}) == at(image, pixel(panel, {-1.5F, 0.7F})));
    CHECK((Colour{255, 0, 255}) != at(image, pixel(panel, {-1.5F - 2.0F / 80.0F, 0.7F})));
  }
  // Panel 1: brightness = evidence.
  CHECK((Colour{255, 255, 255}) == at(image, pixel(0, {0.5F, 2.5F})));
  CHECK((Colour{64, 64, 64}) == at(image, pixel(0, {0.0F, 2.5F})));
  CHECK((Colour{0, 0, 0}) == at(image, pixel(0, {1.0F, -0.7F})));
  // Panel 2: free is white, occupied is thresholded red.
  CHECK((Colour{255, 255, 255}) == at(image, pixel(1, {1.0F, -0.7F})));
  CHECK((Colour{110, 30, 30}) == at(image, pixel(1, {2.8F, 0.0F})));
  // Panel 4: V highest (red end of the map) at the goal, lowest (blue end) far from it.
  const Colour high = at(image, pixel(3, {1.0F, 2.0F}));
  const Colour low = at(image, pixel(3, {-1.95F, -1.95F}));
  CHECK(high[0] > 180 && high[2] < 60);
  CHECK(low[2] > 120 && low[0] < 60);
}

TEST(SnapshotWriter, WritingASnapshotMakesNoHeapAllocationAndFitsTheArena) {
  CHECK_TRUE_TEXT(g_writer.open(dir.c_str(), error, sizeof error), error);
  const SnapshotFrame frame = synthetic_frame(1);
  bool ok = false;
  CHECK_NO_ALLOCATION(ok = g_writer.write(frame, error, sizeof error));
  CHECK_TRUE_TEXT(ok, error);
  // libpng and zlib took everything from the arena (they are shared libraries, so the guard's
  // malloc wrappers cannot see them; the arena counts instead).
  CHECK(g_writer.arena_allocations_last() >= 4U);
  CHECK(g_writer.arena_bytes_last() > 200U * 1024U);  // zlib's deflate window and hash tables
  CHECK(g_writer.arena_bytes_last() <= SnapshotWriter::kArenaBytes * 3U / 4U);  // margin
  CHECK(g_writer.file_bytes_last() > 1000U);
}

TEST(SnapshotWriter, AnExhaustedArenaFailsCleanlyAndKeepsThePreviousFileWhole) {
  CHECK_TRUE_TEXT(g_writer.open(dir.c_str(), error, sizeof error), error);
  CHECK_TRUE_TEXT(g_writer.write(synthetic_frame(1), error, sizeof error), error);
  Image before;
  CHECK_TRUE(read_png(dir + "/cycle-000001.png", before));
  // Room for libpng's own structures and rows, not for zlib's deflate state: zlib's memory
  // comes through libpng's callbacks too. The same cycle again (a resumed mission) must not
  // damage the file already there.
  g_writer.limit_arena(64U * 1024U);
  SnapshotFrame moved = synthetic_frame(1);
  moved.robot.x_m = 1.0F;
  CHECK_FALSE(g_writer.write(moved, error, sizeof error));
  CHECK_TEXT(std::strstr(error, "arena") != nullptr, error);
  const std::vector<std::string> only_first{"cycle-000001.png"};
  CHECK(only_first == list_dir(dir));
  Image after;
  CHECK_TRUE(read_png(dir + "/cycle-000001.png", after));
  CHECK(before.rgb == after.rgb);
  g_writer.limit_arena(0);
  CHECK_TRUE_TEXT(g_writer.write(synthetic_frame(2), error, sizeof error), error);
  const std::vector<std::string> both{"cycle-000001.png", "cycle-000002.png"};
  CHECK(both == list_dir(dir));
}

TEST(SnapshotWriter, WrittenInStepsThePictureIsTheSameAndNoFileShowsBeforeTheLastStep) {
  CHECK_TRUE_TEXT(g_writer.open(dir.c_str(), error, sizeof error), error);
  CHECK_TRUE_TEXT(g_writer.write(synthetic_frame(4), error, sizeof error), error);
  Image whole;
  CHECK_TRUE(read_png(dir + "/cycle-000004.png", whole));
  CHECK_EQUAL(0, std::remove((dir + "/cycle-000004.png").c_str()));
  g_writer.begin(synthetic_frame(4));
  CHECK(g_writer.busy());
  std::size_t steps = 1;
  while (!g_writer.run_unit()) {
    ++steps;
    // Until the last step at most the temporary file exists.
    for (const std::string& name : list_dir(dir)) CHECK(name != "cycle-000004.png");
  }
  CHECK_TRUE_TEXT(g_writer.ok(), g_writer.error());
  CHECK_FALSE(g_writer.busy());
  // The paper in bands of kBandRows rows, title, readings, ten field bands, occupancy, ten
  // bands of the grid, navigation in three parts, ten bands, value, axes, open, the rows in
  // bands of kBandRows, finish.
  const auto field_bands =
      static_cast<std::size_t>((SnapshotWriter::kFieldCells + SnapshotWriter::kFieldBandRows - 1) /
                               SnapshotWriter::kFieldBandRows);
  const auto row_bands = static_cast<std::size_t>(
      (SnapshotWriter::kHeightPx + SnapshotWriter::kBandRows - 1) / SnapshotWriter::kBandRows);
  CHECK_EQUAL(
      row_bands + 2U + field_bands + 1U + field_bands + 3U + field_bands + 3U + row_bands + 1U,
      steps);
  Image stepped;
  CHECK_TRUE(read_png(dir + "/cycle-000004.png", stepped));
  CHECK(whole.rgb == stepped.rgb);
}

namespace {

// The most a mission's picture can hold: every reading a look keeps, polygons over the whole
// view, full point lists and path.
constexpr std::size_t kManyReadings = 28672;  // kMaxLookFeatures + kMaxLookFloorObstacles
std::array<SnapshotReading, kManyReadings> g_many_readings;
std::array<Point2, 4096> g_many_obstacles;
std::array<Point2, 1024> g_many_exploration;
std::array<Point2, 1024> g_long_path;
constexpr std::array<Point2, 4> kEverywhere{
    {{-50.0F, -50.0F}, {50.0F, -50.0F}, {50.0F, 50.0F}, {-50.0F, 50.0F}}};

SnapshotFrame crowded_frame() {
  for (std::size_t i = 0; i < g_many_readings.size(); ++i) {
    const float t = static_cast<float>(i) * 0.001F;
    g_many_readings[i] = {-1.9F + std::fmod(t * 7.0F, 4.8F), -1.9F + std::fmod(t * 3.0F, 4.8F),
                          static_cast<float>(i % 11) / 10.0F};
  }
  for (std::size_t i = 0; i < g_many_obstacles.size(); ++i) {
    const float t = static_cast<float>(i);
    g_many_obstacles[i] = {-1.9F + std::fmod(t * 0.037F, 4.8F),
                           -1.9F + std::fmod(t * 0.011F, 4.8F)};
  }
  for (std::size_t i = 0; i < g_many_exploration.size(); ++i) {
    const float t = static_cast<float>(i);
    g_many_exploration[i] = {-1.9F + std::fmod(t * 0.013F, 4.8F), 2.5F};
  }
  for (std::size_t i = 0; i < g_long_path.size(); ++i) {
    const float t = static_cast<float>(i) * 0.01F;
    g_long_path[i] = {2.0F * std::cos(t), 2.0F * std::sin(t)};
  }
  SnapshotFrame f = synthetic_frame(9);
  f.readings = g_many_readings;
  f.free_polygon = kEverywhere;
  f.navigable_polygon = kEverywhere;
  f.obstacle_points = g_many_obstacles;
  f.exploration_points = g_many_exploration;
  f.path = g_long_path;
  return f;
}

}  // namespace

TEST(SnapshotWriter, NoStepDoesMoreThanItsShareOfTheWorkHoweverFullThePicture) {
  // Work is counted, not timed: pixels written, rows encoded and field rows sampled per step.
  CHECK_TRUE_TEXT(g_writer.open(dir.c_str(), error, sizeof error), error);
  g_writer.begin(crowded_frame());
  std::uint64_t pixels = 0;
  int rows = 0;
  int field_rows = 0;
  std::uint64_t most_pixels = 0;
  bool done = false;
  for (int step = 0; step < 1000 && !done; ++step) {
    done = g_writer.run_unit();
    const SnapshotWriter::UnitWork& w = g_writer.last_unit_work();
    CHECK(w.pixels_written <= SnapshotWriter::kMaxUnitPixels);
    CHECK(w.rows_encoded <= SnapshotWriter::kBandRows);
    CHECK(w.field_rows <= SnapshotWriter::kFieldBandRows);
    pixels += w.pixels_written;
    rows += w.rows_encoded;
    field_rows += w.field_rows;
    most_pixels = std::max(most_pixels, w.pixels_written);
  }
  CHECK_TRUE(done);
  CHECK_TRUE_TEXT(g_writer.ok(), g_writer.error());
  // The counts are the whole picture's work: every pixel painted, every row encoded, the three
  // fields (occupancy, grid, value) sampled whole; and the fullest step is near its share (the
  // measure is real).
  CHECK(pixels >= static_cast<std::uint64_t>(SnapshotWriter::kWidthPx) * SnapshotWriter::kHeightPx);
  CHECK_EQUAL(SnapshotWriter::kHeightPx, rows);
  CHECK_EQUAL(3 * SnapshotWriter::kFieldCells, field_rows);
  CHECK(most_pixels > SnapshotWriter::kMaxUnitPixels / 2);
}

TEST(SnapshotWriter, AMissingDirectoryIsCreatedWithItsParents) {
  const std::string nested = dir + "/runs/seed-7";
  CHECK_TRUE_TEXT(g_writer.open(nested.c_str(), error, sizeof error), error);
  CHECK_TRUE_TEXT(g_writer.write(synthetic_frame(5), error, sizeof error), error);
  const std::vector<std::string> expected{"cycle-000005.png"};
  CHECK(expected == list_dir(nested));
}

TEST(SnapshotWriter, ADirectoryThatCannotBeCreatedOrWrittenIsRefusedWithAReason) {
  const std::string file = dir + "/plain-file";
  FILE* f = std::fopen(file.c_str(), "w");
  CHECK(f != nullptr);
  std::fclose(f);
  CHECK_FALSE(g_writer.open((file + "/snapshots").c_str(), error, sizeof error));
  CHECK_TEXT(std::strstr(error, "cannot create snapshot directory") != nullptr, error);
  CHECK_FALSE(g_writer.write(synthetic_frame(1), error, sizeof error));
  STRCMP_EQUAL("snapshot writer not opened", error);
  if (geteuid() != 0) {  // root may write anywhere
    const std::string locked = dir + "/locked";
    CHECK_EQUAL(0, mkdir(locked.c_str(), 0555));
    CHECK_FALSE(g_writer.open(locked.c_str(), error, sizeof error));
    CHECK_TEXT(std::strstr(error, "not writable") != nullptr, error);
    CHECK(list_dir(locked).empty());
  }
}

TEST(SnapshotWriter, ADirectoryRemovedAfterOpenGivesAnErrorAndNoFile) {
  const std::string sub = dir + "/gone";
  CHECK_TRUE_TEXT(g_writer.open(sub.c_str(), error, sizeof error), error);
  CHECK_EQUAL(0, rmdir(sub.c_str()));
  CHECK_FALSE(g_writer.write(synthetic_frame(9), error, sizeof error));
  CHECK_TEXT(std::strstr(error, "cycle-000009.png.tmp") != nullptr, error);
  CHECK(list_dir(dir).empty());
}
