// Map export: the world memory written as a ROS map_server pair (a PGM picture and its YAML).
#pragma once

#include <cstddef>
#include <string>

#include "algo/worldmap/grid_map.h"

namespace boticelli::firmware {

// The grid's cells in the tiles' bounding box as a binary PGM (P5), one byte a cell, top row
// first: 0 occupied, 254 free, 205 unknown (map_server's trinary convention).
std::string map_pgm(const worldmap::GridMap& grid);
// The YAML that tells map_server (and anyone) where `image`'s lower-left corner lies in the
// mission frame and how big a cell is.
std::string map_yaml(const worldmap::GridMap& grid, const char* image);

// Writes PREFIX.pgm and PREFIX.yaml, each atomically (docs/console.md, `--map`). A map with
// no tile yet is written as a 1×1 unknown picture at the origin. Not for the cyclic path (it
// allocates and fsyncs): the firmware calls it once the mission has stopped. False with a
// one-line reason.
bool write_map_files(const worldmap::GridMap& grid, const char* prefix, char* error,
                     std::size_t error_size);

}  // namespace boticelli::firmware
