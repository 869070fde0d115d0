// TextureBank: the procedural surface patterns (camouflage, leaves), generated once per world.
#pragma once

#include <cstddef>
#include <cstdint>

#include "hal/sim/world.h"

namespace boticelli::hal::sim {

// Each texture is a periodic square of kTextureSize texels holding an intensity factor
// (texel / 128, so 128 = the diffuse colour itself). A pattern's `scale` is 8 texels.
inline constexpr std::uint32_t kTextureSize = 512;
inline constexpr float kTexelsPerScale = 8.0F;

class TextureBank {
 public:
  // Generates one texture per distinct (pattern, seed) of the world's camouflage and leaves
  // surfaces and sets each surface's `texture` index. False when there are too many.
  bool build(World& world, char* error, std::size_t error_size);
  std::size_t size() const { return count_; }
  // Intensity factor at (u, v) [texels], bilinear, wrapping.
  float sample(int texture, float u, float v) const;
  std::uint8_t texel(int texture, std::uint32_t x, std::uint32_t y) const {
    return texels_[static_cast<std::size_t>(texture)][y * kTextureSize + x];
  }

 private:
  struct Key {
    Pattern pattern;
    std::uint32_t seed;
  };
  Key keys_[kMaxTextures]{};
  std::size_t count_ = 0;
  std::uint8_t texels_[kMaxTextures][kTextureSize * kTextureSize]{};
};

// Deterministic integer hash (splitmix/murmur finaliser), shared by textures and noise.
inline std::uint32_t hash32(std::uint32_t x) {
  x ^= x >> 16U;
  x *= 0x7feb352dU;
  x ^= x >> 15U;
  x *= 0x846ca68bU;
  x ^= x >> 16U;
  return x;
}

}  // namespace boticelli::hal::sim
