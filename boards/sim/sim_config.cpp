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
         s.add(ConfigKey::number("sim", "odometry_noise", k.odometry_noise, 0.0, 0.2)) &&
         s.add(ConfigKey::number("sim", "lens_k1_error", k.lens_k1_error, -0.3, 0.3)) &&
         s.add(ConfigKey::number("sim", "lens_k2_error", k.lens_k2_error, -0.5, 0.5)) &&
         s.add(ConfigKey::number("sim", "lens_p1_error", k.lens_p1_error, -0.01, 0.01)) &&
         s.add(ConfigKey::number("sim", "lens_p2_error", k.lens_p2_error, -0.01, 0.01)) &&
         s.add(ConfigKey::number("sim", "focal_scale", k.focal_scale, 0.9, 1.1)) &&
         s.add(ConfigKey::number("sim", "principal_error_px", k.principal_error_px, -20.0, 20.0)) &&
         s.add(ConfigKey::number("sim", "lever_error_m", k.lever_error_m, -0.02, 0.02)) &&
         s.add(ConfigKey::number("sim", "ptu_backlash_rad", k.ptu_backlash_rad, 0.0, 0.01)) &&
         s.add(ConfigKey::number("sim", "chroma_noise", k.chroma_noise, 0.0, 20.0)) &&
         s.add(ConfigKey::number("sim", "exposure_jitter", k.exposure_jitter, 0.0, 0.2));
}

bool apply_sim_config(const SimConfigKeys& k, SimSettings& settings, char* error,
                      std::size_t error_size) {
  hal::sim::BaseParams& b = settings.physics.base;
  const char* r = k.realism.data();
  if (r[0] != '\0') {
    if (std::strcmp(r, "realistic") == 0) {
      apply_realism(SimRealism::kRealistic, settings);
    } else if (std::strcmp(r, "ideal") == 0) {
      apply_realism(SimRealism::kIdeal, settings);
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
  SimOptics& o = settings.optics;
  set(k.lens_k1_error, o.lens_k1_error);
  set(k.lens_k2_error, o.lens_k2_error);
  set(k.lens_p1_error, o.lens_p1_error);
  set(k.lens_p2_error, o.lens_p2_error);
  set(k.focal_scale, o.focal_scale);
  set(k.principal_error_px, o.principal_error_px);
  set(k.lever_error_m, o.lever_error_m);
  set(k.ptu_backlash_rad, settings.physics.ptu.backlash_rad);
  set(k.chroma_noise, settings.render.chroma_noise_sigma);
  set(k.exposure_jitter, settings.render.exposure_jitter);
  return true;
}

}  // namespace boticelli::boards::sim
