// Shared scene set-ups for the stereo tests and benchmark: walls at known distances, target scenes.
#pragma once

#include <cstdint>
#include <vector>

#include "algo/stereo/rig.h"
#include "scene_renderer.h"

namespace boticelli::test {

// One frame pair of a wall at a known distance from the first camera.
struct WallPair {
  float distance_m = 1.0F;
  float pan_rad = 0.0F;
  float first_tilt_rad = 0.0F;
  SceneRenderer scene;
  std::vector<std::uint8_t> first_yuyv;
  std::vector<std::uint8_t> second_yuyv;
};

// Wall distances from 0.3 m to 4.5 m, alternating value-noise texture and camouflage,
// at varied pan and tilt, rendered with luma noise (sample_step: see render_yuyv).
std::vector<float> wall_distances_m();
void render_wall_pair(const stereo::RigModel& rig, std::size_t index, float distance_m,
                      WallPair& out, std::uint32_t sample_step = 1);

}  // namespace boticelli::test
