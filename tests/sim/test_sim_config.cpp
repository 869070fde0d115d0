// Tests of the configuration file's [sim] table: the realism setting and its keys.
#include <cmath>
#include <cstring>
#include <string_view>

#include "board_config.h"
#include "firmware/app/config_file.h"
#include "sim_config.h"

#include "CppUTest/TestHarness.h"

namespace sim = boticelli::boards::sim;
using boticelli::firmware::ConfigSchema;

namespace {

ConfigSchema g_schema;
sim::SimConfigKeys g_keys;
char g_error[256];

// The settings a configuration text makes of the compiled-in ones (false: refused).
bool settings_from(std::string_view text, sim::SimSettings& s) {
  g_schema.clear();
  CHECK(sim::add_sim_config_keys(g_schema, g_keys));
  s = sim::make_settings(sim::make_config(), 1);
  if (!boticelli::firmware::apply_config_text(text, "test.conf", g_schema, g_error,
                                              sizeof g_error)) {
    return false;
  }
  return sim::apply_sim_config(g_keys, s, g_error, sizeof g_error);
}

}  // namespace

TEST_GROUP(SimConfig){};

TEST(SimConfig, RealisticSetsAnUncalibratedBaseAndIdealAPerfectOne) {
  sim::SimSettings s;
  CHECK_TEXT(settings_from("[sim]\nrealism = \"realistic\"\n", s), g_error);
  DOUBLES_EQUAL(0.005, s.physics.base.wheel_scale_left - s.physics.base.wheel_scale_right, 1e-6);
  DOUBLES_EQUAL(1.01, s.physics.base.track_scale, 1e-6);
  DOUBLES_EQUAL(0.01, s.physics.base.turn_scrub, 1e-6);
  CHECK(s.physics.base.odometry_noise > 0.0F);
  CHECK_TEXT(settings_from("[sim]\nrealism = \"ideal\"\n", s), g_error);
  DOUBLES_EQUAL(1.0, s.physics.base.wheel_scale_left, 0.0);
  DOUBLES_EQUAL(1.0, s.physics.base.wheel_scale_right, 0.0);
  DOUBLES_EQUAL(1.0, s.physics.base.track_scale, 0.0);
  DOUBLES_EQUAL(0.0, s.physics.base.turn_scrub, 0.0);
  DOUBLES_EQUAL(0.0, s.physics.base.odometry_noise, 0.0);
}

TEST(SimConfig, AKeyBesideTheRealismOverridesItAndAFileWithoutTheTableKeepsTheDefault) {
  sim::SimSettings s;
  CHECK_TEXT(settings_from("[sim]\ntrack_scale = 1.03\nrealism = \"realistic\"\n", s), g_error);
  DOUBLES_EQUAL(1.03, s.physics.base.track_scale, 1e-6);
  DOUBLES_EQUAL(0.01, s.physics.base.turn_scrub, 1e-6);
  sim::SimSettings defaults = sim::make_settings(sim::make_config(), 1);
  CHECK_TEXT(settings_from("", s), g_error);
  DOUBLES_EQUAL(defaults.physics.base.track_scale, s.physics.base.track_scale, 0.0);
  DOUBLES_EQUAL(defaults.physics.base.wheel_scale_left, s.physics.base.wheel_scale_left, 0.0);
}

TEST(SimConfig, AnUnknownRealismOrAValueOutOfRangeIsRefused) {
  sim::SimSettings s;
  CHECK_FALSE(settings_from("[sim]\nrealism = \"perfect\"\n", s));
  STRCMP_EQUAL("sim.realism = \"perfect\" must be realistic or ideal", g_error);
  CHECK_FALSE(settings_from("[sim]\ntrack_scale = 1.5\n", s));
  STRCMP_CONTAINS("sim.track_scale", g_error);
}
