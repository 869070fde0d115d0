// The [sim] table of the configuration file (see sim_config.h).
#include "sim_config.h"

#include <cmath>
#include <cstdio>
#include <cstring>

namespace boticelli::boards::sim {

bool add_sim_config_keys(firmware::ConfigSchema& s, SimConfigKeys& k) {
  k = SimConfigKeys{};
  using firmware::ConfigKey;
  return s.add(ConfigKey::interface_name("sim", "realism", k.realism)) &&
         s.add(ConfigKey::number("sim", "wheel_scale_left", k.wheel_scale_left, 0.9, 1.1)) &&
         s.add(ConfigKey::number("sim", "wheel_scale_right", k.wheel_scale_right, 0.9, 1.1)) &&
         s.add(ConfigKey::number("sim", "track_scale", k.track_scale, 0.9, 1.1)) &&
         s.add(ConfigKey::number("sim", "turn_scrub", k.turn_scrub, 0.0, 0.2)) &&
         s.add(ConfigKey::number("sim", "odometry_noise", k.odometry_noise, 0.0, 0.2));
}

bool apply_sim_config(const SimConfigKeys& k, SimSettings& settings, char* error,
                      std::size_t error_size) {
  hal::sim::BaseParams& b = settings.physics.base;
  const char* r = k.realism.data();
  if (r[0] != '\0') {
    if (std::strcmp(r, "realistic") == 0) {
      apply_realism(SimRealism::kRealistic, b);
    } else if (std::strcmp(r, "ideal") == 0) {
      apply_realism(SimRealism::kIdeal, b);
    } else {
      std::snprintf(error, error_size, "sim.realism = \"%s\" must be realistic or ideal", r);
      return false;
    }
  }
  const auto set = [](float key, float& value) {
    if (!std::isnan(key)) value = key;
  };
  set(k.wheel_scale_left, b.wheel_scale_left);
  set(k.wheel_scale_right, b.wheel_scale_right);
  set(k.track_scale, b.track_scale);
  set(k.turn_scrub, b.turn_scrub);
  set(k.odometry_noise, b.odometry_noise);
  return true;
}

}  // namespace boticelli::boards::sim
