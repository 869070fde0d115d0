// Procedural patterns: camouflage (blotches with sharp edges in every direction, so strong
// vertical intensity changes) and leaves (busy, but vertical streaks: weak vertical derivative).
#include "hal/sim/textures.h"

#include <algorithm>
#include <cmath>
#include <cstdio>

namespace boticelli::hal::sim {
namespace {

// Periodic value noise in [0, 1]: lattice of `cells_x` x `cells_y` cells over the texture.
float value_noise(std::uint32_t seed, float x, float y, std::uint32_t cells_x,
                  std::uint32_t cells_y) {
  const float fx = x * static_cast<float>(cells_x) / static_cast<float>(kTextureSize);
  const float fy = y * static_cast<float>(cells_y) / static_cast<float>(kTextureSize);
  const float x0f = std::floor(fx);
  const float y0f = std::floor(fy);
  const std::uint32_t x0 = static_cast<std::uint32_t>(x0f) % cells_x;
  const std::uint32_t y0 = static_cast<std::uint32_t>(y0f) % cells_y;
  const std::uint32_t x1 = (x0 + 1U) % cells_x;
  const std::uint32_t y1 = (y0 + 1U) % cells_y;
  auto lattice = [&](std::uint32_t cx, std::uint32_t cy) {
    return static_cast<float>(hash32(seed ^ hash32(cx * 0x9E3779B1U + hash32(cy + 0x1234567U))) >>
                              8U) /
           16777216.0F;
  };
  float tx = fx - x0f;
  float ty = fy - y0f;
  tx = tx * tx * (3.0F - 2.0F * tx);  // smoothstep
  ty = ty * ty * (3.0F - 2.0F * ty);
  const float a = lattice(x0, y0) + (lattice(x1, y0) - lattice(x0, y0)) * tx;
  const float b = lattice(x0, y1) + (lattice(x1, y1) - lattice(x0, y1)) * tx;
  return a + (b - a) * ty;
}

void make_camouflage(std::uint32_t seed, std::uint8_t* out) {
  constexpr std::uint32_t kBlotchCells = kTextureSize / static_cast<std::uint32_t>(kTexelsPerScale);
  // Four cloth tones (intensity factors x128): dark, mid, light, pale.
  constexpr std::uint8_t kTones[4] = {38, 96, 150, 210};
  for (std::uint32_t y = 0; y < kTextureSize; ++y) {
    for (std::uint32_t x = 0; x < kTextureSize; ++x) {
      const float fx = static_cast<float>(x);
      const float fy = static_cast<float>(y);
      const float n = 0.62F * value_noise(seed, fx, fy, kBlotchCells, kBlotchCells) +
                      0.28F * value_noise(seed + 101U, fx, fy, 2 * kBlotchCells, 2 * kBlotchCells) +
                      0.10F * value_noise(seed + 202U, fx, fy, 4 * kBlotchCells, 4 * kBlotchCells);
      const int tone = n < 0.40F ? 0 : (n < 0.50F ? 1 : (n < 0.60F ? 2 : 3));
      out[y * kTextureSize + x] = kTones[tone];
    }
  }
}

void make_leaves(std::uint32_t seed, std::uint8_t* out) {
  // Narrow (1/4 scale) and tall (4 scales) cells: intensity changes across, hardly along, the
  // vertical.
  constexpr std::uint32_t kAcross = kTextureSize / 2U;
  constexpr std::uint32_t kAlong = kTextureSize / 32U;
  for (std::uint32_t y = 0; y < kTextureSize; ++y) {
    for (std::uint32_t x = 0; x < kTextureSize; ++x) {
      const float fx = static_cast<float>(x);
      const float fy = static_cast<float>(y);
      const float n = 0.7F * value_noise(seed, fx, fy, kAcross, kAlong) +
                      0.3F * value_noise(seed + 77U, fx, fy, kAcross / 2U, kAlong / 2U);
      out[y * kTextureSize + x] = static_cast<std::uint8_t>(std::lround(70.0F + 120.0F * n));
    }
  }
}

}  // namespace

bool TextureBank::build(World& world, char* error, std::size_t error_size) {
  count_ = 0;
  for (std::size_t i = 0; i < world.surface_count; ++i) {
    Surface& s = world.surfaces[i];
    if (s.pattern != Pattern::kCamouflage && s.pattern != Pattern::kLeaves) continue;
    std::size_t k = 0;
    while (k < count_ && !(keys_[k].pattern == s.pattern && keys_[k].seed == s.pattern_seed)) ++k;
    if (k == count_) {
      if (count_ == kMaxTextures) {
        std::snprintf(error, error_size,
                      "line %d: more than %zu distinct pattern seeds (reuse seeds)", s.line,
                      kMaxTextures);
        return false;
      }
      keys_[k] = {s.pattern, s.pattern_seed};
      if (s.pattern == Pattern::kCamouflage) {
        make_camouflage(s.pattern_seed, texels_[k]);
      } else {
        make_leaves(s.pattern_seed, texels_[k]);
      }
      ++count_;
    }
    s.texture = static_cast<int>(k);
  }
  return true;
}

float TextureBank::sample(int texture, float u, float v) const {
  const std::uint8_t* t = texels_[static_cast<std::size_t>(texture)];
  // floor() through a 32-bit int (u, v are bounded: the world is within 1000 m and a texel
  // is at least 0.6 mm, so |u|, |v| < 2e6); then wrap into the period.
  std::int32_t iu = static_cast<std::int32_t>(u);
  std::int32_t iv = static_cast<std::int32_t>(v);
  iu -= static_cast<float>(iu) > u ? 1 : 0;
  iv -= static_cast<float>(iv) > v ? 1 : 0;
  const float fu = static_cast<float>(iu);
  const float fv = static_cast<float>(iv);
  constexpr std::uint32_t kMask = kTextureSize - 1U;
  const std::uint32_t x0 = static_cast<std::uint32_t>(iu) & kMask;
  const std::uint32_t y0 = static_cast<std::uint32_t>(iv) & kMask;
  const std::uint32_t x1 = (x0 + 1U) & kMask;
  const std::uint32_t y1 = (y0 + 1U) & kMask;
  const float tx = u - fu;
  const float ty = v - fv;
  const float a = static_cast<float>(t[y0 * kTextureSize + x0]) +
                  (static_cast<float>(t[y0 * kTextureSize + x1]) -
                   static_cast<float>(t[y0 * kTextureSize + x0])) * tx;
  const float b = static_cast<float>(t[y1 * kTextureSize + x0]) +
                  (static_cast<float>(t[y1 * kTextureSize + x1]) -
                   static_cast<float>(t[y1 * kTextureSize + x0])) * tx;
  return (a + (b - a) * ty) * (1.0F / 128.0F);
}

}  // namespace boticelli::hal::sim
