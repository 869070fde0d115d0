// Looks the mission got stuck on, replayed from their recorded readings through the mission's
// own Think stage (make_mission_params of the sim board): each must leave the robot room.
#include <cmath>
#include <cstdio>
#include <string>

#include "algo/core/fixed_vector.h"
#include "algo/evidence/reading.h"
#include "algo/mapping/extraction.h"
#include "algo/mapping/local_model_builder.h"
#include "board_config.h"
#include "firmware/mission/params/mission_params.h"

#include "CppUTest/TestHarness.h"

namespace mapping = boticelli::mapping;
using boticelli::core::FixedVector;
using boticelli::evidence::Reading;

namespace {

struct RecordedLook {
  FixedVector<Reading, 16384> features;
  FixedVector<Reading, 8192> obstacles;
  FixedVector<Reading, 4096> free;
};

// Reads "KIND alpha h r m" lines (KIND F, O or L); '#' lines are comments.
bool load_look(const char* name, RecordedLook& look) {
  const std::string path = std::string(BOTICELLI_TEST_DATA_DIR) + "/" + name;
  FILE* f = std::fopen(path.c_str(), "r");
  if (f == nullptr) return false;
  char line[160];
  bool ok = true;
  while (ok && std::fgets(line, sizeof line, f) != nullptr) {
    if (line[0] == '#') continue;
    char kind = 0;
    Reading r{};
    if (std::sscanf(line, "%c %f %f %f %f", &kind, &r.alpha_rad, &r.h_m, &r.r_m, &r.m) != 5) {
      ok = false;
    } else if (kind == 'F') {
      ok = look.features.push_back(r);
    } else if (kind == 'O') {
      ok = look.obstacles.push_back(r);
    } else if (kind == 'L') {
      ok = look.free.push_back(r);
    } else {
      ok = false;
    }
  }
  std::fclose(f);
  return ok;
}

RecordedLook g_look;
mapping::LocalModelBuilder g_builder;

}  // namespace

TEST_GROUP(LookRegressions){};

// l_shaped_room, seed 1: the robot stood 0.43 m from a wall, 0.8 m from the confirmed target.
// Nothing over the PTU is in the camera's view that close (the top slice, 0.8 m, is seen only
// from 0.62 m on), and the fit rose to m_safe at 0.18 m there, inside the robot's own body:
// no navigable point, no step, and after three such looks the mission ended not found.
TEST(LookRegressions, BesideAWallTheFreePolygonKeepsTheRobotsDiscAndLeavesRoomToMove) {
  g_look = RecordedLook{};
  CHECK_TRUE(load_look("look_beside_wall_l_shaped_room.txt", g_look));
  CHECK(g_look.features.size() > 4000);
  const auto params =
      boticelli::firmware::mission::make_mission_params(boticelli::boards::sim::make_config());
  g_builder.start(params.model, g_look.features.span(), g_look.obstacles.span(),
                  g_look.free.span());
  g_builder.run();
  // The free polygon keeps the robot's disc and margin (the fit's crossings nearer than that
  // are its extrapolation), and there is room to move away from the wall.
  const mapping::ExtractionParams& e = params.model.extraction;
  const mapping::LocalMap& map = g_builder.map();
  for (std::size_t k = 0; k < map.free.vertex_count(); ++k) {
    CHECK(map.free.rho_m(k) >= e.robot_radius_m + e.clearance_margin_m);
  }
  CHECK_TRUE(map.can_move);
  float room = 0.0F;
  for (std::size_t k = 0; k < map.navigable.vertex_count(); ++k) {
    room = std::fmax(room, map.navigable.rho_m(k));
  }
  CHECK_TEXT(room > 0.4F, "no step of 0.4 m in any direction");
}
