// Scene set-ups shared by the stereo tests and the benchmark.
#include "stereo_scenes.h"

namespace boticelli::test {

std::vector<float> wall_distances_m() {
  return {0.3F, 0.45F, 0.65F, 0.85F, 1.1F, 1.5F, 1.9F, 2.2F, 2.6F, 3.1F, 3.8F, 4.5F};
}

void render_wall_pair(const stereo::RigModel& rig, std::size_t index, float distance_m,
                      WallPair& out, std::uint32_t sample_step) {
  out.distance_m = distance_m;
  out.pan_rad = -1.5F + 0.37F * static_cast<float>(index % 9);
  out.first_tilt_rad = 0.08F * static_cast<float>(static_cast<int>(index % 3) - 1);
  const stereo::CameraPose first = rig.camera_pose(out.pan_rad, out.first_tilt_rad);
  const stereo::CameraPose second = rig.second_pose(out.pan_rad, out.first_tilt_rad);
  out.scene.clear();
  const auto seed = static_cast<std::uint32_t>(17 + index * 31);
  const Surface surface = index % 2 == 0 ? Surface::kTexture : Surface::kCamouflage;
  Patch wall = facing_wall(first.centre_m, first.rotation.col(2), distance_m, 4.0F, surface, seed);
  wall.scale_m = surface == Surface::kTexture ? 0.1F : 0.08F;
  out.scene.add(wall);
  const std::size_t bytes = std::size_t{rig.camera().width_px} * rig.camera().height_px * 2;
  out.first_yuyv.assign(bytes, 0);
  out.second_yuyv.assign(bytes, 0);
  out.scene.render_yuyv(rig, first, out.first_yuyv.data(), seed * 2 + 1, 1.5F, sample_step);
  out.scene.render_yuyv(rig, second, out.second_yuyv.data(), seed * 2 + 2, 1.5F, sample_step);
}

}  // namespace boticelli::test
