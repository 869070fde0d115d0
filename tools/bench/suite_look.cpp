// Benchmark suite "look": one 360° look of the mission on the sim renderer vs the world.
#include <time.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <limits>
#include <memory>
#include <numbers>
#include <optional>
#include <random>
#include <string>
#include <vector>

#include "algo/core/geometry.h"
#include "algo/evidence/reading.h"
#include "algo/evidence/reading_limits.h"
#include "algo/image/low_res_frame.h"
#include "algo/mapping/local_model_builder.h"
#include "algo/stereo/rig.h"
#include "algo/stereo/stereo_processor.h"
#include "bench.h"
#include "bench_worlds.h"
#include "board_config.h"
#include "firmware/app/config_file.h"
#include "sim_config.h"
#include "firmware/mission/look/look_processor.h"
#include "firmware/mission/look/look_scan.h"
#include "firmware/mission/params/mission_params.h"
#include "firmware/mission/target/target_tracker.h"
#include "firmware/telemetry/snapshot.h"
#include "hal/sim/renderer.h"
#include "hal/sim/sim_world.h"
#include "hal/sim/textures.h"
#include "hal/sim/world.h"
#include "hal/sim/world_geometry.h"

namespace boticelli::bench {
namespace {

constexpr const char* kSuite = "look";
constexpr double kGridStepM = 0.02;       // area integration step [m]
constexpr double kReachStepM = 0.05;      // reachability flood-fill cell [m]
constexpr double kTargetViewM = 3.5;      // target counted "in view" up to this range [m]
constexpr float kTargetMarginPx = 16.0F;  // ... and this far inside the full-resolution image
constexpr std::size_t kVisibilityRays = 720;

// Large objects live outside the stack.
hal::sim::World g_world;
hal::sim::TextureBank g_bank;
hal::sim::SimWorld g_sim;
hal::sim::Renderer g_renderer;
image::LowResFrame g_first;
image::LowResFrame g_second;
mapping::LocalModelBuilder g_builder;

firmware::SnapshotWriter g_snapshots;
const char* g_snapshot_dir = nullptr;
bool g_snapshot_all = false;  // BOTICELLI_LOOK_SNAPSHOTS_ALL=1: every look, not only unsafe ones
std::uint32_t g_look_number = 0;

// BOTICELLI_LOOK_SNAPSHOTS=DIR: a picture of every look whose free polygon is not wholly free
// or whose navigable polygon's disc touches an obstacle (readings, polygons, the true walls),
// named by the look's number in the run.
void snapshot_look(std::uint32_t number, const core::Pose2& pose,
                   const firmware::mission::LookReadings& look, const mapping::LocalMap& map,
                   float radius_m) {
  static std::vector<firmware::SnapshotReading> readings;
  static std::vector<core::Point2> free_poly, nav_poly;
  static std::vector<std::span<const core::Point2>> outlines;
  static std::vector<firmware::SnapshotCircle> circles;
  readings.clear();
  auto add = [&](const evidence::Reading& r) {
    const core::Point2 w = core::to_world(pose, evidence::floor_point_m(r));
    readings.push_back({w.x_m, w.y_m, r.m});
  };
  for (const evidence::Reading& r : look.features) add(r);
  for (const evidence::Reading& r : look.floor_obstacles) add(r);
  free_poly.clear();
  nav_poly.clear();
  for (std::size_t k = 0; k < map.free.vertex_count(); ++k)
    free_poly.push_back(core::to_world(pose, map.free.vertex(k)));
  for (std::size_t k = 0; k < map.navigable.vertex_count(); ++k)
    nav_poly.push_back(core::to_world(pose, map.navigable.vertex(k)));
  outlines.clear();
  circles.clear();
  for (std::size_t i = 0; i < g_world.collider_count; ++i) {
    const hal::sim::Collider& c = g_world.colliders[i];
    if (c.circle) {
      circles.push_back({{c.centre_x_m, c.centre_y_m}, c.radius_m});
    } else {
      outlines.push_back({c.hull, c.hull_size});
    }
  }
  firmware::SnapshotFrame f;
  f.cycle = number;
  f.state = "look";
  f.robot = pose;
  f.robot_radius_m = radius_m;
  f.view = {pose.x_m - 3.5F, pose.y_m - 3.5F, pose.x_m + 3.5F, pose.y_m + 3.5F};
  f.readings = {readings.data(), readings.size()};
  f.free_polygon = {free_poly.data(), free_poly.size()};
  f.navigable_polygon = {nav_poly.data(), nav_poly.size()};
  f.truth_polygons = {outlines.data(), outlines.size()};
  f.truth_circles = {circles.data(), circles.size()};
  char error[200] = "";
  if (!g_snapshots.write(f, error, sizeof error)) std::fprintf(stderr, "look: %s\n", error);
}

std::int64_t cpu_ns() {
  timespec ts{};
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
  return static_cast<std::int64_t>(ts.tv_sec) * 1000000000LL + ts.tv_nsec;
}

float quantise(float rad, float resolution_rad) {
  return resolution_rad > 0.0F ? std::round(rad / resolution_rad) * resolution_rad : rad;
}

// The views of one look, as the mission's scan (firmware::mission::scan_view).
std::vector<firmware::mission::LookView> look_views(const firmware::mission::MissionParams& params,
                                                    const hal::PanTiltLimits& lim) {
  std::vector<firmware::mission::LookView> views;
  for (std::size_t v = 0; v < params.pan_positions * params.row_count; ++v) {
    views.push_back(firmware::mission::scan_view(params, lim, v));
  }
  return views;
}

// Cells reachable by the robot's disc from the world's start (4-neighbour flood fill).
struct Reach {
  double x0 = 0.0, y0 = 0.0;
  std::size_t nx = 0, ny = 0;
  std::vector<std::uint8_t> reached;
  bool at(double x, double y) const {
    const double fx = (x - x0) / kReachStepM;
    const double fy = (y - y0) / kReachStepM;
    if (fx < 0.0 || fy < 0.0) return false;
    const auto ix = static_cast<std::size_t>(fx);
    const auto iy = static_cast<std::size_t>(fy);
    return ix < nx && iy < ny && reached[iy * nx + ix] != 0;
  }
};

Reach reachable(const hal::sim::World& w, float radius_m, float height_m) {
  Reach r;
  double x0 = 1e9, y0 = 1e9, x1 = -1e9, y1 = -1e9;
  auto grow = [&](double x, double y) {
    x0 = std::min(x0, x);
    x1 = std::max(x1, x);
    y0 = std::min(y0, y);
    y1 = std::max(y1, y);
  };
  for (std::size_t i = 0; i < w.collider_count; ++i) {
    const hal::sim::Collider& c = w.colliders[i];
    if (c.circle) {
      grow(c.centre_x_m - c.radius_m, c.centre_y_m - c.radius_m);
      grow(c.centre_x_m + c.radius_m, c.centre_y_m + c.radius_m);
    } else {
      for (std::size_t k = 0; k < c.hull_size; ++k) grow(c.hull[k].x_m, c.hull[k].y_m);
    }
  }
  grow(w.start.x_m, w.start.y_m);
  r.x0 = x0;
  r.y0 = y0;
  r.nx = static_cast<std::size_t>((x1 - x0) / kReachStepM) + 1;
  r.ny = static_cast<std::size_t>((y1 - y0) / kReachStepM) + 1;
  r.reached.assign(r.nx * r.ny, 0);
  std::vector<std::uint8_t> seen(r.nx * r.ny, 0);
  const auto sx = static_cast<std::size_t>((static_cast<double>(w.start.x_m) - x0) / kReachStepM);
  const auto sy = static_cast<std::size_t>((static_cast<double>(w.start.y_m) - y0) / kReachStepM);
  std::vector<std::size_t> queue{sy * r.nx + sx};
  seen[queue[0]] = 1;
  while (!queue.empty()) {
    const std::size_t c = queue.back();
    queue.pop_back();
    const std::size_t ix = c % r.nx;
    const std::size_t iy = c / r.nx;
    const double x = x0 + (static_cast<double>(ix) + 0.5) * kReachStepM;
    const double y = y0 + (static_cast<double>(iy) + 0.5) * kReachStepM;
    if (hal::sim::disc_clearance_m(w, static_cast<float>(x), static_cast<float>(y), radius_m,
                                   height_m) < 0.0F) {
      continue;
    }
    r.reached[c] = 1;
    const std::size_t next[4] = {ix > 0 ? c - 1 : c, ix + 1 < r.nx ? c + 1 : c,
                                 iy > 0 ? c - r.nx : c, iy + 1 < r.ny ? c + r.nx : c};
    for (const std::size_t n : next) {
      if (seen[n] == 0) {
        seen[n] = 1;
        queue.push_back(n);
      }
    }
  }
  return r;
}

// A floor point is truly free when no collider in the robot's height band covers it.
bool truly_free(double x, double y, float height_m) {
  return hal::sim::disc_clearance_m(g_world, static_cast<float>(x), static_cast<float>(y), 0.0F,
                                    height_m) > 0.0F;
}

// How far the floor is visible from (x, y) in direction a within `bound` (first collider
// footprint in the height band), by sphere tracing on the footprint clearance [m].
double visible_range(double x, double y, double a, double bound, float height_m) {
  double t = 0.0;
  const double c = std::cos(a), s = std::sin(a);
  while (t < bound) {
    const float d = hal::sim::disc_clearance_m(g_world, static_cast<float>(x + t * c),
                                               static_cast<float>(y + t * s), 0.0F, height_m);
    if (d < 0.002F) return t;
    t += std::max(static_cast<double>(d), 0.005);
  }
  return bound;
}

struct Quality {
  double safety = 1.0;      // free polygon area that is truly free / its area
  double coverage = 0.0;    // truly free floor in sight within the circle that the polygon holds
  double nav_safety = 1.0;  // navigable area whose robot disc is truly free / its area
  double free_area_m2 = 0.0;
  double nav_area_m2 = 0.0;
};

Quality quality(const core::Pose2& pose, const mapping::LocalMap& map, double bound,
                float robot_radius_m, float height_m) {
  std::vector<double> sight(kVisibilityRays);
  for (std::size_t k = 0; k < kVisibilityRays; ++k) {
    const double a = 2.0 * std::numbers::pi * static_cast<double>(k) / kVisibilityRays;
    sight[k] = visible_range(pose.x_m, pose.y_m, a, bound, height_m);
  }
  std::size_t in_poly = 0, in_poly_free = 0, visible_free = 0, visible_free_in_poly = 0;
  std::size_t in_nav = 0, in_nav_safe = 0;
  for (double dy = -bound; dy <= bound; dy += kGridStepM) {
    for (double dx = -bound; dx <= bound; dx += kGridStepM) {
      const double rho = std::hypot(dx, dy);
      if (rho > bound) continue;
      const double x = static_cast<double>(pose.x_m) + dx;
      const double y = static_cast<double>(pose.y_m) + dy;
      const bool is_free = truly_free(x, y, height_m);
      const core::Point2 q = core::to_robot(pose, {static_cast<float>(x), static_cast<float>(y)});
      const bool inside = map.free.contains(q);
      double a = std::atan2(dy, dx);
      if (a < 0.0) a += 2.0 * std::numbers::pi;
      const auto k =
          static_cast<std::size_t>(std::lround(a / (2.0 * std::numbers::pi) * kVisibilityRays)) %
          kVisibilityRays;
      const bool visible = rho <= sight[k];
      in_poly += inside ? 1U : 0U;
      in_poly_free += (inside && is_free) ? 1U : 0U;
      visible_free += (visible && is_free) ? 1U : 0U;
      visible_free_in_poly += (visible && is_free && inside) ? 1U : 0U;
      if (map.navigable.contains(q)) {
        ++in_nav;
        in_nav_safe +=
            hal::sim::disc_clearance_m(g_world, static_cast<float>(x), static_cast<float>(y),
                                       robot_radius_m, height_m) >= 0.0F
                ? 1U
                : 0U;
      }
    }
  }
  Quality q;
  const double cell = kGridStepM * kGridStepM;
  q.safety = in_poly > 0 ? static_cast<double>(in_poly_free) / static_cast<double>(in_poly) : 1.0;
  q.coverage = visible_free > 0
                   ? static_cast<double>(visible_free_in_poly) / static_cast<double>(visible_free)
                   : 0.0;
  q.nav_safety = in_nav > 0 ? static_cast<double>(in_nav_safe) / static_cast<double>(in_nav) : 1.0;
  q.free_area_m2 = static_cast<double>(in_poly) * cell;
  q.nav_area_m2 = static_cast<double>(in_nav) * cell;
  return q;
}

double percentile(std::vector<double> v, double p) {
  if (v.empty()) return std::numeric_limits<double>::quiet_NaN();
  std::sort(v.begin(), v.end());
  const auto i = static_cast<std::size_t>(
      std::clamp(p * static_cast<double>(v.size() - 1), 0.0, static_cast<double>(v.size() - 1)));
  return v[i];
}

double mean(const std::vector<double>& v) {
  if (v.empty()) return std::numeric_limits<double>::quiet_NaN();
  double s = 0.0;
  for (const double x : v) s += x;
  return s / static_cast<double>(v.size());
}

// Is the target's corner in both frames of a pair, on a face turned to the camera and not
// hidden? (Pinhole projection; the margin absorbs the mild distortion.)
bool target_in_image(const hal::sim::RigidTransform& first, const hal::sim::RigidTransform& second,
                     const stereo::CameraIntrinsics& cam, float margin_px) {
  const Eigen::Vector3f target = g_world.target_point_m;
  const Eigen::Vector3f to_target = target - first.translation_m;
  const float dist = to_target.norm();
  if (g_world.target_normal.dot(-to_target) <= 0.0F) return false;
  for (const hal::sim::RigidTransform* t : {&first, &second}) {
    const Eigen::Vector3f p = t->rotation.transpose() * (target - t->translation_m);
    if (p.z() <= 0.05F) return false;
    const float u = cam.focal_px * p.x() / p.z() + cam.principal_x_px;
    const float v = cam.focal_px * p.y() / p.z() + cam.principal_y_px;
    if (u < margin_px || v < margin_px || u > static_cast<float>(cam.width_px) - margin_px ||
        v > static_cast<float>(cam.height_px) - margin_px) {
      return false;
    }
  }
  std::size_t surface = 0;
  float t = 0.0F;
  if (hal::sim::cast_ray(g_world, first.translation_m, to_target, surface, t) &&
      t < 1.0F - 0.02F / dist) {
    return false;  // something in front of it
  }
  return true;
}

// How many of the errors [m] are at most 0.1 m (the bar for a target fix).
std::int64_t within_0_1m(const std::vector<double>& errors_m) {
  return static_cast<std::int64_t>(
      std::count_if(errors_m.begin(), errors_m.end(), [](double e) { return e <= 0.1; }));
}

struct WorldStats {
  std::vector<double> readings, floor_obstacles, floor_free, weak_share;
  std::vector<double> range_error_m, range_error_rel;  // |r − r_true| [m] and / δr (Eq 3.7)
  std::vector<double> safety, coverage, nav_safety, free_area, nav_area, pieces, guard_points,
      guard_corroborated;
  std::size_t guard_truncated = 0;
  std::vector<double> render_ms, stereo_ms, target_ms, floor_ms, think_ms;
  std::size_t target_views = 0, target_found = 0, target_far = 0, target_false = 0;
  std::vector<double> target_error_m, target_far_error_m;
  // The calibration self-check: each look's median ratio of stereo to floor-cue distances at
  // obstacle bases (looks with at least 10 ratios), and the ratios' count per look.
  std::vector<double> range_check_ratio, range_check_count;
  std::vector<double> target_across_error_m;  // fixes across pans, target in view
  // Per look, as the mission acts on it: the look's fixes in the mission's TargetTracker.
  std::size_t pose_target_views = 0, pose_target_found = 0, pose_target_confirmed = 0;
  std::vector<double> pose_target_error_m;
};

// BOTICELLI_LOOK_SIM_CONFIG=FILE: a configuration file whose [sim] keys go on top of the
// realism setting (one error at a time, e.g. `[sim]` `focal_scale = 1.01`).
boards::sim::SimConfigKeys g_sim_keys;
bool g_sim_keys_set = false;
char error_of_config[256] = "";

int run_world(const std::string& dir, const std::string& name, std::size_t poses,
              double min_clearance_m, boards::sim::SimRealism realism) {
  const firmware::BoardConfig config = boards::sim::make_config();
  const firmware::mission::MissionParams params = firmware::mission::make_mission_params(config);
  boards::sim::SimSettings settings = boards::sim::make_settings(config, 1);
  boards::sim::apply_realism(realism, settings);
  if (g_sim_keys_set && !boards::sim::apply_sim_config(g_sim_keys, settings, error_of_config,
                                                       sizeof error_of_config)) {
    std::fprintf(stderr, "look: %s\n", error_of_config);
    return 1;
  }
  // The mission's look pipeline: stereo, target fixes and the floor cue of each view, with
  // the configured rig; the simulator draws with the true one.
  static firmware::mission::LookProcessor look(params.rig, params.stereo,
                                               params.model.close_blocked_rays);
  static std::optional<stereo::RigModel> true_rig;
  true_rig.emplace(boards::sim::true_rig_params(config, settings.optics));
  const stereo::RigModel& rig = *true_rig;
  // Gear play: the camera trails each commanded angle by half of it, on the side the axis
  // came from (the PTU's moves between views, as SimWorld::camera_pose() has it).
  const float play = 0.5F * settings.physics.ptu.backlash_rad;
  float last_pan = 0.0F;
  float last_tilt = 0.0F;
  float pan_direction = 0.0F;
  float tilt_direction = 0.0F;
  const auto trail = [&](float& last, float& direction, float to) {
    if (to != last) direction = to > last ? 1.0F : -1.0F;
    last = to;
    return to - play * direction;
  };

  const std::string path = dir + "/" + name + ".sdf";
  char error[256] = "";
  if (!hal::sim::load_world(path.c_str(), g_world, error, sizeof error) ||
      !g_bank.build(g_world, error, sizeof error) ||
      !g_sim.init(g_world, rig, settings.physics, error, sizeof error) ||
      !g_renderer.init(g_world, g_bank, rig.camera(), settings.render, error, sizeof error)) {
    std::fprintf(stderr, "look: %s: %s\n", name.c_str(), error);
    return 1;
  }
  const hal::PanTiltLimits lim = settings.physics.ptu.limits;
  const std::vector<firmware::mission::LookView> views = look_views(params, lim);
  const stereo::CameraIntrinsics& cam = rig.camera();
  const std::size_t stride = std::size_t{2} * cam.width_px;
  std::vector<std::uint8_t> first_yuyv(stride * cam.height_px);
  std::vector<std::uint8_t> second_yuyv(stride * cam.height_px);
  const float height = config.robot_height_m;
  const float radius = config.robot_radius_m;

  // Poses: uniform in the reachable area, centre at least min_clearance_m from every
  // obstacle footprint in the robot's height band, random heading (seeded per world).
  const Reach reach = reachable(g_world, radius, height);
  std::mt19937 rng(12345U + static_cast<std::uint32_t>(std::hash<std::string>{}(name)&0xFFFFU));
  std::uniform_real_distribution<double> ux(reach.x0,
                                            reach.x0 + static_cast<double>(reach.nx) * kReachStepM);
  std::uniform_real_distribution<double> uy(reach.y0,
                                            reach.y0 + static_cast<double>(reach.ny) * kReachStepM);
  std::uniform_real_distribution<double> uyaw(-std::numbers::pi, std::numbers::pi);
  std::vector<core::Pose2> pose_list;
  for (int tries = 0; pose_list.size() < poses && tries < 100000; ++tries) {
    const double x = ux(rng), y = uy(rng), yaw = uyaw(rng);
    if (!reach.at(x, y)) continue;
    if (hal::sim::disc_clearance_m(g_world, static_cast<float>(x), static_cast<float>(y), 0.0F,
                                   height) < static_cast<float>(min_clearance_m)) {
      continue;
    }
    pose_list.push_back({static_cast<float>(x), static_cast<float>(y), static_cast<float>(yaw)});
  }

  WorldStats st;
  std::uint32_t frame_index = 0;
  for (const core::Pose2& pose : pose_list) {
    look.reset();  // the mission's first look: nothing known about the floor yet
    firmware::mission::TargetTracker tracker;
    // One look from one place: "confirmed" here is its views agreeing (the mission also asks
    // for a second place, TargetTrackerParams::min_baseline_m).
    firmware::mission::TargetTrackerParams one_place = params.target;
    one_place.min_baseline_m = 0.0F;
    tracker.configure(one_place);
    bool pose_in_view = false;
    double render_ns = 0, stereo_ns = 0, target_ns = 0, floor_ns = 0;
    hal::sim::RigidTransform last_sighting_pose;  // the first frame of the look's last sighting
    for (std::size_t v = 0; v < views.size(); ++v) {
      const firmware::mission::LookView& view = views[v];
      stereo::PairPose pp;
      pp.pan_rad = quantise(view.pan_rad, lim.pan_resolution_rad);
      pp.first_tilt_rad = quantise(view.tilt_rad, lim.tilt_resolution_rad);
      pp.second_tilt_rad =
          quantise(view.tilt_rad - params.rig.tilt_step_rad, lim.tilt_resolution_rad);
      const float pan_true = trail(last_pan, pan_direction, pp.pan_rad);
      if (view.pair) {
        // The scan approaches a pair's first tilt from above (LookScan, kApproach).
        (void)trail(last_tilt, tilt_direction,
                    firmware::mission::tilt_approach_rad(
                        last_tilt, pp.first_tilt_rad, params.ptu_approach_rad, lim.tilt_max_rad));
      }
      const hal::sim::RigidTransform first_pose =
          g_sim.camera_pose(pose, pan_true, trail(last_tilt, tilt_direction, pp.first_tilt_rad));
      const hal::sim::RigidTransform second_pose =
          view.pair ? g_sim.camera_pose(pose, pan_true,
                                        trail(last_tilt, tilt_direction, pp.second_tilt_rad))
                    : first_pose;
      std::int64_t t0 = cpu_ns();
      g_renderer.render(first_pose, frame_index++, first_yuyv.data(), stride, nullptr);
      if (view.pair) {
        g_renderer.render(second_pose, frame_index++, second_yuyv.data(), stride, nullptr);
      }
      (void)image::downsample_yuyv(first_yuyv.data(), cam.width_px, cam.height_px,
                                   static_cast<std::uint32_t>(stride), params.rig.downsample_factor,
                                   g_first);
      if (view.pair) {
        (void)image::downsample_yuyv(second_yuyv.data(), cam.width_px, cam.height_px,
                                     static_cast<std::uint32_t>(stride),
                                     params.rig.downsample_factor, g_second);
      }
      render_ns += static_cast<double>(cpu_ns() - t0);

      // The view's parts in order, as the mission's background runs them, each timed.
      const firmware::mission::GrabbedView grabbed{g_first, g_second, pp, view.pair, v, false};
      firmware::mission::TargetFixes fixes;
      bool done = false;
      for (std::uint8_t part = 0; !done; ++part) {
        const auto p = static_cast<firmware::mission::ViewPart>(part);
        t0 = cpu_ns();
        done = look.process(p, grabbed, fixes);
        const auto ns = static_cast<double>(cpu_ns() - t0);
        switch (p) {
          case firmware::mission::ViewPart::kStereo:
            stereo_ns += ns;
            break;
          case firmware::mission::ViewPart::kTarget:
            target_ns += ns;
            break;
          case firmware::mission::ViewPart::kFloorFirst:
          case firmware::mission::ViewPart::kFloorSecond:
            floor_ns += ns;
            break;
        }
        if (!view.pair) continue;
        if (p == firmware::mission::ViewPart::kStereo) {
          // Range error of this pair's points against the ray caster along the same line of
          // sight from the first optical centre.
          for (const stereo::StereoPoint& sp : look.stereo().points()) {
            const core::Point2 w = core::to_world(pose, {sp.point_ptu_m.x(), sp.point_ptu_m.y()});
            const Eigen::Vector3f pt(w.x_m, w.y_m, sp.point_ptu_m.z() + params.rig.ptu_height_m);
            const Eigen::Vector3f d = pt - first_pose.translation_m;
            std::size_t surface = 0;
            float t = 0.0F;
            if (!hal::sim::cast_ray(g_world, first_pose.translation_m, d, surface, t)) continue;
            const double err =
                std::fabs(static_cast<double>(d.norm()) * (1.0 - static_cast<double>(t)));
            st.range_error_m.push_back(err);
            if (sp.range_error_m > 0.0F)
              st.range_error_rel.push_back(err / static_cast<double>(sp.range_error_m));
          }
        } else if (p == firmware::mission::ViewPart::kTarget) {
          const stereo::TargetFix& fix = fixes.pair;
          const stereo::TargetFix& across = fixes.across;
          const bool in_image = target_in_image(first_pose, second_pose, cam, kTargetMarginPx);
          const bool anywhere = target_in_image(first_pose, second_pose, cam, -kTargetMarginPx);
          const bool in_view =
              in_image &&
              static_cast<double>((g_world.target_point_m - first_pose.translation_m).norm()) <=
                  kTargetViewM;
          st.target_views += in_view ? 1U : 0U;
          pose_in_view = pose_in_view || in_view;
          // The look's fixes in the tracker as the mission adds them: the pair's, then the
          // one across pans, with the view's id (the first cycle's).
          const auto id = static_cast<std::uint32_t>(v);
          if (fix.found) {
            const Eigen::Vector3f pt =
                firmware::mission::fix_in_world(pose, fix, params.rig.ptu_height_m);
            tracker.add(pt, fix.confidence, id, fix.range_error_m);
            const double e = (pt - g_world.target_point_m).norm();
            if (in_view) {
              ++st.target_found;
              st.target_error_m.push_back(e);
            } else if (anywhere) {
              ++st.target_far;  // beyond kTargetViewM or at the image edge: counted apart
              st.target_far_error_m.push_back(e);
            } else {
              ++st.target_false;  // not in both frames (16 px slack) or hidden: false
            }
          }
          if (across.found) {
            const Eigen::Vector3f pt =
                firmware::mission::fix_in_world(pose, across, params.rig.ptu_height_m);
            tracker.add(pt, across.confidence, id, across.range_error_m);
            const double e = (pt - g_world.target_point_m).norm();
            // In view, or false, as for a pair: the two first frames.
            if (target_in_image(last_sighting_pose, first_pose, cam, kTargetMarginPx) &&
                static_cast<double>((g_world.target_point_m - first_pose.translation_m).norm()) <=
                    kTargetViewM) {
              st.target_across_error_m.push_back(e);
            } else if (!target_in_image(last_sighting_pose, first_pose, cam, -kTargetMarginPx)) {
              ++st.target_false;
            }
          }
          // The processor pairs the next sighting across pans with this one.
          if (fix.first.found) last_sighting_pose = first_pose;
        }
      }
    }
    if (pose_in_view) {
      ++st.pose_target_views;
      if (tracker.sightings() > 0) {
        ++st.pose_target_found;
        st.pose_target_confirmed += tracker.confirmed() ? 1U : 0U;
        const Eigen::Vector3f& est =
            tracker.confirmed() ? tracker.estimate_m() : tracker.candidate_m();
        st.pose_target_error_m.push_back((est - g_world.target_point_m).norm());
      }
    }
    const firmware::mission::LookReadings& readings = look.readings();
    std::size_t weak = 0;
    for (const evidence::Reading& r : readings.features) weak += r.m < 0.6F ? 1U : 0U;
    st.readings.push_back(static_cast<double>(readings.features.size()));
    st.weak_share.push_back(readings.features.empty()
                                ? 0.0
                                : static_cast<double>(weak) /
                                      static_cast<double>(readings.features.size()));
    st.floor_obstacles.push_back(static_cast<double>(readings.floor_obstacles.size()));
    st.floor_free.push_back(static_cast<double>(readings.floor_free.size()));

    // Think: the look ends (features filtered by the reading limits), then the local model
    // from its readings (the first look: no prior look's free polygon).
    const std::int64_t t0 = cpu_ns();
    look.end_look(params.limits);
    {
      float ratio = 0.0F;
      std::size_t n = 0;
      if (look.range_check().median(ratio, n) && n >= 10) {
        st.range_check_ratio.push_back(static_cast<double>(ratio));
      }
      st.range_check_count.push_back(static_cast<double>(n));
    }
    g_builder.start(params.model, readings.features.span(), readings.floor_obstacles.span(),
                    readings.floor_free.span(), readings.floor_free_near.span(),
                    readings.floor_blocked.span());
    g_builder.run();
    st.think_ms.push_back(static_cast<double>(cpu_ns() - t0) * 1e-6);
    st.pieces.push_back(static_cast<double>(g_builder.stats().pieces));
    st.guard_points.push_back(static_cast<double>(g_builder.stats().guard_points));
    st.guard_corroborated.push_back(static_cast<double>(g_builder.stats().guard_corroborated));
    st.guard_truncated +=
        g_builder.stats().guard_dropped > 0 || g_builder.stats().guard_points_full ? 1U : 0U;
    st.render_ms.push_back(render_ns * 1e-6);
    st.stereo_ms.push_back(stereo_ns * 1e-6);
    st.target_ms.push_back(target_ns * 1e-6);
    st.floor_ms.push_back(floor_ns * 1e-6);

    const Quality q =
        quality(pose, g_builder.map(),
                static_cast<double>(params.model.extraction.bounding_radius_m), radius, height);
    if (g_snapshot_dir != nullptr && (g_snapshot_all || q.nav_safety < 1.0 || q.safety < 0.99)) {
      std::fprintf(stderr, "look: %s look %u at (%.2f, %.2f, %.2f): safety %.4f nav safety %.4f\n",
                   name.c_str(), g_look_number, static_cast<double>(pose.x_m),
                   static_cast<double>(pose.y_m), static_cast<double>(pose.yaw_rad), q.safety,
                   q.nav_safety);
      snapshot_look(g_look_number, pose, readings, g_builder.map(), radius);
    }
    ++g_look_number;
    st.safety.push_back(q.safety);
    st.coverage.push_back(q.coverage);
    st.nav_safety.push_back(q.nav_safety);
    st.free_area.push_back(q.free_area_m2);
    st.nav_area.push_back(q.nav_area_m2);
  }

  std::size_t unsafe_nav = 0;
  for (const double s : st.nav_safety) unsafe_nav += s < 1.0 ? 1U : 0U;
  const double min_safety = st.safety.empty()
                                ? std::numeric_limits<double>::quiet_NaN()
                                : *std::min_element(st.safety.begin(), st.safety.end());
  const double min_nav = st.nav_safety.empty()
                             ? std::numeric_limits<double>::quiet_NaN()
                             : *std::min_element(st.nav_safety.begin(), st.nav_safety.end());
  JsonLine(kSuite, name.c_str())
      .text("realism", realism == boards::sim::SimRealism::kRealistic ? "realistic" : "ideal")
      .integer("poses", static_cast<std::int64_t>(pose_list.size()))
      .integer("views", static_cast<std::int64_t>(views.size()))
      .num("readings", mean(st.readings))
      .num("share_m_below_0_6", mean(st.weak_share))
      .num("floor_obstacle_readings", mean(st.floor_obstacles))
      .num("floor_free_readings", mean(st.floor_free))
      .integer("range_points", static_cast<std::int64_t>(st.range_error_m.size()))
      .num("range_err_median_m", percentile(st.range_error_m, 0.5))
      .num("range_err_p90_m", percentile(st.range_error_m, 0.9))
      .num("range_err_p99_m", percentile(st.range_error_m, 0.99))
      .num("range_err_median_dr", percentile(st.range_error_rel, 0.5))
      .num("range_err_p90_dr", percentile(st.range_error_rel, 0.9))
      .num("range_err_p99_dr", percentile(st.range_error_rel, 0.99))
      .num("pieces", mean(st.pieces))
      .num("guard_points", mean(st.guard_points))
      .num("guard_corroborated", mean(st.guard_corroborated))
      .integer("looks_guard_truncated", static_cast<std::int64_t>(st.guard_truncated))
      .num("safety", mean(st.safety))
      .num("safety_min", min_safety)
      .num("coverage", mean(st.coverage))
      .num("nav_safety", mean(st.nav_safety))
      .num("nav_safety_min", min_nav)
      .integer("looks_nav_unsafe", static_cast<std::int64_t>(unsafe_nav))
      .num("free_area_m2", mean(st.free_area))
      .num("nav_area_m2", mean(st.nav_area))
      .integer("target_views", static_cast<std::int64_t>(st.target_views))
      .integer("target_found", static_cast<std::int64_t>(st.target_found))
      .num("target_rate", st.target_views > 0 ? static_cast<double>(st.target_found) /
                                                    static_cast<double>(st.target_views)
                                              : std::numeric_limits<double>::quiet_NaN())
      .integer("target_found_within_0_1m", within_0_1m(st.target_error_m))
      .num("target_err_median_m", percentile(st.target_error_m, 0.5))
      .num("target_err_max_m", percentile(st.target_error_m, 1.0))
      .integer("target_across", static_cast<std::int64_t>(st.target_across_error_m.size()))
      .integer("target_across_within_0_1m", within_0_1m(st.target_across_error_m))
      .num("target_across_err_median_m", percentile(st.target_across_error_m, 0.5))
      .num("target_across_err_max_m", percentile(st.target_across_error_m, 1.0))
      .integer("target_far", static_cast<std::int64_t>(st.target_far))
      .num("target_far_err_median_m", percentile(st.target_far_error_m, 0.5))
      .integer("target_false", static_cast<std::int64_t>(st.target_false))
      .integer("looks_target_in_view", static_cast<std::int64_t>(st.pose_target_views))
      .integer("looks_target_found", static_cast<std::int64_t>(st.pose_target_found))
      .integer("looks_target_confirmed", static_cast<std::int64_t>(st.pose_target_confirmed))
      .integer("looks_target_within_0_1m", within_0_1m(st.pose_target_error_m))
      .num("looks_target_err_median_m", percentile(st.pose_target_error_m, 0.5))
      .num("looks_target_err_max_m", percentile(st.pose_target_error_m, 1.0))
      .num("render_ms", mean(st.render_ms))
      .num("stereo_ms", mean(st.stereo_ms))
      .num("target_ms", mean(st.target_ms))
      .num("floor_ms", mean(st.floor_ms))
      .num("think_ms", mean(st.think_ms))
      .num("range_check_ratio_median", percentile(st.range_check_ratio, 0.5))
      .num("range_check_ratio_p10", percentile(st.range_check_ratio, 0.1))
      .num("range_check_ratio_p90", percentile(st.range_check_ratio, 0.9))
      .integer("range_check_looks", static_cast<std::int64_t>(st.range_check_ratio.size()))
      .num("range_check_count_mean", mean(st.range_check_count))
      .emit();
  return 0;
}

int run() {
  const auto poses = static_cast<std::size_t>(env_long("BOTICELLI_LOOK_POSES", 20));
  // BOTICELLI_LOOK_REALISM=ideal|realistic: the simulator's setting ([sim] realism); the
  // board's default without it.
  boards::sim::SimRealism realism = boards::sim::kDefaultRealism;
  if (const char* r = std::getenv("BOTICELLI_LOOK_REALISM"); r != nullptr && r[0] != '\0') {
    if (std::strcmp(r, "realistic") == 0) {
      realism = boards::sim::SimRealism::kRealistic;
    } else if (std::strcmp(r, "ideal") == 0) {
      realism = boards::sim::SimRealism::kIdeal;
    } else {
      std::fprintf(stderr, "look: BOTICELLI_LOOK_REALISM=%s must be realistic or ideal\n", r);
      return 1;
    }
  }
  if (const char* f = std::getenv("BOTICELLI_LOOK_SIM_CONFIG"); f != nullptr && f[0] != '\0') {
    static firmware::ConfigSchema schema;
    schema.clear();
    if (!boards::sim::add_sim_config_keys(schema, g_sim_keys) ||
        firmware::load_config_file(f, schema, error_of_config, sizeof error_of_config) !=
            firmware::ConfigLoad::kLoaded) {
      std::fprintf(stderr, "look: %s\n", error_of_config);
      return 1;
    }
    // The file's realism, if it names one, decides the row's label.
    if (std::strcmp(g_sim_keys.realism.data(), "realistic") == 0) {
      realism = boards::sim::SimRealism::kRealistic;
    } else if (std::strcmp(g_sim_keys.realism.data(), "ideal") == 0) {
      realism = boards::sim::SimRealism::kIdeal;
    }
    g_sim_keys_set = true;
  }
  const double clearance = env_double("BOTICELLI_LOOK_CLEARANCE_M", 0.35);
  int status = 0;
  const std::string dir = worlds_dir("BOTICELLI_LOOK_WORLDS_DIR", BOTICELLI_WORLDS_DIR);
  g_snapshot_dir = std::getenv("BOTICELLI_LOOK_SNAPSHOTS");
  g_snapshot_all = env_long("BOTICELLI_LOOK_SNAPSHOTS_ALL", 0) != 0;
  if (g_snapshot_dir != nullptr) {
    char error[200] = "";
    if (!g_snapshots.open(g_snapshot_dir, error, sizeof error)) {
      std::fprintf(stderr, "look: %s\n", error);
      return 1;
    }
  }
  for (const std::string& name : world_names(dir, "BOTICELLI_LOOK_WORLDS", kSuite)) {
    if (run_world(dir, name, poses, clearance, realism) != 0) status = 1;
  }
  return status;
}

[[maybe_unused]] const bool g_registered = register_suite(
    {kSuite, "one 360-degree look on the sim renderer vs the world's geometry", &run});

}  // namespace
}  // namespace boticelli::bench
