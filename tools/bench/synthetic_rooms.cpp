// Synthetic range data for the environments of thesis §4.8.2: room geometry, ray casting, readings.
#include "synthetic_rooms.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstring>
#include <limits>
#include <numbers>
#include <random>

namespace boticelli::bench {
namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();
constexpr double kTwoPi = 2.0 * std::numbers::pi;

// Cylinder of radius 2.5 m about (0, 0); rectangle 5 x 4.5 m; corridor 5 x 1.5 m.
// The PTU centre is 1 m above the floor, mid-height of the 2 m walls.
constexpr double kSensorZ = 1.0;
constexpr FloorBox kNoBox{};
constexpr FloorBox kBoxInCylinder{0.75, 1.25, -0.25, 0.25, 0.5};
constexpr FloorBox kBoxInRectangleA{1.0, 1.5, 0.8, 1.3, 0.5};
constexpr FloorBox kBoxInRectangleB{-1.4, -0.6, -1.3, -0.5, 0.5};

const std::array<RoomSpec, 10> kEnvironments = {{
    {"cylinder_centre",
     "cylindrical room seen from its centre (Fig 4.5a,c)",
     1,
     RoomShape::kCylinder,
     2.5,
     0,
     0,
     0,
     0,
     {0.0, 0.0, kSensorZ},
     kNoBox,
     0.0},
    {"cylinder_centre_outliers",
     "same, 5% outliers at half distance (Fig 4.5b,d)",
     7,
     RoomShape::kCylinder,
     2.5,
     0,
     0,
     0,
     0,
     {0.0, 0.0, kSensorZ},
     kNoBox,
     0.05},
    {"cylinder_offcentre",
     "cylindrical room seen from an arbitrary point (Fig 4.5e,g)",
     16,
     RoomShape::kCylinder,
     2.5,
     0,
     0,
     0,
     0,
     {1.0, 0.7, kSensorZ},
     kNoBox,
     0.0},
    {"cylinder_offcentre_outliers",
     "same, 5% outliers (Fig 4.5f,h)",
     57,
     RoomShape::kCylinder,
     2.5,
     0,
     0,
     0,
     0,
     {1.0, 0.7, kSensorZ},
     kNoBox,
     0.05},
    {"rectangle",
     "rectangular room (Fig 4.6a,d)",
     45,
     RoomShape::kRectangle,
     0,
     -2.5,
     2.5,
     -2.0,
     2.5,
     {0.0, 0.0, kSensorZ},
     kNoBox,
     0.0},
    {"corridor",
     "corridor, one wall far (Fig 4.6b,e)",
     6,
     RoomShape::kRectangle,
     0,
     -1.0,
     4.0,
     -0.75,
     0.75,
     {0.0, 0.0, kSensorZ},
     kNoBox,
     0.0},
    {"cylinder_box_view1",
     "0.5 m box in the cylindrical room, view 1 (Fig 4.7a)",
     59,
     RoomShape::kCylinder,
     2.5,
     0,
     0,
     0,
     0,
     {0.0, 0.0, kSensorZ},
     kBoxInCylinder,
     0.0},
    {"cylinder_box_view2",
     "0.5 m box in the cylindrical room, view 2 (Fig 4.7b)",
     65,
     RoomShape::kCylinder,
     2.5,
     0,
     0,
     0,
     0,
     {-0.6, 0.8, kSensorZ},
     kBoxInCylinder,
     0.0},
    {"rectangle_box_case1",
     "box in the rectangular room, case 1 (Fig 4.7e)",
     151,
     RoomShape::kRectangle,
     0,
     -2.5,
     2.5,
     -2.0,
     2.5,
     {0.0, 0.0, kSensorZ},
     kBoxInRectangleA,
     0.0},
    {"rectangle_box_case2",
     "box in the rectangular room, case 2 (Fig 4.7f)",
     252,
     RoomShape::kRectangle,
     0,
     -2.5,
     2.5,
     -2.0,
     2.5,
     {0.0, 0.0, kSensorZ},
     kBoxInRectangleB,
     0.0},
}};

}  // namespace

std::span<const RoomSpec> thesis_environments() {
  return kEnvironments;
}

const RoomSpec* find_environment(const char* name) {
  for (const RoomSpec& s : kEnvironments) {
    if (std::strcmp(s.name, name) == 0) {
      return &s;
    }
  }
  return nullptr;
}

Bounds3 SyntheticRoom::bounds() const {
  if (spec_.shape == RoomShape::kCylinder) {
    const double r = spec_.radius_m;
    return {{-r, -r, 0.0}, {r, r, spec_.wall_height_m}};
  }
  return {{spec_.x_min, spec_.y_min, 0.0}, {spec_.x_max, spec_.y_max, spec_.wall_height_m}};
}

bool SyntheticRoom::inside_room(const Vec3& p) const {
  if (p.z < 0.0 || p.z > spec_.wall_height_m) {
    return false;
  }
  if (spec_.shape == RoomShape::kCylinder) {
    return p.x * p.x + p.y * p.y < spec_.radius_m * spec_.radius_m;
  }
  return p.x > spec_.x_min && p.x < spec_.x_max && p.y > spec_.y_min && p.y < spec_.y_max;
}

bool SyntheticRoom::inside_box(const Vec3& p) const {
  const FloorBox& b = spec_.box;
  return b.height_m > 0.0 && p.x >= b.x_min && p.x <= b.x_max && p.y >= b.y_min && p.y <= b.y_max &&
         p.z >= 0.0 && p.z <= b.height_m;
}

bool SyntheticRoom::solid(const Vec3& p) const {
  if (p.z < 0.0) {
    return true;
  }
  if (inside_box(p)) {
    return true;
  }
  return p.z <= spec_.wall_height_m && !inside_room(p);
}

double SyntheticRoom::box_entry(const Vec3& o, const Vec3& d, double t_max) const {
  const FloorBox& b = spec_.box;
  if (!(b.height_m > 0.0)) {
    return kInf;
  }
  const std::array<double, 3> lo = {b.x_min, b.y_min, 0.0};
  const std::array<double, 3> hi = {b.x_max, b.y_max, b.height_m};
  const std::array<double, 3> oo = {o.x, o.y, o.z};
  const std::array<double, 3> dd = {d.x, d.y, d.z};
  double t0 = 0.0;
  double t1 = t_max;
  for (std::size_t a = 0; a < 3; ++a) {
    if (std::fabs(dd[a]) < 1e-15) {
      if (oo[a] < lo[a] || oo[a] > hi[a]) {
        return kInf;
      }
      continue;
    }
    double ta = (lo[a] - oo[a]) / dd[a];
    double tb = (hi[a] - oo[a]) / dd[a];
    if (ta > tb) {
      std::swap(ta, tb);
    }
    t0 = std::max(t0, ta);
    t1 = std::min(t1, tb);
    if (t0 > t1) {
      return kInf;
    }
  }
  return t0;
}

bool SyntheticRoom::visible_free(const Vec3& p) const {
  if (!inside_room(p) || inside_box(p)) {
    return false;
  }
  const Vec3 s = spec_.sensor;
  const Vec3 d{p.x - s.x, p.y - s.y, p.z - s.z};
  // The segment s → p (parameter t in [0, 1]) must miss the box.
  return !(box_entry(s, d, 1.0) <= 1.0);
}

double SyntheticRoom::wall_distance_xy(double cx, double cy) const {
  const Vec3 s = spec_.sensor;
  if (spec_.shape == RoomShape::kCylinder) {
    // |s + t c| = R, t > 0 (s inside).
    const double b = s.x * cx + s.y * cy;
    const double c = s.x * s.x + s.y * s.y - spec_.radius_m * spec_.radius_m;
    return -b + std::sqrt(b * b - c);
  }
  double t = kInf;
  if (cx > 0.0) {
    t = std::min(t, (spec_.x_max - s.x) / cx);
  } else if (cx < 0.0) {
    t = std::min(t, (spec_.x_min - s.x) / cx);
  }
  if (cy > 0.0) {
    t = std::min(t, (spec_.y_max - s.y) / cy);
  } else if (cy < 0.0) {
    t = std::min(t, (spec_.y_min - s.y) / cy);
  }
  return t;
}

SyntheticRoom::Hit SyntheticRoom::cast_from_sensor(const Vec3& d) const {
  const Vec3 s = spec_.sensor;
  const double dxy = std::hypot(d.x, d.y);
  double t_wall = kInf;
  if (dxy > 1e-12) {
    const double t = wall_distance_xy(d.x / dxy, d.y / dxy) / dxy;
    const double z = s.z + d.z * t;
    if (z >= 0.0 && z <= spec_.wall_height_m) {
      t_wall = t;
    }
  }
  const double t_floor = d.z < 0.0 ? -s.z / d.z : kInf;
  const double t_box = box_entry(s, d, kInf);
  if (t_box <= t_wall && t_box <= t_floor && std::isfinite(t_box)) {
    return {t_box, true};
  }
  if (t_wall <= t_floor && std::isfinite(t_wall)) {
    return {t_wall, true};
  }
  return {t_floor, false};
}

evidence::Reading SyntheticRoom::reading_of(const Vec3& p, float m) const {
  const Vec3 s = spec_.sensor;
  const double dx = p.x - s.x;
  const double dy = p.y - s.y;
  const double dz = p.z - s.z;
  double a = std::atan2(dy, dx);
  if (a < 0.0) {
    a += kTwoPi;
  }
  if (a >= kTwoPi) {
    a = 0.0;
  }
  return {static_cast<float>(a), static_cast<float>(dz),
          static_cast<float>(std::sqrt(dx * dx + dy * dy + dz * dz)), m};
}

Vec3 SyntheticRoom::world_of(const evidence::Reading& reading) const {
  const double r = reading.r_m;
  const double h = reading.h_m;
  const double rho = std::sqrt(std::max(0.0, r * r - h * h));
  const Vec3 s = spec_.sensor;
  return {s.x + rho * std::cos(static_cast<double>(reading.alpha_rad)),
          s.y + rho * std::sin(static_cast<double>(reading.alpha_rad)), s.z + h};
}

bool SyntheticRoom::add_feature(Vec3 d, double outlier_fraction, double range_error_b,
                                std::mt19937& rng, std::vector<evidence::Reading>& out) const {
  const double len = std::sqrt(d.x * d.x + d.y * d.y + d.z * d.z);
  d = {d.x / len, d.y / len, d.z / len};
  const Hit hit = cast_from_sensor(d);
  if (!hit.featured || !(hit.distance_m <= spec_.max_range_m)) {
    return false;
  }
  double t = hit.distance_m;
  if (std::uniform_real_distribution<double>(0.0, 1.0)(rng) < outlier_fraction) {
    t *= 0.5;  // §4.8.2: outliers appear twice as close as they are
  }
  if (range_error_b > 0.0) {
    // Laplace by inversion: u uniform in (-1/2, 1/2), e = -b sgn(u) ln(1 - 2|u|).
    const double u = std::uniform_real_distribution<double>(-0.5, 0.5)(rng);
    const double e = range_error_b * std::copysign(-std::log1p(-2.0 * std::fabs(u)), u);
    t *= std::max(1.0 + e, 0.05);
  }
  const Vec3 s = spec_.sensor;
  out.push_back(reading_of({s.x + d.x * t, s.y + d.y * t, s.z + d.z * t},
                           static_cast<float>(spec_.feature_m)));
  return true;
}

std::vector<evidence::Reading> SyntheticRoom::generate_readings(
    std::size_t features, std::uint32_t seed, double outlier_fraction_override) const {
  const double outliers =
      outlier_fraction_override >= 0.0 ? outlier_fraction_override : spec_.outlier_fraction;
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  std::vector<evidence::Reading> out;
  out.reserve(features);
  const Vec3 s = spec_.sensor;
  std::size_t attempts = 0;
  while (out.size() < features && attempts < 100 * features + 100) {
    ++attempts;
    const double alpha = kTwoPi * unit(rng);
    const double cx = std::cos(alpha);
    const double cy = std::sin(alpha);
    const double rho = wall_distance_xy(cx, cy);
    const double z = spec_.wall_height_m * unit(rng);
    (void)add_feature({rho * cx, rho * cy, z - s.z}, outliers, 0.0, rng, out);
  }
  return out;
}

std::vector<evidence::Reading> SyntheticRoom::generate_camera_readings(
    const CameraScan& scan, std::size_t features, std::uint32_t seed,
    double outlier_fraction_override) const {
  const double outliers =
      outlier_fraction_override >= 0.0 ? outlier_fraction_override : spec_.outlier_fraction;
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  std::vector<evidence::Reading> out;
  const std::size_t tilts = std::min(scan.tilt_count, scan.tilt_rad.size());
  const std::size_t images = scan.pan_positions * tilts;
  if (images == 0 || !(scan.focal_px > 0.0)) {
    return out;
  }
  out.reserve(features);
  const double pan_offset = kTwoPi * unit(rng);
  for (std::size_t image = 0; image < images; ++image) {
    // Images share the features evenly; the first ones take the remainder.
    const std::size_t quota = features / images + (image < features % images ? 1 : 0);
    const std::size_t pan_index = image / tilts;  // each pan position takes `tilts` images
    const double pan = pan_offset + kTwoPi * static_cast<double>(pan_index) /
                                        static_cast<double>(scan.pan_positions);
    const double tilt = scan.tilt_rad[image % tilts];
    const double cp = std::cos(pan);
    const double sp = std::sin(pan);
    const double ct = std::cos(tilt);
    const double st = std::sin(tilt);
    const auto max_attempts =
        static_cast<std::size_t>(scan.attempts_per_feature * static_cast<double>(quota)) + 1;
    std::size_t found = 0;
    for (std::size_t attempt = 0; attempt < max_attempts && found < quota; ++attempt) {
      // Pixel → camera frame (x forward, y left, z up) → tilt about y → pan about z.
      const double u = scan.width_px * unit(rng);
      const double v = scan.height_px * unit(rng);
      const double yc = -(u - 0.5 * scan.width_px) / scan.focal_px;
      const double zc = -(v - 0.5 * scan.height_px) / scan.focal_px;
      const double xt = ct - zc * st;  // forward after tilting (tilt < 0 looks down)
      const double zt = st + zc * ct;
      if (add_feature({xt * cp - yc * sp, xt * sp + yc * cp, zt}, outliers, scan.range_error_b, rng,
                      out)) {
        ++found;
      }
    }
  }
  return out;
}

std::vector<aln::Sample<float, 3>> to_fit_samples(std::span<const evidence::RaySample> samples) {
  std::vector<aln::Sample<float, 3>> out(samples.size());
  for (std::size_t i = 0; i < samples.size(); ++i) {
    out[i].x = Eigen::Vector3f(samples[i].alpha_rad, samples[i].h_m, samples[i].r_m);
    out[i].y = samples[i].occupancy;
  }
  return out;
}

std::vector<aln::Sample<float, 3>> room_fit_samples(const SyntheticRoom& room,
                                                    std::span<const evidence::Reading> readings,
                                                    const evidence::RaySampleParams& params,
                                                    evidence::RaySampleBuffer& buffer) {
  buffer.clear();
  (void)evidence::append_ray_samples(readings, params, buffer,
                                     evidence::OccupancyBound::kPlausibility);
  evidence::PadRegion region;
  region.h_min_m = static_cast<float>(-room.sensor().z);
  region.h_max_m = static_cast<float>(room.spec().wall_height_m - room.sensor().z);
  region.r_max_m = static_cast<float>(room.spec().max_range_m);
  evidence::PadRandom random{12345U};
  (void)evidence::append_featureless_pads(readings, region, evidence::FeaturelessPadParams{},
                                          random, buffer);
  (void)evidence::append_seam_copies(buffer, evidence::kSeamMarginRad);
  return to_fit_samples(std::span<const evidence::RaySample>(buffer.data(), buffer.size()));
}

}  // namespace boticelli::bench
