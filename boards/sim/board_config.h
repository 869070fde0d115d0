// sim board config: the simulated robot (same geometry as the reference robot), camera, PTU,
// rates and capacities, as data (wiring in sim_board.cpp).
#pragma once

#include <cstdint>

#include "algo/stereo/rig.h"
#include "firmware/app/board.h"
#include "firmware/mission/params/mission_params.h"
#include "hal/sim/renderer.h"
#include "hal/sim/sim_world.h"

namespace boticelli::boards::sim {

// The robot the firmware is told about (thesis §3.4, App. A): the sim draws exactly this.
inline firmware::BoardConfig make_config() {
  firmware::BoardConfig c;
  c.camera_width_px = 640;
  c.camera_height_px = 480;
  c.focal_px = 600.0F;        // F = 150 px at 160x120, as in the thesis
  c.principal_x_px = 319.5F;  // image centre in rig.h's pixel-centre convention
  c.principal_y_px = 239.5F;
  c.k1 = -0.02F;  // a cheap webcam's mild barrel distortion (k2 = p1 = p2 = k3 = 0)
  c.ptu_height_m = 0.6F;
  c.lever_m = 0.21F;               // L
  c.support_angle_rad = 0.0F;      // Ω
  c.tilt_step_rad = 0.134390352F;  // Φ = 7.7°
  c.robot_radius_m = 0.25F;
  c.robot_height_m = 0.8F;
  c.wheel_radius_m = 0.08F;
  c.track_width_m = 0.40F;
  c.max_speed_m_s = 0.3F;
  c.max_turn_rate_rad_s = 0.8F;
  c.minor_frame_us = 10000;  // 100 Hz executive; each frame steps the world 10 ms
  c.console_baud = 115200;
  c.telemetry_period_ms = 1000;
  c.realtime = false;            // a host process: no mlockall, no SCHED_FIFO
  c.watchdog_timeout_ms = 2000;  // the stand-in counts expirations in simulated time
  // Simulated time stands still while the host computes, so background work is bounded by
  // units, not by the clock: the work per frame (and so the mission) does not depend on
  // the host's speed.
  c.background_units_per_slice = 32;
  c.checkpoint_period_ms = 1000;
  return c;
}

// How far the simulated robot departs from the thesis's perfect one ([sim] realism).
enum class SimRealism : std::uint8_t {
  kIdeal,      // perfect odometry and optics: the thesis's reproductions
  kRealistic,  // an uncalibrated small base, a calibrated camera's residual errors
};

// The camera and rig as they truly are, against the nominal ones in the firmware's
// configuration (the firmware never sees these): what a careful calibration still leaves.
struct SimOptics {
  float lens_k1_error = 0.0F;       // true k1 − configured k1
  float lens_k2_error = 0.0F;       // true k2 − configured k2
  float lens_p1_error = 0.0F;       // true p1 − configured p1
  float lens_p2_error = 0.0F;       // true p2 − configured p2
  float focal_scale = 1.0F;         // true focal length / configured
  float principal_error_px = 0.0F;  // true principal point − configured: +x and −y [px, full res]
  float lever_error_m = 0.0F;       // true PTU-camera lever L − configured [m]
};
// The setting the board starts with (tests, benches and runs without a [sim] table).
inline constexpr SimRealism kDefaultRealism = SimRealism::kIdeal;

// Everything only the simulation needs.
struct SimSettings {
  float camera_fps = 30.0F;           // frame rate in simulated time
  hal::sim::RenderSettings render{};  // gain, noise 2 grey levels, vignetting 0.25
  hal::sim::SimParams physics{};      // PTU-D46 limits/speeds, base ramps, 1 ms steps
  SimOptics optics{};                 // the true camera and rig against the configured ones
};

// Every error of a realism setting. Realistic:
// - the base: an uncalibrated hobby base (Borenstein & Feng 1996): wheel diameters 0.5 %
//   apart, the effective track 1 % wider than the odometry assumes, each in-place turn 1 %
//   (sd) off, and 1 % (sd) white noise per wheel per 1 ms physics step (it averages out:
//   millimetres over a mission);
// - the camera as OpenCV's calibration leaves it (not an uncalibrated lens): focal length 1 %
//   long, principal point 2 px off on each axis, k1 0.01, k2 0.02, p1 and p2 0.0005 off;
// - the rig: the lever 2 mm long, 0.05° of backlash in each PTU axis (the PTU-D46's step);
// - the sensor: chroma noise of 1.5 levels and the exposure changing by 2 % (sd) from frame
//   to frame.
inline void apply_realism(SimRealism realism, SimSettings& s) {
  const bool real = realism == SimRealism::kRealistic;
  hal::sim::BaseParams& b = s.physics.base;
  b.wheel_scale_left = real ? 1.0025F : 1.0F;
  b.wheel_scale_right = real ? 0.9975F : 1.0F;
  b.track_scale = real ? 1.01F : 1.0F;
  b.turn_scrub = real ? 0.01F : 0.0F;
  b.odometry_noise = real ? 0.01F : 0.0F;
  SimOptics& o = s.optics;
  o.lens_k1_error = real ? 0.01F : 0.0F;
  o.lens_k2_error = real ? -0.02F : 0.0F;
  o.lens_p1_error = real ? 0.0005F : 0.0F;
  o.lens_p2_error = real ? -0.0005F : 0.0F;
  o.focal_scale = real ? 1.01F : 1.0F;
  o.principal_error_px = real ? 2.0F : 0.0F;
  o.lever_error_m = real ? 0.002F : 0.0F;
  s.physics.ptu.backlash_rad = real ? 8.7266e-4F : 0.0F;  // 0.05°
  s.render.chroma_noise_sigma = real ? 1.5F : 0.0F;
  s.render.exposure_jitter = real ? 0.02F : 0.0F;
}

inline SimSettings make_settings(const firmware::BoardConfig& c, std::uint64_t seed) {
  SimSettings s;
  s.render.seed = seed;
  s.physics.seed = seed;
  s.physics.base.robot_radius_m = c.robot_radius_m;
  s.physics.base.robot_height_m = c.robot_height_m;
  s.physics.base.track_width_m = c.track_width_m;
  s.physics.base.odometry_track_scale = c.odometry_track_scale;
  s.physics.base.odometry_left_scale = c.odometry_left_scale();
  s.physics.base.odometry_right_scale = c.odometry_right_scale();
  s.physics.base.max_speed_m_s = c.max_speed_m_s;
  s.physics.base.max_turn_rate_rad_s = c.max_turn_rate_rad_s;
  // The ODrives' watchdog, as configured on the robot: 0.2 s without a setpoint stops them.
  s.physics.base.command_timeout_us = 200000;
  apply_realism(kDefaultRealism, s);
  return s;
}

// The rig the firmware's configuration describes (its stereo code reads the same).
inline stereo::RigParams make_rig_params(const firmware::BoardConfig& c) {
  return firmware::mission::make_rig_params(c);
}

// The rig the simulator draws and moves: the configured one with the optics' errors.
inline stereo::RigParams true_rig_params(const firmware::BoardConfig& c, const SimOptics& o) {
  stereo::RigParams r = make_rig_params(c);
  r.camera.k1 += o.lens_k1_error;
  r.camera.k2 += o.lens_k2_error;
  r.camera.p1 += o.lens_p1_error;
  r.camera.p2 += o.lens_p2_error;
  r.camera.focal_px *= o.focal_scale;
  r.camera.principal_x_px += o.principal_error_px;
  r.camera.principal_y_px -= o.principal_error_px;
  r.lever_m += o.lever_error_m;
  return r;
}

}  // namespace boticelli::boards::sim
