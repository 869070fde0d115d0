// Reads a PNG file back as 8-bit RGB for tests that check the pictures the firmware writes.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

namespace boticelli::test {

struct RgbImage {
  int width = 0;
  int height = 0;
  std::vector<std::uint8_t> rgb;  // row after row, 3 bytes a pixel

  std::array<int, 3> at(int x, int y) const {
    const std::size_t i = (static_cast<std::size_t>(y) * static_cast<std::size_t>(width) +
                           static_cast<std::size_t>(x)) *
                          3U;
    return {rgb[i], rgb[i + 1], rgb[i + 2]};
  }
  // How many pixels have exactly this colour.
  std::size_t count(std::array<int, 3> colour) const;
};

// False if the file cannot be read or decoded.
bool read_png(const std::string& path, RgbImage& out);

}  // namespace boticelli::test
