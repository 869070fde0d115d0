// The configuration file's [sim] table: the one place for the simulator's realism settings
// (how far the simulated robot departs from the thesis's perfect one).
#pragma once

#include <cstddef>
#include <limits>

#include "board_config.h"
#include "firmware/app/config_file.h"

namespace boticelli::boards::sim {

// What a configuration file said in [sim]; a key it did not name stays unset (NaN, or an
// empty realism), and the settings the board already holds are kept for it.
struct SimConfigKeys {
  firmware::DeviceName realism{};  // "realistic" or "ideal": every realism key at once
  float wheel_scale_left = std::numeric_limits<float>::quiet_NaN();
  float wheel_scale_right = std::numeric_limits<float>::quiet_NaN();
  float track_scale = std::numeric_limits<float>::quiet_NaN();
  float turn_scrub = std::numeric_limits<float>::quiet_NaN();
  float odometry_noise = std::numeric_limits<float>::quiet_NaN();
  float lens_k1_error = std::numeric_limits<float>::quiet_NaN();
  float lens_k2_error = std::numeric_limits<float>::quiet_NaN();
  float lens_p1_error = std::numeric_limits<float>::quiet_NaN();
  float lens_p2_error = std::numeric_limits<float>::quiet_NaN();
  float focal_scale = std::numeric_limits<float>::quiet_NaN();
  float principal_error_px = std::numeric_limits<float>::quiet_NaN();
  float lever_error_m = std::numeric_limits<float>::quiet_NaN();
  float ptu_backlash_rad = std::numeric_limits<float>::quiet_NaN();
  float chroma_noise = std::numeric_limits<float>::quiet_NaN();
  float exposure_jitter = std::numeric_limits<float>::quiet_NaN();
};

// Binds the [sim] keys to `keys` (all unset).
bool add_sim_config_keys(firmware::ConfigSchema& schema, SimConfigKeys& keys);
// Applies what the file set: `realism` first (the whole setting), then each key it named on
// top. False, with "sim.realism = "x" must be realistic or ideal", for an unknown setting.
bool apply_sim_config(const SimConfigKeys& keys, SimSettings& settings, char* error,
                      std::size_t error_size);

}  // namespace boticelli::boards::sim
