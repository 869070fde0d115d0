// Tests of the configuration file's [sim] table: the realism setting and its keys.
#include <cmath>
#include <cstring>
#include <numbers>
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
  // The camera as a calibration leaves it, the rig's play and the sensor's noise.
  DOUBLES_EQUAL(1.01, s.optics.focal_scale, 1e-6);
  DOUBLES_EQUAL(0.01, s.optics.lens_k1_error, 1e-6);
  DOUBLES_EQUAL(-0.02, s.optics.lens_k2_error, 1e-6);
  DOUBLES_EQUAL(0.0005, s.optics.lens_p1_error, 1e-7);
  DOUBLES_EQUAL(-0.0005, s.optics.lens_p2_error, 1e-7);
  DOUBLES_EQUAL(2.0, s.optics.principal_error_px, 1e-6);
  DOUBLES_EQUAL(0.002, s.optics.lever_error_m, 1e-7);
  DOUBLES_EQUAL(0.05 * std::numbers::pi / 180.0, s.physics.ptu.backlash_rad, 1e-7);
  DOUBLES_EQUAL(1.5, s.render.chroma_noise_sigma, 1e-6);
  DOUBLES_EQUAL(0.02, s.render.exposure_jitter, 1e-6);
  CHECK_TEXT(settings_from("[sim]\nrealism = \"ideal\"\n", s), g_error);
  DOUBLES_EQUAL(1.0, s.optics.focal_scale, 0.0);
  DOUBLES_EQUAL(0.0, s.optics.lens_k1_error, 0.0);
  DOUBLES_EQUAL(0.0, s.optics.lens_k2_error, 0.0);
  DOUBLES_EQUAL(0.0, s.optics.lens_p1_error, 0.0);
  DOUBLES_EQUAL(0.0, s.optics.lens_p2_error, 0.0);
  DOUBLES_EQUAL(0.0, s.optics.principal_error_px, 0.0);
  DOUBLES_EQUAL(0.0, s.optics.lever_error_m, 0.0);
  DOUBLES_EQUAL(0.0, s.physics.ptu.backlash_rad, 0.0);
  DOUBLES_EQUAL(0.0, s.render.chroma_noise_sigma, 0.0);
  DOUBLES_EQUAL(0.0, s.render.exposure_jitter, 0.0);
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

TEST(SimConfig, EachOpticsKeySetsItsErrorAndTheTrueRigCarriesThem) {
  sim::SimSettings s;
  CHECK_TEXT(settings_from("[sim]\nlens_k1_error = -0.15\nlens_k2_error = 0.1\n"
                           "lens_p1_error = 0.001\nlens_p2_error = -0.002\nfocal_scale = 0.98\n"
                           "principal_error_px = -3\nlever_error_m = 0.005\n"
                           "ptu_backlash_rad = 0.003\nchroma_noise = 2.5\nexposure_jitter = 0.1\n",
                           s),
             g_error);
  DOUBLES_EQUAL(0.003, s.physics.ptu.backlash_rad, 1e-7);
  DOUBLES_EQUAL(2.5, s.render.chroma_noise_sigma, 1e-6);
  DOUBLES_EQUAL(0.1, s.render.exposure_jitter, 1e-7);
  const boticelli::firmware::BoardConfig config = sim::make_config();
  const boticelli::stereo::RigParams nominal = sim::make_rig_params(config);
  const boticelli::stereo::RigParams truth = sim::true_rig_params(config, s.optics);
  DOUBLES_EQUAL(nominal.camera.k1 - 0.15F, truth.camera.k1, 1e-6);
  DOUBLES_EQUAL(nominal.camera.k2 + 0.1F, truth.camera.k2, 1e-6);
  DOUBLES_EQUAL(nominal.camera.p1 + 0.001F, truth.camera.p1, 1e-7);
  DOUBLES_EQUAL(nominal.camera.p2 - 0.002F, truth.camera.p2, 1e-7);
  DOUBLES_EQUAL(nominal.camera.focal_px * 0.98F, truth.camera.focal_px, 1e-3);
  DOUBLES_EQUAL(nominal.camera.principal_x_px - 3.0F, truth.camera.principal_x_px, 1e-4);
  DOUBLES_EQUAL(nominal.camera.principal_y_px + 3.0F, truth.camera.principal_y_px, 1e-4);
  DOUBLES_EQUAL(nominal.lever_m + 0.005F, truth.lever_m, 1e-6);
  // Without errors the true rig is the configured one.
  const boticelli::stereo::RigParams same = sim::true_rig_params(config, sim::SimOptics{});
  DOUBLES_EQUAL(nominal.camera.focal_px, same.camera.focal_px, 0.0);
  DOUBLES_EQUAL(nominal.lever_m, same.lever_m, 0.0);
  CHECK_FALSE(settings_from("[sim]\nfocal_scale = 1.2\n", s));
  STRCMP_CONTAINS("sim.focal_scale", g_error);
  CHECK_FALSE(settings_from("[sim]\nptu_backlash_rad = -0.001\n", s));
  STRCMP_CONTAINS("sim.ptu_backlash_rad", g_error);
}
