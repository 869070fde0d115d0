// Ray-casting renderer of textured rectangles for the stereo tests and benchmark.
#include "scene_renderer.h"

#include <algorithm>
#include <cmath>
#include <array>
#include <vector>

namespace boticelli::test {

namespace {

std::uint32_t hash3(std::int32_t x, std::int32_t y, std::uint32_t seed) {
  std::uint32_t h = seed * 0x9E3779B9U ^ static_cast<std::uint32_t>(x) * 0x85EBCA6BU ^
                    static_cast<std::uint32_t>(y) * 0xC2B2AE35U;
  h ^= h >> 16;
  h *= 0x7FEB352DU;
  h ^= h >> 15;
  h *= 0x846CA68BU;
  h ^= h >> 16;
  return h;
}

float unit_hash(std::int32_t x, std::int32_t y, std::uint32_t seed) {
  return static_cast<float>(hash3(x, y, seed) >> 8) * (1.0F / 16777216.0F);
}

// Random lattice values, built once (lookups are much cheaper than hashing per sample,
// which matters under emulation and sanitizers).
constexpr std::int32_t kLattice = 512;
const std::array<float, kLattice * kLattice>& lattice() {
  static std::array<float, kLattice * kLattice> table{};
  static const bool filled = [] {
    for (std::int32_t y = 0; y < kLattice; ++y) {
      for (std::int32_t x = 0; x < kLattice; ++x) {
        table[static_cast<std::size_t>(y * kLattice + x)] = unit_hash(x, y, 0x51ED27U);
      }
    }
    return true;
  }();
  (void)filled;
  return table;
}

// Luma noise with unit standard deviation (sum of two uniforms), built once.
constexpr std::size_t kNoiseTable = 1U << 18;
const std::array<float, kNoiseTable>& noise_table() {
  static std::array<float, kNoiseTable> table{};
  static const bool filled = [] {
    for (std::size_t i = 0; i < kNoiseTable; ++i) {
      const std::uint32_t hash = hash3(static_cast<std::int32_t>(i), 17, 0xA5A5U);
      table[i] =
          2.449F * (static_cast<float>((hash & 0xFFFFU) + (hash >> 16)) * (1.0F / 65536.0F) - 1.0F);
    }
    return true;
  }();
  (void)filled;
  return table;
}

// Smooth value noise in [0, 1] with lattice spacing 1.
float value_noise(float x, float y, std::uint32_t seed) {
  const float fx = std::floor(x);
  const float fy = std::floor(y);
  const auto ix = static_cast<std::int32_t>(fx) + static_cast<std::int32_t>((seed * 97U) % 509U);
  const auto iy = static_cast<std::int32_t>(fy) + static_cast<std::int32_t>((seed * 61U) % 503U);
  float tx = x - fx;
  float ty = y - fy;
  tx = tx * tx * (3.0F - 2.0F * tx);
  ty = ty * ty * (3.0F - 2.0F * ty);
  const auto& t = lattice();
  const auto at = [&t](std::int32_t lx, std::int32_t ly) {
    return t[static_cast<std::size_t>((ly & (kLattice - 1)) * kLattice + (lx & (kLattice - 1)))];
  };
  const float a = at(ix, iy);
  const float b = at(ix + 1, iy);
  const float c = at(ix, iy + 1);
  const float d = at(ix + 1, iy + 1);
  return (a + (b - a) * tx) + ((c + (d - c) * tx) - (a + (b - a) * tx)) * ty;
}

struct Rgb {
  float r, g, b;
};
constexpr Rgb kPaperWhite{0.9F, 0.9F, 0.88F};
constexpr Rgb kTargetGreen{0.12F, 0.6F, 0.22F};

Rgb surface_colour(const Patch& p, float x_m, float y_m) {
  switch (p.surface) {
    case Surface::kTexture: {
      const float s = p.scale_m;
      const float n = 0.5F * value_noise(x_m / s, y_m / s, p.seed) +
                      0.3F * value_noise(x_m / (0.4F * s), y_m / (0.4F * s), p.seed + 1) +
                      0.2F * value_noise(x_m / (0.16F * s), y_m / (0.16F * s), p.seed + 2);
      const float g = 0.1F + 0.8F * n;
      return {g, g * 0.95F, g * 0.9F};
    }
    case Surface::kCamouflage: {
      const float s = p.scale_m;
      const float n = 0.7F * value_noise(x_m / s, y_m / s, p.seed) +
                      0.3F * value_noise(x_m / (0.3F * s), y_m / (0.3F * s), p.seed + 7);
      if (n < 0.3F) return {0.1F, 0.1F, 0.08F};     // black
      if (n < 0.48F) return {0.38F, 0.27F, 0.16F};  // brown
      if (n < 0.64F) return {0.3F, 0.38F, 0.2F};    // olive green
      return {0.55F, 0.52F, 0.36F};                 // khaki
    }
    case Surface::kPlain:
      return {p.colour[0], p.colour[1], p.colour[2]};
    case Surface::kPaper:
      return kPaperWhite;
    case Surface::kTarget: {
      // Equilateral triangle, vertex up, centroid at the patch centre.
      const float s = p.target_side_m;
      const float h = s * 0.8660254F;
      const float top = 2.0F * h / 3.0F;
      const float below = y_m - (top - h);  // height above the base
      if (below >= 0.0F && y_m <= top) {
        const float half = 0.5F * s * (top - y_m) / h;
        if (std::fabs(x_m) <= half) return kTargetGreen;
      }
      return kPaperWhite;
    }
    case Surface::kTriangleOnPlain:
    case Surface::kTallTriangle: {
      const float s = p.target_side_m;
      const float h = (p.surface == Surface::kTallTriangle ? 3.0F : 1.0F) * s * 0.8660254F;
      const float top = 2.0F * h / 3.0F;
      const float below = y_m - (top - h);
      if (below >= 0.0F && y_m <= top && std::fabs(x_m) <= 0.5F * s * (top - y_m) / h) {
        return kTargetGreen;
      }
      return p.surface == Surface::kTallTriangle ? kPaperWhite
                                                 : Rgb{p.colour[0], p.colour[1], p.colour[2]};
    }
    case Surface::kGreenSquare:
      return (std::fabs(x_m) <= 0.5F * p.target_side_m && std::fabs(y_m) <= 0.5F * p.target_side_m)
                 ? kTargetGreen
                 : kPaperWhite;
  }
  return {p.colour[0], p.colour[1], p.colour[2]};
}

std::uint8_t to_byte(float v) {
  return static_cast<std::uint8_t>(std::clamp(v, 0.0F, 255.0F) + 0.5F);
}

}  // namespace

Patch facing_wall(const Eigen::Vector3f& eye_m, const Eigen::Vector3f& forward, float distance_m,
                  float half_size_m, Surface surface, std::uint32_t seed) {
  Eigen::Vector3f f(forward.x(), forward.y(), 0.0F);
  f.normalize();
  Patch p;
  p.centre_m = eye_m + distance_m * f;
  p.right = Eigen::Vector3f(f.y(), -f.x(), 0.0F);  // seen from the eye, right is f × z
  p.up = Eigen::Vector3f::UnitZ();
  p.half_width_m = half_size_m;
  p.half_height_m = half_size_m;
  p.surface = surface;
  p.seed = seed;
  return p;
}

bool SceneRenderer::intersect(const Eigen::Vector3f& origin_m, const Eigen::Vector3f& dir,
                              float& t_m, const Patch** hit) const {
  bool found = false;
  for (const Patch& p : patches_) {
    const Eigen::Vector3f normal = p.right.cross(p.up);
    const float denom = normal.dot(dir);
    if (std::fabs(denom) < 1e-9F) continue;
    const float t = normal.dot(p.centre_m - origin_m) / denom;
    if (!(t > 1e-4F) || (found && t >= t_m)) continue;
    const Eigen::Vector3f q = origin_m + t * dir - p.centre_m;
    if (std::fabs(q.dot(p.right)) > p.half_width_m || std::fabs(q.dot(p.up)) > p.half_height_m)
      continue;
    t_m = t;
    if (hit != nullptr) *hit = &p;
    found = true;
  }
  return found;
}

Eigen::Vector3f SceneRenderer::shade(const Eigen::Vector3f& origin_m,
                                     const Eigen::Vector3f& dir) const {
  float t = 0.0F;
  const Patch* hit = nullptr;
  if (!intersect(origin_m, dir, t, &hit)) return background;
  const Eigen::Vector3f q = origin_m + t * dir - hit->centre_m;
  const Rgb c = surface_colour(*hit, q.dot(hit->right), q.dot(hit->up));
  return {c.r, c.g, c.b};
}

void SceneRenderer::render_yuyv(const stereo::RigModel& rig, const stereo::CameraPose& pose,
                                std::uint8_t* yuyv, std::uint32_t noise_seed, float noise_sigma,
                                std::uint32_t sample_step) const {
  // Per-patch constants for this eye, so a sample costs a few multiplications per patch.
  // Plain floats: Eigen's out-of-line helpers would come from unoptimised test objects in
  // Debug builds (one definition per template), making the renderer crawl.
  struct Prepared {
    const Patch* patch;
    float normal[3];
    float right[3];
    float up[3];
    float numerator;  // n·(c − o)
    float eye_x;      // (o − c)·right
    float eye_y;      // (o − c)·up
  };
  std::array<Prepared, 32> prepared{};
  std::size_t count = 0;
  for (const Patch& p : patches_) {
    if (count == prepared.size()) break;
    const Eigen::Vector3f normal = p.right.cross(p.up);
    const Eigen::Vector3f offset = pose.centre_m - p.centre_m;
    prepared[count++] = {&p,
                         {normal.x(), normal.y(), normal.z()},
                         {p.right.x(), p.right.y(), p.right.z()},
                         {p.up.x(), p.up.y(), p.up.z()},
                         -normal.dot(offset),
                         offset.dot(p.right),
                         offset.dot(p.up)};
  }
  const stereo::CameraIntrinsics& cam = rig.camera();
  float rot[9];
  for (int r = 0; r < 3; ++r) {
    for (int c = 0; c < 3; ++c) rot[r * 3 + c] = pose.rotation(r, c);
  }
  const float bg[3] = {background.x(), background.y(), background.z()};
  const auto colour_at = [&](float pu, float pv, float ycc[3]) {
    float d[3];
    if (cam.k1 == 0.0F && cam.radial_k1_only()) {
      const float xn = (pu - cam.principal_x_px) / cam.focal_px;
      const float yn = (pv - cam.principal_y_px) / cam.focal_px;
      for (int r = 0; r < 3; ++r) d[r] = rot[r * 3] * xn + rot[r * 3 + 1] * yn + rot[r * 3 + 2];
    } else {
      const Eigen::Vector3f ray = stereo::RigModel::ray_ptu(pose, cam, Eigen::Vector2f(pu, pv));
      d[0] = ray.x();
      d[1] = ray.y();
      d[2] = ray.z();
    }
    const Patch* hit = nullptr;
    float hit_x = 0.0F;
    float hit_y = 0.0F;
    float nearest = 0.0F;
    for (std::size_t i = 0; i < count; ++i) {
      const Prepared& q = prepared[i];
      const float denom = q.normal[0] * d[0] + q.normal[1] * d[1] + q.normal[2] * d[2];
      if (std::fabs(denom) < 1e-9F) continue;
      const float t = q.numerator / denom;
      if (!(t > 1e-4F) || (hit != nullptr && t >= nearest)) continue;
      const float x = q.eye_x + t * (d[0] * q.right[0] + d[1] * q.right[1] + d[2] * q.right[2]);
      const float y = q.eye_y + t * (d[0] * q.up[0] + d[1] * q.up[1] + d[2] * q.up[2]);
      if (std::fabs(x) > q.patch->half_width_m || std::fabs(y) > q.patch->half_height_m) continue;
      nearest = t;
      hit = q.patch;
      hit_x = x;
      hit_y = y;
    }
    const Rgb c = hit == nullptr ? Rgb{bg[0], bg[1], bg[2]} : surface_colour(*hit, hit_x, hit_y);
    // BT.601 full range, chroma centred on 128.
    ycc[0] = 255.0F * (0.299F * c.r + 0.587F * c.g + 0.114F * c.b);
    ycc[1] = 128.0F + 255.0F * (-0.168736F * c.r - 0.331264F * c.g + 0.5F * c.b);
    ycc[2] = 128.0F + 255.0F * (0.5F * c.r - 0.418688F * c.g - 0.081312F * c.b);
  };
  const auto w = static_cast<std::int32_t>(cam.width_px);
  const auto h = static_cast<std::int32_t>(cam.height_px);
  const std::int32_t step = sample_step == 2 ? 2 : 1;
  const auto& noise = noise_table();
  const std::size_t noise_offset = std::size_t{noise_seed} * 7919U;
  std::vector<float> samples(static_cast<std::size_t>(w) * 3);  // Y Cb Cr per sample of a row
  for (std::int32_t v = 0; v < h; ++v) {
    std::uint8_t* row = yuyv + static_cast<std::ptrdiff_t>(v) * w * 2;
    if (step == 1 || v % 2 == 0) {
      for (std::int32_t u = 0; u < w; u += step) {
        const float offset = step == 2 ? 0.5F : 0.0F;
        colour_at(static_cast<float>(u) + offset, static_cast<float>(v) + offset,
                  &samples[static_cast<std::size_t>(u / step) * 3]);
      }
    }
    for (std::int32_t u = 0; u < w; u += 2) {
      const float* a = &samples[static_cast<std::size_t>(u / step) * 3];
      const float* b = &samples[static_cast<std::size_t>((u + 1) / step) * 3];
      const std::size_t i =
          static_cast<std::size_t>(v) * static_cast<std::size_t>(w) + static_cast<std::size_t>(u);
      std::uint8_t* p = row + static_cast<std::ptrdiff_t>(u) * 2;
      p[0] = to_byte(a[0] + noise_sigma * noise[(i + noise_offset) & (kNoiseTable - 1)]);
      p[1] = to_byte(0.5F * (a[1] + b[1]));
      p[2] = to_byte(b[0] + noise_sigma * noise[(i + 1 + noise_offset) & (kNoiseTable - 1)]);
      p[3] = to_byte(0.5F * (a[2] + b[2]));
    }
  }
}

Eigen::Vector3f SceneRenderer::target_corner(const Patch& patch) {
  const float top = 2.0F * patch.target_side_m * 0.8660254F / 3.0F;
  return patch.centre_m + top * patch.up;
}

}  // namespace boticelli::test
