// Map export: the world memory as a map_server PGM/YAML pair (see map_export.h).
#include "firmware/telemetry/map_export.h"

#include <cstdio>
#include <cstring>

#include "firmware/state/atomic_file.h"

namespace boticelli::firmware {
namespace {

constexpr unsigned char kOccupied = 0;
constexpr unsigned char kFree = 254;
constexpr unsigned char kUnknown = 205;

// The picture's cell box: the tiles in use, or one cell at the origin.
void picture_box(const worldmap::GridMap& grid, worldmap::Cell& lo, worldmap::Cell& hi) {
  if (!grid.tile_bounds(lo, hi)) {
    lo = {0, 0};
    hi = {1, 1};
  }
}

}  // namespace

std::string map_pgm(const worldmap::GridMap& grid) {
  worldmap::Cell lo, hi;
  picture_box(grid, lo, hi);
  const int width = hi.ix - lo.ix;
  const int height = hi.iy - lo.iy;
  char header[64];
  const int n = std::snprintf(header, sizeof header, "P5\n%d %d\n255\n", width, height);
  std::string out(header, static_cast<std::size_t>(n));
  out.reserve(out.size() + static_cast<std::size_t>(width) * static_cast<std::size_t>(height));
  for (int iy = hi.iy - 1; iy >= lo.iy; --iy) {
    for (int ix = lo.ix; ix < hi.ix; ++ix) {
      const worldmap::CellState s = grid.state({ix, iy});
      out.push_back(static_cast<char>(s == worldmap::CellState::kOccupied ? kOccupied
                                      : s == worldmap::CellState::kFree   ? kFree
                                                                          : kUnknown));
    }
  }
  return out;
}

std::string map_yaml(const worldmap::GridMap& grid, const char* image) {
  worldmap::Cell lo, hi;
  picture_box(grid, lo, hi);
  const double cell = static_cast<double>(grid.cell_m());
  char text[512];
  const int n = std::snprintf(
      text, sizeof text,
      "# The mission's world memory at the end of the run, in the mission frame (odometry at "
      "start).\nimage: %s\nresolution: %.6f\norigin: [%.6f, %.6f, 0.0]\nnegate: 0\n"
      "occupied_thresh: 0.65\nfree_thresh: 0.196\n",
      image, cell, lo.ix * cell, lo.iy * cell);
  return {text, static_cast<std::size_t>(n)};
}

bool write_map_files(const worldmap::GridMap& grid, const char* prefix, char* error,
                     std::size_t error_size) {
  // PREFIX = DIR/NAME (DIR "." when there is no slash).
  const char* slash = std::strrchr(prefix, '/');
  char dir[512];
  const char* name = slash != nullptr ? slash + 1 : prefix;
  if (slash == nullptr) {
    std::snprintf(dir, sizeof dir, ".");
  } else if (slash == prefix) {
    std::snprintf(dir, sizeof dir, "/");
  } else {
    std::snprintf(dir, sizeof dir, "%.*s", static_cast<int>(slash - prefix), prefix);
  }
  if (*name == '\0' || std::strlen(prefix) >= sizeof dir - 8) {
    std::snprintf(error, error_size, "--map %s: needs DIR/NAME (NAME.pgm and NAME.yaml)", prefix);
    return false;
  }
  char pgm_name[512];
  char yaml_name[512];
  std::snprintf(pgm_name, sizeof pgm_name, "%s.pgm", name);
  std::snprintf(yaml_name, sizeof yaml_name, "%s.yaml", name);
  return write_file_atomically(dir, pgm_name, map_pgm(grid), error, error_size) &&
         write_file_atomically(dir, yaml_name, map_yaml(grid, pgm_name), error, error_size);
}

}  // namespace boticelli::firmware
