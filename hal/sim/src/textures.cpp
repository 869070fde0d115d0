// Procedural patterns: camouflage (blotches with sharp edges in every direction, so strong
// vertical intensity changes) and leaves (busy, but vertical streaks: weak vertical derivative).
#include "hal/sim/textures.h"

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdio>
#include <vector>

namespace boticelli::hal::sim {
namespace {

// Periodic value noise in [0, 1] on a lattice of cells_x x cells_y cells over the texture:
// the lattice values are hashed once, then each row of texels interpolates between them with
// smoothstep weights (cells are whole powers of two of texels, so the weights repeat).
class ValueNoise {
 public:
  ValueNoise(std::uint32_t seed, std::uint32_t cells_x, std::uint32_t cells_y)
      : cells_x_(cells_x),
        cells_y_(cells_y),
        span_x_(kTextureSize / cells_x),
        span_y_(kTextureSize / cells_y),
        lattice_(std::size_t{cells_x} * cells_y),
        weight_x_(span_x_),
        weight_y_(span_y_) {
    for (std::uint32_t cy = 0; cy < cells_y; ++cy) {
      for (std::uint32_t cx = 0; cx < cells_x; ++cx) {
        const std::uint32_t h = hash32(seed ^ hash32(cx * 0x9E3779B1U + hash32(cy + 0x1234567U)));
        lattice_[cy * cells_x + cx] = static_cast<float>(h >> 8U) / 16777216.0F;
      }
    }
    auto smoothstep = [](std::uint32_t k, std::uint32_t span) {
      const float t = static_cast<float>(k) / static_cast<float>(span);
      return t * t * (3.0F - 2.0F * t);
    };
    for (std::uint32_t k = 0; k < span_x_; ++k) weight_x_[k] = smoothstep(k, span_x_);
    for (std::uint32_t k = 0; k < span_y_; ++k) weight_y_[k] = smoothstep(k, span_y_);
  }

  // Adds weight x the noise of texel row y to `row` (kTextureSize values).
  void add_row(std::uint32_t y, float weight, float* row) const {
    const std::uint32_t y0 = y / span_y_;
    const std::uint32_t y1 = (y0 + 1U) % cells_y_;
    const float ty = weight_y_[y % span_y_];
    const float* l0 = &lattice_[std::size_t{y0} * cells_x_];
    const float* l1 = &lattice_[std::size_t{y1} * cells_x_];
    std::uint32_t x = 0;
    for (std::uint32_t cx = 0; cx < cells_x_; ++cx) {
      const std::uint32_t cx1 = (cx + 1U) % cells_x_;
      const float left = l0[cx] + (l1[cx] - l0[cx]) * ty;
      const float right = l0[cx1] + (l1[cx1] - l0[cx1]) * ty;
      for (std::uint32_t k = 0; k < span_x_; ++k, ++x) {
        row[x] += weight * (left + (right - left) * weight_x_[k]);
      }
    }
  }

 private:
  std::uint32_t cells_x_;
  std::uint32_t cells_y_;
  std::uint32_t span_x_;  // texels per cell
  std::uint32_t span_y_;
  std::vector<float> lattice_;  // built at init only
  std::vector<float> weight_x_;
  std::vector<float> weight_y_;
};

// Writes the tone indices (kCamouflageTones), 2 bits per texel, into `packed`.
void make_camouflage(std::uint32_t seed, std::uint8_t* packed) {
  constexpr std::uint32_t kBlotchCells = kTextureSize / static_cast<std::uint32_t>(kTexelsPerScale);
  const ValueNoise coarse(seed, kBlotchCells, kBlotchCells);
  const ValueNoise medium(seed + 101U, 2 * kBlotchCells, 2 * kBlotchCells);
  const ValueNoise fine(seed + 202U, 4 * kBlotchCells, 4 * kBlotchCells);
  std::vector<float> row(kTextureSize);
  for (std::uint32_t y = 0; y < kTextureSize; ++y) {
    std::fill(row.begin(), row.end(), 0.0F);
    coarse.add_row(y, 0.62F, row.data());
    medium.add_row(y, 0.28F, row.data());
    fine.add_row(y, 0.10F, row.data());
    std::uint8_t* out = packed + std::size_t{y} * (kTextureSize / 4U);
    for (std::uint32_t x = 0; x < kTextureSize; x += 4U) {
      std::uint32_t byte = 0;
      for (std::uint32_t k = 0; k < 4U; ++k) {
        const float n = row[x + k];
        const std::uint32_t tone = n < 0.40F ? 0U : (n < 0.50F ? 1U : (n < 0.60F ? 2U : 3U));
        byte |= tone << (2U * k);
      }
      out[x / 4U] = static_cast<std::uint8_t>(byte);
    }
  }
}

void make_leaves(std::uint32_t seed, std::uint8_t* out) {
  // Narrow (1/4 scale) and tall (4 scales) cells: intensity changes across, hardly along, the
  // vertical.
  constexpr std::uint32_t kAcross = kTextureSize / 2U;
  constexpr std::uint32_t kAlong = kTextureSize / 32U;
  const ValueNoise streaks(seed, kAcross, kAlong);
  const ValueNoise broad(seed + 77U, kAcross / 2U, kAlong / 2U);
  std::vector<float> row(kTextureSize);
  for (std::uint32_t y = 0; y < kTextureSize; ++y) {
    std::fill(row.begin(), row.end(), 0.0F);
    streaks.add_row(y, 0.7F, row.data());
    broad.add_row(y, 0.3F, row.data());
    for (std::uint32_t x = 0; x < kTextureSize; ++x) {
      // bugprone-incorrect-roundings: the tone is 70-190 (row is in [0, 1]), where adding 0.5
      // and truncating rounds half up, as lround does but for the float just below .5.
      // NOLINTNEXTLINE(bugprone-incorrect-roundings)
      out[y * kTextureSize + x] = static_cast<std::uint8_t>(70.0F + 120.0F * row[x] + 0.5F);
    }
  }
}

}  // namespace

bool TextureBank::build(World& world, char* error, std::size_t error_size) {
  count_ = 0;
  leaves_count_ = 0;
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
      if (s.pattern == Pattern::kLeaves && leaves_count_ == kMaxLeavesTextures) {
        std::snprintf(error, error_size,
                      "line %d: more than %zu distinct leaves seeds (reuse seeds)", s.line,
                      kMaxLeavesTextures);
        return false;
      }
      if (s.pattern == Pattern::kCamouflage) {
        keys_[k] = {s.pattern, s.pattern_seed, k};
        make_camouflage(s.pattern_seed, camouflage_[k]);
      } else {
        keys_[k] = {s.pattern, s.pattern_seed, leaves_count_};
        make_leaves(s.pattern_seed, leaves_[leaves_count_]);
        ++leaves_count_;
      }
      ++count_;
    }
    s.texture = static_cast<int>(k);
  }
  return true;
}

float TextureBank::sample(int texture, float u, float v) const {
  const Key& key = keys_[static_cast<std::size_t>(texture)];
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
  const std::size_t i00 = std::size_t{y0} * kTextureSize + x0;
  const std::size_t i01 = std::size_t{y0} * kTextureSize + x1;
  const std::size_t i10 = std::size_t{y1} * kTextureSize + x0;
  const std::size_t i11 = std::size_t{y1} * kTextureSize + x1;
  float t00 = 0.0F;
  float t01 = 0.0F;
  float t10 = 0.0F;
  float t11 = 0.0F;
  if (key.pattern == Pattern::kLeaves) {
    const std::uint8_t* t = leaves_[key.slot];
    t00 = static_cast<float>(t[i00]);
    t01 = static_cast<float>(t[i01]);
    t10 = static_cast<float>(t[i10]);
    t11 = static_cast<float>(t[i11]);
  } else {
    const std::uint8_t* t = camouflage_[key.slot];
    t00 = static_cast<float>(camouflage_tone(t, i00));
    t01 = static_cast<float>(camouflage_tone(t, i01));
    t10 = static_cast<float>(camouflage_tone(t, i10));
    t11 = static_cast<float>(camouflage_tone(t, i11));
  }
  const float tx = u - fu;
  const float ty = v - fv;
  const float a = t00 + (t01 - t00) * tx;
  const float b = t10 + (t11 - t10) * tx;
  return (a + (b - a) * ty) * (1.0F / 128.0F);
}

}  // namespace boticelli::hal::sim
