// Synthetic range data for the environments of thesis §4.8.2, with analytic ground truth.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <random>
#include <span>
#include <vector>

#include "algo/aln/samples.h"
#include "algo/evidence/occupancy_model.h"
#include "algo/evidence/ray_samples.h"
#include "algo/evidence/reading.h"

namespace boticelli::bench {

// A point or direction in the world frame [m]: floor is z = 0, z up.
struct Vec3 {
  double x = 0.0;
  double y = 0.0;
  double z = 0.0;
};

enum class RoomShape : std::uint8_t { kCylinder, kRectangle };

// An axis-aligned box standing on the floor (the thesis's "small box, half a meter high").
struct FloorBox {
  double x_min = 0.0;
  double x_max = 0.0;
  double y_min = 0.0;
  double y_max = 0.0;
  double height_m = 0.0;  // 0 = no box
};

// One environment of §4.8.2. Walls are vertical, wall_height_m high, and full of
// features with evidence feature_m; the floor is featureless; there is no ceiling.
struct RoomSpec {
  const char* name;         // short id, e.g. "cylinder_centre"
  const char* thesis_case;  // the thesis's wording / figure
  int thesis_pieces;        // linear pieces the thesis reports (ε = 0.15)
  RoomShape shape;
  double radius_m;                    // kCylinder: wall radius about (0, 0)
  double x_min, x_max, y_min, y_max;  // kRectangle: wall lines
  Vec3 sensor;                        // PTU centre
  FloorBox box;
  double outlier_fraction;  // share of features seen at half their distance (§4.8.2)
  double wall_height_m = 2.0;
  double feature_m = 0.9;
  double max_range_m = 4.5;  // visibility of the sensor (§3.4)
};

// How the camera looks at the room (docs/mission.md "A cycle", thesis §3.4): a pinhole camera on
// the PTU centre, one image per (pan, tilt) position. Defaults: the thesis's 160×120 image
// with F = 150 px (56° × 44° field of view, as the sim board's camera), about 15 pan
// positions, and two tilts — level (walls up to 22° above the horizon) and 0.5 rad down
// (the floor and low obstacles from 0.5 m to the walls' foot).
struct CameraScan {
  std::size_t pan_positions = 15;
  std::array<double, 4> tilt_rad = {0.0, -0.5, 0.0, 0.0};  // the first tilt_count are used
  std::size_t tilt_count = 2;
  double width_px = 160.0;
  double height_px = 120.0;
  double focal_px = 150.0;
  // A feature detector keeps the best features of a textured image; an image that sees
  // mostly featureless floor yields fewer. Pixels tried per image, as a multiple of its
  // share of features, before it gives up.
  double attempts_per_feature = 20.0;
  // The stereo's range error: each reading's range is multiplied by 1 + e, e drawn from a
  // Laplace distribution of scale range_error_b (|e| has median b ln 2, 90th percentile
  // b ln 10). 0: exact ranges. kStereoRangeErrorB matches the stereo suite's measurements.
  double range_error_b = 0.0;
};

// Laplace scale of the stereo's relative range error: the stereo suite's 1-2 m band has
// |r - r_true| / r_true at 0.009 / 0.029 / 0.039 (50th / 90th / 95th percentile,
// docs/benchmarks.md); b = 0.013 gives 0.009 / 0.030 / 0.039.
inline constexpr double kStereoRangeErrorB = 0.013;

// Axis-aligned bounds [m].
struct Bounds3 {
  Vec3 min;
  Vec3 max;
};

// The ten rows of the thesis's simulation table, in its order.
std::span<const RoomSpec> thesis_environments();
// Looks a row up by name; nullptr if unknown.
const RoomSpec* find_environment(const char* name);

class SyntheticRoom {
 public:
  explicit SyntheticRoom(const RoomSpec& spec) : spec_(spec) {}

  [[nodiscard]] const RoomSpec& spec() const { return spec_; }
  // The PTU centre: the origin of every Reading's (α, h, r).
  [[nodiscard]] Vec3 sensor() const { return spec_.sensor; }
  // The room's bounding box, floor to wall top (cylinder: the square around it).
  [[nodiscard]] Bounds3 bounds() const;

  // Ground truth. Inside: within the walls, above the floor, below the wall top.
  [[nodiscard]] bool inside_room(const Vec3& p) const;
  [[nodiscard]] bool inside_box(const Vec3& p) const;
  // Solid: outside the walls (at wall height), inside the box, or below the floor.
  [[nodiscard]] bool solid(const Vec3& p) const;
  // Free and seen: inside the room, not in the box, and the segment from the sensor to p
  // is not blocked by the box. Everything else is occupied or unknown to the sensor.
  [[nodiscard]] bool visible_free(const Vec3& p) const;

  // First surface along a ray from the sensor: distance [m] (infinity if none) and
  // whether the surface has features (walls and the box do, the floor does not).
  struct Hit {
    double distance_m;
    bool featured;
  };
  [[nodiscard]] Hit cast_from_sensor(const Vec3& direction_unit) const;

  // `features` readings: pan angle uniform in [0, 2π), a point uniform in height on the
  // wall in that direction, the first surface on the line of sight to it (wall or box),
  // evidence feature_m. A share outlier_fraction (of the spec, or the override if ≥ 0)
  // is moved to half its distance. Deterministic for a seed.
  [[nodiscard]] std::vector<evidence::Reading> generate_readings(
      std::size_t features, std::uint32_t seed, double outlier_fraction_override = -1.0) const;

  // `features` readings as the camera finds them (CameraScan): the share of each image is
  // taken at uniformly random pixels whose line of sight first meets a featured surface
  // (walls and the box, not the floor) within max_range_m; the pan positions start at a
  // random offset. So low obstacles are seen from above and in front, as the robot sees
  // them, and nothing is seen through them. Outliers as generate_readings. Deterministic
  // for a seed; fewer than `features` only if the images see too little texture.
  [[nodiscard]] std::vector<evidence::Reading> generate_camera_readings(
      const CameraScan& scan, std::size_t features, std::uint32_t seed,
      double outlier_fraction_override = -1.0) const;

  // (α, h, r) about the sensor ↔ world frame.
  [[nodiscard]] evidence::Reading reading_of(const Vec3& world_point, float m) const;
  [[nodiscard]] Vec3 world_of(const evidence::Reading& reading) const;

 private:
  // Horizontal distance from the sensor to the walls in direction (cx, cy) (unit).
  [[nodiscard]] double wall_distance_xy(double cx, double cy) const;
  [[nodiscard]] double box_entry(const Vec3& origin, const Vec3& dir, double t_max) const;
  // Casts along direction d (any length) and, if the first surface is featured and within
  // range, appends its reading (moved to half its distance with probability
  // outlier_fraction, one draw from rng; then, if range_error_b > 0, its range scaled by
  // 1 + e, e Laplace of that scale, one more draw). Returns whether it did.
  bool add_feature(Vec3 d, double outlier_fraction, double range_error_b, std::mt19937& rng,
                   std::vector<evidence::Reading>& out) const;
  RoomSpec spec_;
};

// Ray samples as the ALN's training samples: x = (α, h, r), y = the occupancy, weight 1.
std::vector<aln::Sample<float, 3>> to_fit_samples(std::span<const evidence::RaySample> samples);

// What the vs-octomap suite fits to a room's readings: their ray samples (Fig 4.2b, the
// plausibility bound), zero pads in featureless directions over the room's heights and range
// (§4.9.1, seeded) and seam copies, built in `buffer` (cleared first).
std::vector<aln::Sample<float, 3>> room_fit_samples(const SyntheticRoom& room,
                                                    std::span<const evidence::Reading> readings,
                                                    const evidence::RaySampleParams& params,
                                                    evidence::RaySampleBuffer& buffer);

// Sets `model`'s input box and weight bounds (evidence::configure_occupancy_model) for the
// room: heights from the floor to the wall tops relative to the sensor, ranges to 1.2 times
// the sensor's visibility, |∂F/∂α| bounded by max_alpha_slope_per_rad (the thesis's 1 per rad
// unless the sensor model says otherwise, evidence::alpha_slope_bound_per_rad).
template <typename Model>
void configure_room_model(Model& model, const SyntheticRoom& room,
                          float max_alpha_slope_per_rad = evidence::kMaxAlphaSlopePerRad) {
  evidence::configure_occupancy_model(
      model, static_cast<float>(-room.sensor().z),
      static_cast<float>(room.spec().wall_height_m - room.sensor().z),
      static_cast<float>(room.spec().max_range_m * 1.2), max_alpha_slope_per_rad);
}

}  // namespace boticelli::bench
