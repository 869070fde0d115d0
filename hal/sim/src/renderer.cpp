// Ray caster: per-pixel rays (with the lens distortion) against boxes, cylinders and planes,
// culled per 16x16 tile by each surface's projected bounds; Lambert + ambient shading,
// procedural patterns, vignetting, sensor noise; BT.601 (limited range) YUYV output.
#include "hal/sim/renderer.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>

namespace boticelli::hal::sim {

namespace {
constexpr float kNear_m = 1e-3F;
constexpr float kInf = std::numeric_limits<float>::infinity();
}  // namespace

// What one frame needs per surface: the camera in the surface's frame and its image bounds.
struct Renderer::Candidate {
  Eigen::Matrix3f local_from_camera;  // rotation
  Eigen::Vector3f origin_local;       // the optical centre in the surface's frame [m]
  float min_x, min_y, max_x, max_y;   // bounds in normalised image coordinates
  float min_z;                        // nearest z-depth of the bounds [m]
  bool visible;
  // Boxes seen from outside: the faces a ray can enter through are those whose plane has the
  // optical centre on its outer side (at most three; for a wall usually one).
  int entry_count;  // −1: the camera is inside the box
  int entry_axis[3];
  float entry_plane[3];  // ±half size on that axis [m]
};

struct Renderer::FrameSetup {
  Candidate surfaces[kMaxSurfaces];
};

namespace {

struct Hit {
  float t = kInf;  // z-depth [m] (rays are (x, y, 1) in the camera frame)
  int face = 0;
};

// Box centred at the origin with half extents h.
inline bool hit_box(const Eigen::Vector3f& o, const Eigen::Vector3f& d, const Eigen::Vector3f& h,
                    float best, Hit& hit) {
  float t_near = -kInf;
  float t_far = kInf;
  int face_near = 0;
  int face_far = 0;
  for (int a = 0; a < 3; ++a) {
    if (std::fabs(d[a]) < 1e-12F) {
      if (o[a] < -h[a] || o[a] > h[a]) return false;
      continue;
    }
    const float inv = 1.0F / d[a];
    float t0 = (-h[a] - o[a]) * inv;  // enters through the − face when d > 0
    float t1 = (h[a] - o[a]) * inv;
    int f0 = 2 * a + 1;
    int f1 = 2 * a;
    if (t0 > t1) {
      std::swap(t0, t1);
      std::swap(f0, f1);
    }
    if (t0 > t_near) {
      t_near = t0;
      face_near = f0;
    }
    if (t1 < t_far) {
      t_far = t1;
      face_far = f1;
    }
  }
  if (t_near > t_far || t_far < kNear_m) return false;
  const float t = t_near > kNear_m ? t_near : t_far;
  if (t >= best) return false;
  hit.t = t;
  hit.face = t_near > kNear_m ? face_near : face_far;
  return true;
}

// The same box for a ray from outside it: only the faces facing the origin can be entered,
// and a ray enters a convex body through at most one face.
inline bool hit_box_from_outside(const Eigen::Vector3f& o, const Eigen::Vector3f& d,
                                 const Eigen::Vector3f& h, int count, const int* axes,
                                 const float* planes, float best, Hit& hit) {
  for (int k = 0; k < count; ++k) {
    const int a = axes[k];
    const float gap = planes[k] - o[a];  // from the origin to the face's plane
    if (gap * d[a] <= 0.0F) continue;    // moving away from (or along) that face
    const float t = gap / d[a];
    if (t <= kNear_m || t >= best) continue;
    const int b = a == 0 ? 1 : 0;
    const int c = a == 2 ? 1 : 2;
    if (std::fabs(o[b] + t * d[b]) <= h[b] && std::fabs(o[c] + t * d[c]) <= h[c]) {
      hit = {t, 2 * a + (planes[k] < 0.0F ? 1 : 0)};
      return true;
    }
  }
  return false;
}

// Cylinder along z, radius h.x, half length h.z. Faces: 0 side, 4 top, 5 bottom.
inline bool hit_cylinder(const Eigen::Vector3f& o, const Eigen::Vector3f& d,
                         const Eigen::Vector3f& h, float best, Hit& hit) {
  bool found = false;
  const float r2 = h.x() * h.x();
  const float a = d.x() * d.x() + d.y() * d.y();
  if (a > 1e-12F) {
    const float b = o.x() * d.x() + o.y() * d.y();
    const float c = o.x() * o.x() + o.y() * o.y() - r2;
    const float disc = b * b - a * c;
    if (disc >= 0.0F) {
      const float s = std::sqrt(disc);
      for (const float t : {(-b - s) / a, (-b + s) / a}) {
        if (t > kNear_m && t < best && std::fabs(o.z() + t * d.z()) <= h.z()) {
          best = t;
          hit = {t, 0};
          found = true;
          break;
        }
      }
    }
  }
  if (std::fabs(d.z()) > 1e-12F) {
    for (const float zc : {h.z(), -h.z()}) {
      const float t = (zc - o.z()) / d.z();
      if (t > kNear_m && t < best) {
        const float x = o.x() + t * d.x();
        const float y = o.y() + t * d.y();
        if (x * x + y * y <= r2) {
          best = t;
          hit = {t, zc > 0.0F ? 4 : 5};
          found = true;
        }
      }
    }
  }
  return found;
}

// Rectangle in the local z = 0 plane, half extents h.x, h.y.
inline bool hit_plane(const Eigen::Vector3f& o, const Eigen::Vector3f& d, const Eigen::Vector3f& h,
                      float best, Hit& hit) {
  if (std::fabs(d.z()) < 1e-12F) return false;
  const float t = -o.z() / d.z();
  if (t <= kNear_m || t >= best) return false;
  if (std::fabs(o.x() + t * d.x()) > h.x() || std::fabs(o.y() + t * d.y()) > h.y()) return false;
  hit = {t, 4};
  return true;
}

inline bool hit_surface(const Surface& s, const Eigen::Vector3f& o, const Eigen::Vector3f& d,
                        float best, Hit& hit) {
  switch (s.shape) {
    case Shape::kBox:
      return hit_box(o, d, s.half_size_m, best, hit);
    case Shape::kCylinder:
      return hit_cylinder(o, d, s.half_size_m, best, hit);
    case Shape::kPlane:
      return hit_plane(o, d, s.half_size_m, best, hit);
  }
  return false;
}

// Gaussian-like noise in standard deviations (Irwin–Hall of four bytes), deterministic.
inline float noise_sd(std::uint32_t key) {
  const std::uint32_t h = hash32(key);
  const int sum = static_cast<int>(h & 0xFFU) + static_cast<int>((h >> 8U) & 0xFFU) +
                  static_cast<int>((h >> 16U) & 0xFFU) + static_cast<int>(h >> 24U);
  return static_cast<float>(sum - 510) * (1.0F / 147.8F);
}

inline std::uint8_t to_byte(float v) {
  // bugprone-incorrect-roundings: clamped to [0, 255] first, so adding 0.5 and truncating
  // rounds half up, as lround does but for the float just below .5, and costs no call.
  // NOLINTNEXTLINE(bugprone-incorrect-roundings)
  return static_cast<std::uint8_t>(std::clamp(v, 0.0F, 255.0F) + 0.5F);
}

}  // namespace

bool Renderer::init(const World& world, const TextureBank& textures,
                    const stereo::CameraIntrinsics& camera, const RenderSettings& settings,
                    char* error, std::size_t error_size) {
  if (camera.width_px == 0 || camera.height_px == 0 || camera.width_px % 2 != 0 ||
      camera.width_px > 4096 || camera.height_px > 4096 || !(camera.focal_px > 0.0F)) {
    std::snprintf(error, error_size, "camera %ux%u px, F %g px is not supported", camera.width_px,
                  camera.height_px, static_cast<double>(camera.focal_px));
    return false;
  }
  world_ = &world;
  textures_ = &textures;
  width_ = camera.width_px;
  height_ = camera.height_px;
  tiles_x_ = (width_ + kTile - 1) / kTile;
  tiles_y_ = (height_ + kTile - 1) / kTile;
  const std::size_t pixels = static_cast<std::size_t>(width_) * height_;
  rays_.reset(new float[2 * pixels]);
  vignette_.reset(new float[pixels]);
  tile_bounds_.reset(new float[4 * static_cast<std::size_t>(tiles_x_) * tiles_y_]);
  for (std::size_t t = 0; t < static_cast<std::size_t>(tiles_x_) * tiles_y_; ++t) {
    tile_bounds_[4 * t + 0] = kInf;
    tile_bounds_[4 * t + 1] = kInf;
    tile_bounds_[4 * t + 2] = -kInf;
    tile_bounds_[4 * t + 3] = -kInf;
  }
  for (std::uint32_t v = 0; v < height_; ++v) {
    for (std::uint32_t u = 0; u < width_; ++u) {
      const Eigen::Vector2f n = camera.normalized_from_pixel(
          Eigen::Vector2f(static_cast<float>(u), static_cast<float>(v)));
      const std::size_t i = static_cast<std::size_t>(v) * width_ + u;
      rays_[2 * i] = n.x();
      rays_[2 * i + 1] = n.y();
      float* b = &tile_bounds_[std::size_t{4} * ((v / kTile) * tiles_x_ + u / kTile)];
      b[0] = std::min(b[0], n.x());
      b[1] = std::min(b[1], n.y());
      b[2] = std::max(b[2], n.x());
      b[3] = std::max(b[3], n.y());
    }
  }
  // The target's frame in its surface's coordinates.
  const Surface& ts = world.surfaces[world.target_surface];
  if (ts.target_face != kNoFace) {
    const TargetFace f = target_face_frame(ts);
    const Eigen::Matrix3f rt = ts.world_from_local.rotation.transpose();
    target_centre_local_ = rt * (f.centre_m - ts.world_from_local.translation_m);
    target_up_local_ = rt * f.up;
    target_right_local_ = rt * f.right;
  }
  face_light_.reset(new Eigen::Vector3f[6 * kMaxSurfaces]);
  const Eigen::Vector3f ambient(world.ambient.r, world.ambient.g, world.ambient.b);
  const Eigen::Vector3f light(world.light_diffuse.r, world.light_diffuse.g, world.light_diffuse.b);
  for (std::size_t i = 0; i < world.surface_count; ++i) {
    for (int f = 0; f < 6; ++f) {
      Eigen::Vector3f n_local = Eigen::Vector3f::Zero();
      n_local[f / 2] = (f % 2 == 0) ? 1.0F : -1.0F;
      const Eigen::Vector3f n_world = world.surfaces[i].world_from_local.rotation * n_local;
      const float lambert = std::max(0.0F, -n_world.dot(world.light_direction));
      face_light_[6 * i + static_cast<std::size_t>(f)] = ambient + lambert * light;
    }
  }
  set_settings(settings);
  return true;
}

void Renderer::set_settings(const RenderSettings& settings) {
  settings_ = settings;
  settings_.vignetting = std::clamp(settings_.vignetting, 0.0F, 0.99F);
  // Vignetting: brightness falls with the squared distance from the image centre, to
  // (1 − vignetting) in the corners.
  const float cx = 0.5F * static_cast<float>(width_ - 1);
  const float cy = 0.5F * static_cast<float>(height_ - 1);
  const float r2_max = cx * cx + cy * cy;
  for (std::uint32_t v = 0; v < height_; ++v) {
    for (std::uint32_t u = 0; u < width_; ++u) {
      const float dx = static_cast<float>(u) - cx;
      const float dy = static_cast<float>(v) - cy;
      vignette_[static_cast<std::size_t>(v) * width_ + u] =
          1.0F - settings_.vignetting * (dx * dx + dy * dy) / r2_max;
    }
  }
}

void Renderer::setup_frame(const RigidTransform& world_from_camera, FrameSetup& setup) const {
  const Eigen::Matrix3f& rc = world_from_camera.rotation;
  const Eigen::Vector3f& oc = world_from_camera.translation_m;
  for (std::size_t i = 0; i < world_->surface_count; ++i) {
    const Surface& s = world_->surfaces[i];
    Candidate& c = setup.surfaces[i];
    const Eigen::Matrix3f rs_t = s.world_from_local.rotation.transpose();
    c.local_from_camera = rs_t * rc;
    c.origin_local = rs_t * (oc - s.world_from_local.translation_m);
    // Bounds: the corners of the local bounding box in the camera frame, with every edge
    // clipped to z ≥ near; the projection of a convex body is the hull of those points.
    const Eigen::Vector3f& h = s.half_size_m;
    const Eigen::Matrix3f camera_from_local = c.local_from_camera.transpose();
    const Eigen::Vector3f origin_camera = -camera_from_local * c.origin_local;
    Eigen::Vector3f corners[8];
    for (int k = 0; k < 8; ++k) {
      const Eigen::Vector3f p((k & 1) ? h.x() : -h.x(), (k & 2) ? h.y() : -h.y(),
                              (k & 4) ? h.z() : -h.z());
      corners[k] = camera_from_local * p + origin_camera;
    }
    c.min_x = kInf;
    c.min_y = kInf;
    c.max_x = -kInf;
    c.max_y = -kInf;
    c.min_z = kInf;
    auto add = [&c](const Eigen::Vector3f& p) {
      c.min_z = std::min(c.min_z, p.z());
      const float x = p.x() / p.z();
      const float y = p.y() / p.z();
      c.min_x = std::min(c.min_x, x);
      c.min_y = std::min(c.min_y, y);
      c.max_x = std::max(c.max_x, x);
      c.max_y = std::max(c.max_y, y);
    };
    for (int k = 0; k < 8; ++k) {
      if (corners[k].z() >= kNear_m) add(corners[k]);
      for (int bit = 1; bit < 8; bit <<= 1) {
        if ((k & bit) != 0) continue;
        const Eigen::Vector3f& a = corners[k];
        const Eigen::Vector3f& b = corners[k | bit];
        if ((a.z() < kNear_m) != (b.z() < kNear_m)) {
          const float t = (kNear_m - a.z()) / (b.z() - a.z());
          Eigen::Vector3f p = a + t * (b - a);
          p.z() = kNear_m;
          add(p);
        }
      }
    }
    c.visible = c.min_x <= c.max_x;
    c.entry_count = 0;
    if (s.shape == Shape::kBox) {
      for (int a = 0; a < 3; ++a) {
        if (c.origin_local[a] > h[a]) {
          c.entry_axis[c.entry_count] = a;
          c.entry_plane[c.entry_count++] = h[a];
        } else if (c.origin_local[a] < -h[a]) {
          c.entry_axis[c.entry_count] = a;
          c.entry_plane[c.entry_count++] = -h[a];
        }
      }
      if (c.entry_count == 0) c.entry_count = -1;
    }
  }
}

void Renderer::tile_candidates(const FrameSetup& setup, std::uint32_t tile, std::uint16_t* list,
                               std::size_t& count) const {
  const float* b = &tile_bounds_[4 * static_cast<std::size_t>(tile)];
  count = 0;
  for (std::size_t i = 0; i < world_->surface_count; ++i) {
    const Candidate& c = setup.surfaces[i];
    if (c.visible && c.max_x >= b[0] && c.min_x <= b[2] && c.max_y >= b[1] && c.min_y <= b[3]) {
      // Keep the list sorted by nearest depth, so a pixel can stop at the first surface
      // that cannot be beaten.
      std::size_t k = count++;
      while (k > 0 && setup.surfaces[list[k - 1]].min_z > c.min_z) {
        list[k] = list[k - 1];
        --k;
      }
      list[k] = static_cast<std::uint16_t>(i);
    }
  }
}

void Renderer::render(const RigidTransform& world_from_camera, std::uint32_t frame_index,
                      std::uint8_t* yuyv, std::size_t stride_bytes, float* depth_m) const {
  FrameSetup setup;
  setup_frame(world_from_camera, setup);
  const World& world = *world_;
  const Eigen::Vector3f light_dir = world.light_direction;
  const Eigen::Vector3f ambient(world.ambient.r, world.ambient.g, world.ambient.b);
  const Eigen::Vector3f light(world.light_diffuse.r, world.light_diffuse.g, world.light_diffuse.b);
  const std::uint32_t noise_key =
      hash32(static_cast<std::uint32_t>(settings_.seed) ^
             hash32(static_cast<std::uint32_t>(settings_.seed >> 32U) + frame_index * 0x9E3779B9U));
  const float exposure = settings_.exposure_jitter > 0.0F
                             ? std::max(0.0F, 1.0F + settings_.exposure_jitter *
                                                         noise_sd(hash32(noise_key ^ 0xE7F05E1DU)))
                             : 1.0F;
  const float gain = 255.0F * settings_.gain * exposure;
  std::uint16_t list[kMaxSurfaces];
  for (std::uint32_t ty = 0; ty < tiles_y_; ++ty) {
    for (std::uint32_t tx = 0; tx < tiles_x_; ++tx) {
      std::size_t count = 0;
      tile_candidates(setup, ty * tiles_x_ + tx, list, count);
      const std::uint32_t u_end = std::min(width_, (tx + 1) * kTile);
      const std::uint32_t v_end = std::min(height_, (ty + 1) * kTile);
      for (std::uint32_t v = ty * kTile; v < v_end; ++v) {
        std::uint8_t* row =
            yuyv != nullptr ? yuyv + static_cast<std::size_t>(v) * stride_bytes : nullptr;
        for (std::uint32_t u = tx * kTile; u < u_end; u += 2) {
          float rgb[2][3];
          for (std::uint32_t k = 0; k < 2; ++k) {
            const std::size_t pix = static_cast<std::size_t>(v) * width_ + u + k;
            const Eigen::Vector3f d_cam(rays_[2 * pix], rays_[2 * pix + 1], 1.0F);
            Hit best;
            int best_surface = -1;
            Eigen::Vector3f best_d = Eigen::Vector3f::Zero();  // the ray in that surface's frame
            for (std::size_t n = 0; n < count; ++n) {
              const Candidate& c = setup.surfaces[list[n]];
              if (c.min_z >= best.t) break;  // every later surface is farther
              // d_cam = (x, y, 1): two columns and a sum, no full product.
              const Eigen::Vector3f d = c.local_from_camera.col(0) * d_cam.x() +
                                        c.local_from_camera.col(1) * d_cam.y() +
                                        c.local_from_camera.col(2);
              Hit hit;
              const Surface& s = world.surfaces[list[n]];
              const bool found =
                  (s.shape == Shape::kBox && c.entry_count > 0)
                      ? hit_box_from_outside(c.origin_local, d, s.half_size_m, c.entry_count,
                                             c.entry_axis, c.entry_plane, best.t, hit)
                      : hit_surface(s, c.origin_local, d, best.t, hit);
              if (found) {
                best = hit;
                best_surface = list[n];
                best_d = d;
              }
            }
            if (depth_m != nullptr) depth_m[pix] = best.t;
            if (row == nullptr) continue;
            Eigen::Vector3f radiance;
            if (best_surface < 0) {
              radiance = Eigen::Vector3f(settings_.background.r, settings_.background.g,
                                         settings_.background.b);
            } else {
              const Surface& s = world.surfaces[static_cast<std::size_t>(best_surface)];
              const Candidate& c = setup.surfaces[static_cast<std::size_t>(best_surface)];
              const Eigen::Vector3f& d = best_d;
              const Eigen::Vector3f p = c.origin_local + best.t * d;
              Eigen::Vector3f n_local = Eigen::Vector3f::Zero();
              float su = 0.0F;  // surface coordinates [m]; sv runs "up" on vertical faces
              float sv = 0.0F;
              if (s.shape == Shape::kCylinder && best.face == 0) {
                n_local = Eigen::Vector3f(p.x(), p.y(), 0.0F) / s.half_size_m.x();
                su = s.half_size_m.x() * std::atan2(p.y(), p.x());
                sv = p.z();
              } else {
                const int axis = best.face / 2;
                n_local[axis] = (best.face % 2 == 0) ? 1.0F : -1.0F;
                su = axis == 0 ? p.y() : p.x();
                sv = axis == 2 ? p.y() : p.z();
              }
              // Planes are seen from both sides: light the side facing the camera.
              int face = best.face;
              if (n_local.dot(d) > 0.0F) {
                n_local = -n_local;
                face ^= 1;
              }
              Eigen::Vector3f albedo(s.diffuse.r, s.diffuse.g, s.diffuse.b);
              switch (s.pattern) {
                case Pattern::kPlain:
                  break;
                case Pattern::kPaper:
                  albedo = Eigen::Vector3f(0.93F, 0.93F, 0.91F);
                  break;
                case Pattern::kCamouflage:
                case Pattern::kLeaves: {
                  const float texels = kTexelsPerScale / s.pattern_scale_m;
                  albedo *= textures_->sample(s.texture, su * texels, sv * texels);
                  break;
                }
              }
              if (best.face == s.target_face && s.shape == Shape::kBox) {
                // Green equilateral triangle, centroid at the face centre, vertex up.
                const Eigen::Vector3f rel = p - target_centre_local_;
                const float a = rel.dot(target_right_local_);
                const float b = rel.dot(target_up_local_);
                const float circumradius = s.target_size_m * 0.57735027F;
                constexpr float kSqrt3 = 1.7320508F;
                if (b >= -0.5F * circumradius && kSqrt3 * a + b <= circumradius &&
                    -kSqrt3 * a + b <= circumradius) {
                  albedo = Eigen::Vector3f(0.05F, 0.60F, 0.10F);
                }
              }
              if (!settings_.shading) {
                radiance = albedo;
              } else if (s.shape == Shape::kCylinder && best.face == 0) {
                const Eigen::Vector3f n_world = s.world_from_local.rotation * n_local;
                const float lambert = std::max(0.0F, -n_world.dot(light_dir));
                radiance = albedo.cwiseProduct(ambient + lambert * light);
              } else {
                radiance =
                    albedo.cwiseProduct(face_light_[6 * static_cast<std::size_t>(best_surface) +
                                                    static_cast<std::size_t>(face)]);
              }
            }
            radiance *= gain * vignette_[pix];
            rgb[k][0] = radiance.x();
            rgb[k][1] = radiance.y();
            rgb[k][2] = radiance.z();
          }
          if (row == nullptr) continue;
          // BT.601 limited range from [0, 255] RGB; chroma averaged over the pixel pair.
          std::uint8_t* out = row + 2 * static_cast<std::size_t>(u);
          float y[2];
          for (std::uint32_t k = 0; k < 2; ++k) {
            y[k] =
                16.0F + (65.481F * rgb[k][0] + 128.553F * rgb[k][1] + 24.966F * rgb[k][2]) / 255.0F;
            if (settings_.noise_sigma_grey > 0.0F) {
              const std::uint32_t pix = v * width_ + u + k;
              y[k] += settings_.noise_sigma_grey * noise_sd(noise_key ^ (pix * 0x85EBCA6BU));
            }
          }
          const float r = 0.5F * (rgb[0][0] + rgb[1][0]);
          const float g = 0.5F * (rgb[0][1] + rgb[1][1]);
          const float bl = 0.5F * (rgb[0][2] + rgb[1][2]);
          float cb = 128.0F + (-37.797F * r - 74.203F * g + 112.0F * bl) / 255.0F;
          float cr = 128.0F + (112.0F * r - 93.786F * g - 18.214F * bl) / 255.0F;
          if (settings_.chroma_noise_sigma > 0.0F) {
            const std::uint32_t pair = (v * width_ + u) * 0xC2B2AE35U;
            cb += settings_.chroma_noise_sigma * noise_sd(noise_key ^ pair ^ 0x27D4EB2FU);
            cr += settings_.chroma_noise_sigma * noise_sd(noise_key ^ pair ^ 0x165667B1U);
          }
          out[0] = to_byte(y[0]);
          out[1] = to_byte(cb);
          out[2] = to_byte(y[1]);
          out[3] = to_byte(cr);
        }
      }
    }
  }
}

bool cast_ray(const World& world, const Eigen::Vector3f& origin_m, const Eigen::Vector3f& direction,
              std::size_t& surface, float& t) {
  Hit best;
  bool found = false;
  for (std::size_t i = 0; i < world.surface_count; ++i) {
    const Surface& s = world.surfaces[i];
    const Eigen::Matrix3f rs_t = s.world_from_local.rotation.transpose();
    const Eigen::Vector3f o = rs_t * (origin_m - s.world_from_local.translation_m);
    Hit hit;
    if (hit_surface(s, o, rs_t * direction, best.t, hit)) {
      best = hit;
      surface = i;
      found = true;
    }
  }
  t = best.t;
  return found;
}

bool Renderer::trace_pixel(const RigidTransform& world_from_camera, std::uint32_t u,
                           std::uint32_t v, std::size_t& surface, float& depth_m) const {
  if (u >= width_ || v >= height_) return false;
  const std::size_t pix = static_cast<std::size_t>(v) * width_ + u;
  const Eigen::Vector3f d_cam(rays_[2 * pix], rays_[2 * pix + 1], 1.0F);
  // The ray (x, y, 1) has unit z, so its parameter is the z-depth.
  return cast_ray(*world_, world_from_camera.translation_m, world_from_camera.rotation * d_cam,
                  surface, depth_m);
}

}  // namespace boticelli::hal::sim
