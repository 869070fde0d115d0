// libFuzzer target: the sim board's world loader (SDF subset, tinyxml2) on arbitrary text.
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdlib>

#include "hal/sim/world.h"

namespace {
boticelli::hal::sim::World g_world;
char g_error[256];
}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  g_error[0] = '\0';
  if (!boticelli::hal::sim::parse_world(reinterpret_cast<const char*>(data), size, "fuzz.sdf",
                                        g_world, g_error, sizeof g_error)) {
    if (g_error[0] == '\0') std::abort();  // a rejection always says why
    return 0;
  }
  // An accepted world is finite: its start and its target point.
  if (!std::isfinite(g_world.start.x_m) || !std::isfinite(g_world.start.y_m) ||
      !g_world.target_point_m.allFinite()) {
    std::abort();
  }
  return 0;
}
