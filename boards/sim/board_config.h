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
  kIdeal,      // perfect odometry: the thesis's reproductions
  kRealistic,  // the errors of an uncalibrated small base
};
// The setting the board starts with (tests, benches and runs without a [sim] table).
inline constexpr SimRealism kDefaultRealism = SimRealism::kIdeal;

// The base's odometry errors under a realism setting. Realistic: an uncalibrated hobby base
// (Borenstein & Feng 1996): wheel diameters 0.5 % apart, the effective track 1 % wider than
// the odometry assumes, each in-place turn 1 % (sd) off, and 1 % (sd) white noise per wheel
// per 1 ms physics step (it averages out: millimetres over a mission).
inline void apply_realism(SimRealism realism, hal::sim::BaseParams& b) {
  const bool real = realism == SimRealism::kRealistic;
  b.wheel_scale_left = real ? 1.0025F : 1.0F;
  b.wheel_scale_right = real ? 0.9975F : 1.0F;
  b.track_scale = real ? 1.01F : 1.0F;
  b.turn_scrub = real ? 0.01F : 0.0F;
  b.odometry_noise = real ? 0.01F : 0.0F;
}

// Everything only the simulation needs.
struct SimSettings {
  float camera_fps = 30.0F;           // frame rate in simulated time
  hal::sim::RenderSettings render{};  // gain, noise 2 grey levels, vignetting 0.25
  hal::sim::SimParams physics{};      // PTU-D46 limits/speeds, base ramps, 1 ms steps
};

inline SimSettings make_settings(const firmware::BoardConfig& c, std::uint64_t seed) {
  SimSettings s;
  s.render.seed = seed;
  s.physics.seed = seed;
  s.physics.base.robot_radius_m = c.robot_radius_m;
  s.physics.base.robot_height_m = c.robot_height_m;
  s.physics.base.track_width_m = c.track_width_m;
  s.physics.base.max_speed_m_s = c.max_speed_m_s;
  s.physics.base.max_turn_rate_rad_s = c.max_turn_rate_rad_s;
  // The ODrives' watchdog, as configured on the robot: 0.2 s without a setpoint stops them.
  s.physics.base.command_timeout_us = 200000;
  apply_realism(kDefaultRealism, s.physics.base);
  return s;
}

// The rig the renderer uses: built from the same config the firmware's stereo code reads.
inline stereo::RigParams make_rig_params(const firmware::BoardConfig& c) {
  return firmware::mission::make_rig_params(c);
}

}  // namespace boticelli::boards::sim
