// Benchmark suite "render": frames per second of the sim camera (640x480 YUYV, one core).
#include <time.h>

#include <algorithm>
#include <cstdint>
#include <cstdio>
#include <memory>

#include "algo/stereo/rig.h"
#include "bench.h"
#include "hal/sim/renderer.h"
#include "hal/sim/sim_world.h"
#include "hal/sim/textures.h"
#include "hal/sim/world.h"

namespace {

using namespace boticelli::hal::sim;

// CPU time of this thread [ns]: on a busy shared host the wall time also counts the time the
// thread waited for a core; this does not.
std::int64_t thread_cpu_ns() {
  timespec ts{};
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
  return static_cast<std::int64_t>(ts.tv_sec) * 1000000000 + ts.tv_nsec;
}

// The look-around of one mission cycle: 15 pan positions, each at two tilts (Φ apart), from
// a few places in the room; every frame with noise, vignetting and distortion as on the board.
int bench_world(const char* name, int rounds) {
  static World world;
  static TextureBank bank;
  static SimWorld sim;
  char path[512];
  std::snprintf(path, sizeof path, "%s/%s.sdf", BOTICELLI_WORLDS_DIR, name);
  char error[256];
  if (!load_world(path, world, error, sizeof error) || !bank.build(world, error, sizeof error)) {
    std::fprintf(stderr, "render: %s\n", error);
    return 1;
  }
  boticelli::stereo::RigParams params;  // the thesis's rig: 640x480, F = 600 px, L = 21 cm
  params.camera.k1 = -0.02F;
  const boticelli::stereo::RigModel rig(params);
  if (!sim.init(world, rig, SimParams{}, error, sizeof error)) {
    std::fprintf(stderr, "render: %s\n", error);
    return 1;
  }
  Renderer renderer;
  if (!renderer.init(world, bank, rig.camera(), RenderSettings{}, error, sizeof error)) {
    std::fprintf(stderr, "render: %s\n", error);
    return 1;
  }
  const std::size_t bytes = std::size_t{2} * rig.camera().width_px * rig.camera().height_px;
  std::unique_ptr<std::uint8_t[]> image(new std::uint8_t[bytes]);
  // Places: the start, and the start moved 1 m along each axis when that is free.
  boticelli::core::Pose2 places[5];
  int place_count = 0;
  const boticelli::core::Pose2 s = world.start;
  const float offsets[5][2] = {{0, 0}, {1, 0}, {-1, 0}, {0, 1}, {0, -1}};
  for (const auto& o : offsets) {
    const boticelli::core::Pose2 p{s.x_m + o[0], s.y_m + o[1], s.yaw_rad};
    if (sim.clearance_m(p.x_m, p.y_m) > 0.0F) places[place_count++] = p;
  }
  double worst_ms = 0.0;
  std::int64_t total_ns = 0;
  std::int64_t cpu_ns = 0;
  int frames = 0;
  for (int r = 0; r < rounds; ++r) {
    for (int p = 0; p < place_count; ++p) {
      for (int k = 0; k < 15; ++k) {
        const float pan = -2.6F + 5.2F * static_cast<float>(k) / 14.0F;
        for (const float tilt : {0.0F, -rig.params().tilt_step_rad}) {
          const RigidTransform pose = sim.camera_pose(places[p], pan, tilt);
          const std::int64_t c0 = thread_cpu_ns();
          const std::int64_t t0 = boticelli::bench::now_ns();
          renderer.render(pose, static_cast<std::uint32_t>(frames), image.get(),
                          std::size_t{2} * rig.camera().width_px, nullptr);
          const std::int64_t dt = boticelli::bench::now_ns() - t0;
          cpu_ns += thread_cpu_ns() - c0;
          boticelli::bench::do_not_optimize(image[bytes / 2]);
          total_ns += dt;
          worst_ms = std::max(worst_ms, static_cast<double>(dt) * 1e-6);
          ++frames;
        }
      }
    }
  }
  const double mean_ms = static_cast<double>(total_ns) * 1e-6 / frames;
  const double cpu_ms = static_cast<double>(cpu_ns) * 1e-6 / frames;
  // "fps" is on one core (the thread's CPU time); "fps_wall" also counts waiting for a core.
  boticelli::bench::JsonLine("render", name)
      .integer("width_px", rig.camera().width_px)
      .integer("height_px", rig.camera().height_px)
      .integer("surfaces", static_cast<std::int64_t>(world.surface_count))
      .integer("frames", frames)
      .num("fps", 1000.0 / cpu_ms)
      .num("ms_per_frame", cpu_ms)
      .num("fps_wall", 1000.0 / mean_ms)
      .num("ms_per_frame_wall_worst", worst_ms)
      .flag("faster_than_30fps", 1000.0 / cpu_ms >= 30.0)
      .emit();
  return 0;
}

}  // namespace

BOTICELLI_BENCH_SUITE(render, "sim camera: 640x480 YUYV frames per second on one core") {
  int failures = bench_world("thesis_room", 2);
  failures += bench_world("cluttered_room", 1);
  failures += bench_world("cylindrical_room", 1);
  return failures == 0 ? 0 : 1;
}
