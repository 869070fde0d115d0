// Snapshot drawing: the 3x5 bitmap font and the canvas primitives, all clipped (snapshot_canvas.h).
#include "snapshot_canvas.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstddef>
#include <cstring>

namespace boticelli::firmware::snapshot_detail {
namespace {

// A 3x5 bitmap font: 5 rows of 3 pixels, '#' set. Lower case prints as upper case.
struct Glyph {
  char c;
  const char* rows;  // 15 characters
};
constexpr std::array<Glyph, 54> kFont{{
    {'0', "####.##.##.####"}, {'1', ".#.##..#..#.###"}, {'2', "###..#####..###"},
    {'3', "###..#.##..####"}, {'4', "#.##.####..#..#"}, {'5', "####..###..####"},
    {'6', "####..####.####"}, {'7', "###..#..#.#..#."}, {'8', "####.#####.####"},
    {'9', "####.####..####"}, {'A', ".#.#.#####.##.#"}, {'B', "##.#.###.#.###."},
    {'C', ".###..#..#...##"}, {'D', "##.#.##.##.###."}, {'E', "####..##.#..###"},
    {'F', "####..##.#..#.."}, {'G', ".###..#.##.#.##"}, {'H', "#.##.#####.##.#"},
    {'I', "###.#..#..#.###"}, {'J', "..#..#..##.#.#."}, {'K', "#.##.###.#.##.#"},
    {'L', "#..#..#..#..###"}, {'M', "#.########.##.#"}, {'N', "##.#.##.##.##.#"},
    {'O', ".#.#.##.##.#.#."}, {'P', "##.#.###.#..#.."}, {'Q', ".#.#.##.####.##"},
    {'R', "##.#.###.#.##.#"}, {'S', ".###...#...###."}, {'T', "###.#..#..#..#."},
    {'U', "#.##.##.##.####"}, {'V', "#.##.##.##.#.#."}, {'W', "#.##.########.#"},
    {'X', "#.##.#.#.#.##.#"}, {'Y', "#.##.#.#..#..#."}, {'Z', "###..#.#.#..###"},
    {'-', "......###......"}, {'.', ".............#."}, {':', "....#.....#...."},
    {'=', "...###...###..."}, {'/', "..#..#.#.#..#.."}, {'(', ".#.#..#..#...#."},
    {')', ".#...#..#..#.#."}, {',', "..........#.#.."}, {'_', "............###"},
    {'+', "....#.###.#...."}, {'>', "#...#...#.#.#.."}, {'<', "..#.#.#...#...#"},
    {'#', "#.#####.#####.#"}, {'%', "#....#.#.#....#"}, {'*', "#.#.#.#.#......"},
    {'!', ".#..#..#.....#."}, {'?', "###..#.##....#."}, {' ', "..............."},
}};

constexpr bool glyphs_complete() {
  for (const Glyph& g : kFont) {
    int n = 0;
    while (g.rows[n] == '.' || g.rows[n] == '#') ++n;
    if (n != 15 || g.rows[n] != '\0') return false;
  }
  return true;
}
static_assert(glyphs_complete(), "every glyph has 5 rows of 3 pixels");

constexpr std::uint16_t glyph_bits(const char* rows) {
  std::uint16_t bits = 0;
  for (int i = 0; i < 15 && rows[i] != '\0'; ++i) {
    if (rows[i] == '#') bits = static_cast<std::uint16_t>(bits | (1U << i));
  }
  return bits;
}

constexpr std::array<std::uint16_t, 128> make_font_table() {
  std::array<std::uint16_t, 128> table{};
  for (const Glyph& g : kFont) table[static_cast<unsigned char>(g.c)] = glyph_bits(g.rows);
  for (char c = 'a'; c <= 'z'; ++c) {
    table[static_cast<unsigned char>(c)] = table[static_cast<unsigned char>(c - 'a' + 'A')];
  }
  return table;
}
constexpr std::array<std::uint16_t, 128> kFontBits = make_font_table();

}  // namespace

void Canvas::put(int x, int y, Rgb c) {
  if (x < clip_.x0 || y < clip_.y0 || x >= clip_.x1 || y >= clip_.y1) return;
  std::uint8_t* p = rgb_ + (static_cast<std::size_t>(y) * static_cast<std::size_t>(width_) +
                            static_cast<std::size_t>(x)) *
                               3U;
  p[0] = c.r;
  p[1] = c.g;
  p[2] = c.b;
  if (writes_ != nullptr) ++*writes_;
}

void Canvas::fill(Rect r, Rgb c) {
  const int x0 = std::max(r.x0, clip_.x0);
  const int x1 = std::min(r.x1, clip_.x1);
  const int y0 = std::max(r.y0, clip_.y0);
  const int y1 = std::min(r.y1, clip_.y1);
  if (x0 >= x1 || y0 >= y1) return;
  for (int y = y0; y < y1; ++y) {
    std::uint8_t* p = rgb_ + (static_cast<std::size_t>(y) * static_cast<std::size_t>(width_) +
                              static_cast<std::size_t>(x0)) *
                                 3U;
    for (int x = x0; x < x1; ++x, p += 3) {
      p[0] = c.r;
      p[1] = c.g;
      p[2] = c.b;
    }
  }
  if (writes_ != nullptr) {
    *writes_ += static_cast<std::uint64_t>(x1 - x0) * static_cast<std::uint64_t>(y1 - y0);
  }
}

void Canvas::line(float ax, float ay, float bx, float by, Rgb c) {
  if (!std::isfinite(ax) || !std::isfinite(ay) || !std::isfinite(bx) || !std::isfinite(by)) {
    return;
  }
  float t0 = 0.0F;
  float t1 = 1.0F;
  const float dx = bx - ax;
  const float dy = by - ay;
  const float lo_x = static_cast<float>(clip_.x0);
  const float hi_x = static_cast<float>(clip_.x1) - 0.001F;
  const float lo_y = static_cast<float>(clip_.y0);
  const float hi_y = static_cast<float>(clip_.y1) - 0.001F;
  const std::array<float, 4> p{-dx, dx, -dy, dy};
  const std::array<float, 4> q{ax - lo_x, hi_x - ax, ay - lo_y, hi_y - ay};
  for (std::size_t i = 0; i < 4; ++i) {
    if (p[i] == 0.0F) {
      if (q[i] < 0.0F) return;
      continue;
    }
    const float t = q[i] / p[i];
    if (p[i] < 0.0F) {
      t0 = std::max(t0, t);
    } else {
      t1 = std::min(t1, t);
    }
    if (t0 > t1) return;
  }
  int x = static_cast<int>(std::floor(ax + t0 * dx));
  int y = static_cast<int>(std::floor(ay + t0 * dy));
  const int xe = static_cast<int>(std::floor(ax + t1 * dx));
  const int ye = static_cast<int>(std::floor(ay + t1 * dy));
  const int sx = x < xe ? 1 : -1;
  const int sy = y < ye ? 1 : -1;
  const int ddx = std::abs(xe - x);
  const int ddy = -std::abs(ye - y);
  int err = ddx + ddy;
  for (;;) {
    put(x, y, c);
    if (x == xe && y == ye) break;
    const int e2 = 2 * err;
    if (e2 >= ddy) {
      err += ddy;
      x += sx;
    }
    if (e2 <= ddx) {
      err += ddx;
      y += sy;
    }
  }
}

void Canvas::disc(float cx, float cy, float r, Rgb c) {
  if (!std::isfinite(cx) || !std::isfinite(cy) || !(r >= 0.0F)) return;
  const int x0 = std::max(clip_.x0, static_cast<int>(std::floor(std::max(cx - r, -1e6F))));
  const int x1 = std::min(clip_.x1 - 1, static_cast<int>(std::ceil(std::min(cx + r, 1e6F))));
  const int y0 = std::max(clip_.y0, static_cast<int>(std::floor(std::max(cy - r, -1e6F))));
  const int y1 = std::min(clip_.y1 - 1, static_cast<int>(std::ceil(std::min(cy + r, 1e6F))));
  for (int y = y0; y <= y1; ++y) {
    for (int x = x0; x <= x1; ++x) {
      const float ex = static_cast<float>(x) + 0.5F - cx;
      const float ey = static_cast<float>(y) + 0.5F - cy;
      if (ex * ex + ey * ey <= r * r) put(x, y, c);
    }
  }
}

void Canvas::circle(float cx, float cy, float r, Rgb c) {
  if (!std::isfinite(cx) || !std::isfinite(cy) || !(r > 0.0F) || r > 1e5F) return;
  const int n = std::clamp(static_cast<int>(r), 16, 256);
  float px = cx + r;
  float py = cy;
  for (int i = 1; i <= n; ++i) {
    const float a = 6.2831853F * static_cast<float>(i) / static_cast<float>(n);
    const float qx = cx + r * std::cos(a);
    const float qy = cy - r * std::sin(a);
    line(px, py, qx, qy, c);
    px = qx;
    py = qy;
  }
}

void Canvas::square(float cx, float cy, int half, Rgb c) {
  if (!std::isfinite(cx) || !std::isfinite(cy) || std::fabs(cx) > 1e6F || std::fabs(cy) > 1e6F) {
    return;
  }
  const int x = static_cast<int>(std::floor(cx));
  const int y = static_cast<int>(std::floor(cy));
  fill({x - half, y - half, x + half + 1, y + half + 1}, c);
}

void Canvas::text(int x, int y, const char* s, Rgb c) {
  for (; *s != '\0'; ++s, x += kGlyphAdvancePx) {
    const auto index = static_cast<unsigned char>(*s);
    const std::uint16_t bits = index < 128 ? kFontBits[index] : kFontBits['?'];
    for (int row = 0; row < 5; ++row) {
      for (int col = 0; col < 3; ++col) {
        if ((bits & (1U << (row * 3 + col))) == 0) continue;
        fill({x + col * kTextScale, y + row * kTextScale, x + (col + 1) * kTextScale,
              y + (row + 1) * kTextScale},
             c);
      }
    }
  }
}

int text_width(const char* s) {
  const auto n = static_cast<int>(std::strlen(s));
  return n == 0 ? 0 : n * kGlyphAdvancePx - kTextScale;
}

}  // namespace boticelli::firmware::snapshot_detail
