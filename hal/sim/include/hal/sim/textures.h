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
// Camouflage has exactly these four tones (intensity factors x128: dark, mid, light, pale), so
// it is stored losslessly with 2 bits per texel (64 KiB a texture); leaves keep a byte per
// texel (256 KiB) and are rarer (trees), so fewer of them fit. A bank holds
// kMaxTextures x 64 KiB + kMaxLeavesTextures x 256 KiB (6 MiB with 64 and 8).
inline constexpr std::uint8_t kCamouflageTones[4] = {38, 96, 150, 210};
inline constexpr std::size_t kMaxLeavesTextures = 8;  // distinct leaves seeds

class TextureBank {
 public:
  // Generates one texture per distinct (pattern, seed) of the world's camouflage and leaves
  // surfaces and sets each surface's `texture` index. False when there are too many.
  bool build(World& world, char* error, std::size_t error_size);
  std::size_t size() const { return count_; }
  // Intensity factor at (u, v) [texels], bilinear, wrapping.
  float sample(int texture, float u, float v) const;
  // One texel's intensity factor x128.
  std::uint8_t texel(int texture, std::uint32_t x, std::uint32_t y) const {
    const Key& k = keys_[static_cast<std::size_t>(texture)];
    return k.pattern == Pattern::kLeaves
               ? leaves_[k.slot][y * kTextureSize + x]
               : camouflage_tone(camouflage_[k.slot], y * kTextureSize + x);
  }

 private:
  static constexpr std::size_t kTexels = std::size_t{kTextureSize} * kTextureSize;
  struct Key {
    Pattern pattern;
    std::uint32_t seed;
    std::size_t slot;  // index into camouflage_ or leaves_, by pattern
  };
  static std::uint8_t camouflage_tone(const std::uint8_t* packed, std::size_t i) {
    return kCamouflageTones[(static_cast<unsigned>(packed[i >> 2U]) >> ((i & 3U) * 2U)) & 3U];
  }
  Key keys_[kMaxTextures]{};
  std::size_t count_ = 0;
  std::size_t leaves_count_ = 0;
  std::uint8_t camouflage_[kMaxTextures][kTexels / 4]{};  // 2-bit tone indices, texel i in
                                                          // bits 2(i%4).. of byte i/4
  std::uint8_t leaves_[kMaxLeavesTextures][kTexels]{};
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
