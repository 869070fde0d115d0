// Tests of the map export: the world memory as a map_server PGM/YAML pair.
#include <cstdio>
#include <string>

#include "algo/worldmap/grid_map.h"
#include "firmware/telemetry/map_export.h"

#include "CppUTest/TestHarness.h"
#include "test_files.h"

namespace wm = boticelli::worldmap;
using boticelli::firmware::map_pgm;
using boticelli::firmware::map_yaml;
using boticelli::firmware::write_map_files;

namespace {
wm::GridMap g_grid;  // large: static

// The byte of cell (ix, iy) in a PGM of the box lo..hi (top row first).
unsigned char pixel(const std::string& pgm, std::size_t header, wm::Cell lo, wm::Cell hi, int ix,
                    int iy) {
  const int width = hi.ix - lo.ix;
  const std::size_t at = header + static_cast<std::size_t>((hi.iy - 1 - iy) * width + (ix - lo.ix));
  return static_cast<unsigned char>(pgm.at(at));
}
}  // namespace

TEST_GROUP(MapExport){void setup() override{g_grid.configure({});
}
}
;

TEST(MapExport, ThePictureShowsEachCellAtItsPlaceTopRowFirst) {
  CHECK(g_grid.add({-3, 5}, 10));    // occupied, in the tile at (-16, 0)
  CHECK(g_grid.add({20, -1}, -10));  // free, in the tile at (16, -16)
  const std::string pgm = map_pgm(g_grid);
  const std::string header = "P5\n48 32\n255\n";
  CHECK_EQUAL(header, pgm.substr(0, header.size()));
  LONGS_EQUAL(header.size() + 48 * 32, pgm.size());
  const wm::Cell lo{-16, -16}, hi{32, 16};
  LONGS_EQUAL(0, pixel(pgm, header.size(), lo, hi, -3, 5));
  LONGS_EQUAL(254, pixel(pgm, header.size(), lo, hi, 20, -1));
  LONGS_EQUAL(205, pixel(pgm, header.size(), lo, hi, 20, 0));
  LONGS_EQUAL(205, pixel(pgm, header.size(), lo, hi, -3, 4));
  STRCMP_CONTAINS("resolution: 0.050000\norigin: [-0.800000, -0.800000, 0.0]\n",
                  map_yaml(g_grid, "m.pgm").c_str());
  STRCMP_CONTAINS("image: m.pgm\n", map_yaml(g_grid, "m.pgm").c_str());
}

TEST(MapExport, AnEmptyMapIsOneUnknownCellAtTheOrigin) {
  CHECK_EQUAL(std::string("P5\n1 1\n255\n\xcd"), map_pgm(g_grid));
  STRCMP_CONTAINS("origin: [0.000000, 0.000000, 0.0]", map_yaml(g_grid, "m.pgm").c_str());
}

TEST(MapExport, WritesBothFilesBesideEachOtherAndSaysWhyItCannot) {
  CHECK(g_grid.add({0, 0}, 10));
  const std::string dir = boticelli::test::temp_dir("map-export");
  char error[256] = "";
  CHECK_TEXT(write_map_files(g_grid, (dir + "/end").c_str(), error, sizeof error), error);
  CHECK_EQUAL(map_pgm(g_grid), boticelli::test::read_file(dir + "/end.pgm"));
  STRCMP_CONTAINS("image: end.pgm\n", boticelli::test::read_file(dir + "/end.yaml").c_str());
  CHECK_FALSE(write_map_files(g_grid, (dir + "/missing/end").c_str(), error, sizeof error));
  STRCMP_CONTAINS("missing", error);
  CHECK_FALSE(write_map_files(g_grid, (dir + "/").c_str(), error, sizeof error));
  STRCMP_CONTAINS("needs DIR/NAME", error);
  std::remove((dir + "/end.pgm").c_str());
  std::remove((dir + "/end.yaml").c_str());
  std::remove(dir.c_str());
}
