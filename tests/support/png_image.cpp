// Reads a PNG file back as 8-bit RGB (libpng's simplified API).
#include "png_image.h"

#include <png.h>

namespace boticelli::test {

std::size_t RgbImage::count(std::array<int, 3> colour) const {
  std::size_t n = 0;
  for (std::size_t i = 0; i + 2 < rgb.size(); i += 3) {
    if (rgb[i] == colour[0] && rgb[i + 1] == colour[1] && rgb[i + 2] == colour[2]) ++n;
  }
  return n;
}

bool read_png(const std::string& path, RgbImage& out) {
  png_image image{};
  image.version = PNG_IMAGE_VERSION;
  if (png_image_begin_read_from_file(&image, path.c_str()) == 0) return false;
  image.format = PNG_FORMAT_RGB;
  out.width = static_cast<int>(image.width);
  out.height = static_cast<int>(image.height);
  out.rgb.resize(PNG_IMAGE_SIZE(image));
  const bool ok = png_image_finish_read(&image, nullptr, out.rgb.data(), 0, nullptr) != 0;
  png_image_free(&image);
  return ok;
}

}  // namespace boticelli::test
