// Snapshots: renders the four panels into the fixed canvas and writes them as PNG (snapshot.h).
#include "firmware/snapshot.h"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <array>
#include <cerrno>
#include <cstdarg>
#include <cmath>
#include <cstdio>
#include <cstring>

#ifdef BOTICELLI_HAVE_PNG
#include <png.h>
#endif

namespace boticelli::firmware {
namespace {

// ---------------------------------------------------------------------------------------------
// Colours (RGB). Tests read some of them back from the file.
struct Rgb {
  std::uint8_t r, g, b;
};
constexpr Rgb kPaper{235, 235, 235};  // around the panels
constexpr Rgb kInk{0, 0, 0};          // text, ticks
constexpr Rgb kFrameLine{90, 90, 90};
constexpr Rgb kTruth{255, 0, 255};  // true walls and colliders, 1 px
constexpr Rgb kRobot{255, 140, 0};
constexpr Rgb kObstacle{220, 0, 0};
constexpr Rgb kExploration{0, 90, 255};
constexpr Rgb kGoal{0, 200, 200};
constexpr Rgb kFreeFill{225, 240, 225};
constexpr Rgb kFreeLine{60, 140, 60};
constexpr Rgb kNavigableFill{170, 220, 170};
constexpr Rgb kNavigableLine{0, 100, 0};
constexpr Rgb kPath{60, 60, 60};
constexpr Rgb kContour{255, 220, 0};
constexpr Rgb kStep{255, 255, 255};
constexpr Rgb kNoData{128, 128, 128};

// ---------------------------------------------------------------------------------------------
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
constexpr int kTextScale = 2;                    // each font pixel is 2x2 picture pixels
constexpr int kGlyphAdvancePx = 4 * kTextScale;  // 3 columns + 1 space
constexpr int kGlyphHeightPx = 5 * kTextScale;

// ---------------------------------------------------------------------------------------------
// Drawing on the canvas. Every primitive clips to a rectangle, so no world coordinate can write
// outside the canvas or loop for long.
struct Rect {
  int x0, y0, x1, y1;  // half-open: [x0, x1) x [y0, y1)
};

class Canvas {
 public:
  Canvas(std::uint8_t* rgb, int width, int height) : rgb_(rgb), width_(width), height_(height) {}

  void set_clip(Rect r) { clip_ = r; }
  void clear_clip() { clip_ = {0, 0, width_, height_}; }

  void put(int x, int y, Rgb c) {
    if (x < clip_.x0 || y < clip_.y0 || x >= clip_.x1 || y >= clip_.y1) return;
    std::uint8_t* p = rgb_ + (static_cast<std::size_t>(y) * static_cast<std::size_t>(width_) +
                              static_cast<std::size_t>(x)) *
                                 3U;
    p[0] = c.r;
    p[1] = c.g;
    p[2] = c.b;
  }

  void fill(Rect r, Rgb c) {
    const int x0 = std::max(r.x0, clip_.x0);
    const int x1 = std::min(r.x1, clip_.x1);
    const int y0 = std::max(r.y0, clip_.y0);
    const int y1 = std::min(r.y1, clip_.y1);
    for (int y = y0; y < y1; ++y) {
      for (int x = x0; x < x1; ++x) put(x, y, c);
    }
  }

  // A segment between pixel positions (float, so far-off points clip exactly): Liang-Barsky
  // against the clip rectangle, then Bresenham.
  void line(float ax, float ay, float bx, float by, Rgb c) {
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

  void disc(float cx, float cy, float r, Rgb c) {
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

  // A circle outline as a polygon of short chords (at most 256 of them).
  void circle(float cx, float cy, float r, Rgb c) {
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

  void square(float cx, float cy, int half, Rgb c) {
    if (!std::isfinite(cx) || !std::isfinite(cy) || std::fabs(cx) > 1e6F || std::fabs(cy) > 1e6F) {
      return;
    }
    const int x = static_cast<int>(std::floor(cx));
    const int y = static_cast<int>(std::floor(cy));
    fill({x - half, y - half, x + half + 1, y + half + 1}, c);
  }

  void text(int x, int y, const char* s, Rgb c) {
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

 private:
  std::uint8_t* rgb_;
  int width_;
  int height_;
  Rect clip_{0, 0, 0, 0};
};

int text_width(const char* s) {
  const auto n = static_cast<int>(std::strlen(s));
  return n == 0 ? 0 : n * kGlyphAdvancePx - kTextScale;
}

// ---------------------------------------------------------------------------------------------
// World → panel pixels: one scale for both axes, the extent's longer side fills the panel.
struct PanelMap {
  int x0 = 0;  // plot area's top-left pixel
  int y0 = 0;
  float centre_x_m = 0.0F;
  float centre_y_m = 0.0F;
  float px_per_m = 1.0F;

  float u(float x_m) const {
    return static_cast<float>(x0) + 0.5F * SnapshotWriter::kPanelPx + (x_m - centre_x_m) * px_per_m;
  }
  float v(float y_m) const {
    return static_cast<float>(y0) + 0.5F * SnapshotWriter::kPanelPx - (y_m - centre_y_m) * px_per_m;
  }
  // World point at the centre of pixel (column i, row j) of the plot area.
  float x_at(float i) const {
    return centre_x_m + (i + 0.5F - 0.5F * SnapshotWriter::kPanelPx) / px_per_m;
  }
  float y_at(float j) const {
    return centre_y_m - (j + 0.5F - 0.5F * SnapshotWriter::kPanelPx) / px_per_m;
  }
  Rect plot() const {
    return {x0, y0, x0 + SnapshotWriter::kPanelPx, y0 + SnapshotWriter::kPanelPx};
  }
};

PanelMap panel_map(const SnapshotExtent& view, int panel) {
  PanelMap m;
  const int col = panel % 2;
  const int row = panel / 2;
  m.x0 = col * SnapshotWriter::kCellWidthPx + SnapshotWriter::kCellLeftPx;
  m.y0 =
      SnapshotWriter::kTitlePx + row * SnapshotWriter::kCellHeightPx + SnapshotWriter::kCellTopPx;
  float w = view.max_x_m - view.min_x_m;
  float h = view.max_y_m - view.min_y_m;
  if (!(w > 1e-3F) || !std::isfinite(w)) w = 1.0F;
  if (!(h > 1e-3F) || !std::isfinite(h)) h = 1.0F;
  m.centre_x_m = 0.5F * (view.min_x_m + view.max_x_m);
  m.centre_y_m = 0.5F * (view.min_y_m + view.max_y_m);
  if (!std::isfinite(m.centre_x_m)) m.centre_x_m = 0.0F;
  if (!std::isfinite(m.centre_y_m)) m.centre_y_m = 0.0F;
  m.px_per_m = static_cast<float>(SnapshotWriter::kPanelPx) / std::max(w, h);
  return m;
}

// Tick labels: a "nice" step so that at most 8 ticks span the panel.
float tick_step_m(float span_m) {
  constexpr std::array<float, 12> kSteps{0.05F, 0.1F, 0.2F, 0.25F, 0.5F,  1.0F,
                                         2.0F,  2.5F, 5.0F, 10.0F, 20.0F, 50.0F};
  for (float s : kSteps) {
    if (span_m / s <= 8.0F) return s;
  }
  return 100.0F;
}

void format_tick(char* out, std::size_t n, float value_m, float step_m) {
  if (std::fabs(value_m) < 1e-3F * step_m) value_m = 0.0F;
  const int decimals = step_m >= 1.0F ? 0 : (step_m >= 0.1F && step_m != 0.25F ? 1 : 2);
  std::snprintf(out, n, "%.*f", decimals, static_cast<double>(value_m));
}

void draw_axes(Canvas& c, const PanelMap& m) {
  c.clear_clip();
  const Rect p = m.plot();
  c.line(static_cast<float>(p.x0 - 1), static_cast<float>(p.y0 - 1), static_cast<float>(p.x1),
         static_cast<float>(p.y0 - 1), kFrameLine);
  c.line(static_cast<float>(p.x0 - 1), static_cast<float>(p.y1), static_cast<float>(p.x1),
         static_cast<float>(p.y1), kFrameLine);
  c.line(static_cast<float>(p.x0 - 1), static_cast<float>(p.y0 - 1), static_cast<float>(p.x0 - 1),
         static_cast<float>(p.y1), kFrameLine);
  c.line(static_cast<float>(p.x1), static_cast<float>(p.y0 - 1), static_cast<float>(p.x1),
         static_cast<float>(p.y1), kFrameLine);
  const float span_m = static_cast<float>(SnapshotWriter::kPanelPx) / m.px_per_m;
  const float step = tick_step_m(span_m);
  char label[16];
  const float x_lo = m.x_at(0.0F);
  for (float t = std::ceil(x_lo / step) * step; t <= m.x_at(SnapshotWriter::kPanelPx - 1.0F);
       t += step) {
    const auto u = static_cast<int>(std::floor(m.u(t)));
    c.line(static_cast<float>(u), static_cast<float>(p.y1), static_cast<float>(u),
           static_cast<float>(p.y1 + 4), kInk);
    format_tick(label, sizeof label, t, step);
    c.text(u - text_width(label) / 2, p.y1 + 6, label, kInk);
  }
  const float y_lo = m.y_at(SnapshotWriter::kPanelPx - 1.0F);
  for (float t = std::ceil(y_lo / step) * step; t <= m.y_at(0.0F); t += step) {
    const auto v = static_cast<int>(std::floor(m.v(t)));
    c.line(static_cast<float>(p.x0 - 5), static_cast<float>(v), static_cast<float>(p.x0 - 1),
           static_cast<float>(v), kInk);
    format_tick(label, sizeof label, t, step);
    c.text(p.x0 - 7 - text_width(label), v - kGlyphHeightPx / 2, label, kInk);
  }
}

// A legend line under the tick labels: swatches with words.
class Legend {
 public:
  Legend(Canvas& c, const PanelMap& m)
      : c_(c), x_(m.x0), y_(m.y0 + SnapshotWriter::kPanelPx + 24) {}
  void item(Rgb swatch, const char* words) {
    c_.clear_clip();
    c_.fill({x_, y_, x_ + 10, y_ + 10}, kFrameLine);
    c_.fill({x_ + 1, y_ + 1, x_ + 9, y_ + 9}, swatch);
    c_.text(x_ + 14, y_, words, kInk);
    x_ += 14 + text_width(words) + 12;
  }

 private:
  Canvas& c_;
  int x_;
  int y_;
};

void draw_polyline(Canvas& c, const PanelMap& m, std::span<const core::Point2> pts, bool closed,
                   Rgb colour) {
  if (pts.empty()) return;
  for (std::size_t i = 0; i + 1 < pts.size(); ++i) {
    c.line(m.u(pts[i].x_m), m.v(pts[i].y_m), m.u(pts[i + 1].x_m), m.v(pts[i + 1].y_m), colour);
  }
  if (closed && pts.size() > 2) {
    c.line(m.u(pts.back().x_m), m.v(pts.back().y_m), m.u(pts.front().x_m), m.v(pts.front().y_m),
           colour);
  }
}

// Even-odd scanline fill of a polygon inside the plot area, crossings kept in a fixed array (a
// row with more crossings than that is left partly unfilled, never overrun).
void fill_polygon(Canvas& c, const PanelMap& m, std::span<const core::Point2> pts, Rgb colour) {
  if (pts.size() < 3) return;
  constexpr std::size_t kMaxCrossings = 512;
  std::array<float, kMaxCrossings> xs{};
  const std::size_t n = pts.size();
  for (int j = 0; j < SnapshotWriter::kPanelPx; ++j) {
    const float y = m.y_at(static_cast<float>(j));
    std::size_t count = 0;
    for (std::size_t i = 0; i < n && count < kMaxCrossings; ++i) {
      const core::Point2 a = pts[i];
      const core::Point2 b = pts[(i + 1) % n];
      if ((a.y_m <= y) == (b.y_m <= y)) continue;
      const float t = (y - a.y_m) / (b.y_m - a.y_m);
      xs[count++] = m.u(a.x_m + t * (b.x_m - a.x_m));
    }
    std::sort(xs.begin(), xs.begin() + static_cast<std::ptrdiff_t>(count));
    const int row = m.y0 + j;
    for (std::size_t k = 0; k + 1 < count; k += 2) {
      const float lo = std::max(xs[k], static_cast<float>(m.x0));
      const float hi = std::min(xs[k + 1], static_cast<float>(m.x0 + SnapshotWriter::kPanelPx));
      if (!(lo < hi)) continue;
      const auto x0 = static_cast<int>(std::lround(lo));
      const auto x1 = static_cast<int>(std::lround(hi));
      c.fill({x0, row, x1, row + 1}, colour);
    }
  }
}

void draw_truth(Canvas& c, const PanelMap& m, const SnapshotFrame& f) {
  for (const auto& polygon : f.truth_polygons) draw_polyline(c, m, polygon, true, kTruth);
  for (const SnapshotCircle& circle : f.truth_circles) {
    c.circle(m.u(circle.centre.x_m), m.v(circle.centre.y_m), circle.radius_m * m.px_per_m, kTruth);
  }
}

void draw_robot_outline(Canvas& c, const PanelMap& m, const SnapshotFrame& f, Rgb colour) {
  const float u = m.u(f.robot.x_m);
  const float v = m.v(f.robot.y_m);
  const float r = std::max(3.0F, f.robot_radius_m * m.px_per_m);
  c.circle(u, v, r, colour);
  c.line(u, v, u + r * std::cos(f.robot.yaw_rad), v - r * std::sin(f.robot.yaw_rad), colour);
}

// Samples a field once per kFieldCellPx x kFieldCellPx block (at the block's centre).
// Field rows [j0, j1) of the panel's kFieldCells × kFieldCells samples.
void sample_field(const PanelMap& m, SnapshotField fn, const void* context, float* out, int j0,
                  int j1) {
  constexpr int kCell = SnapshotWriter::kFieldCellPx;
  for (int j = j0; j < j1; ++j) {
    const float y = m.y_at(static_cast<float>(j * kCell) + 0.5F * (kCell - 1));
    for (int i = 0; i < SnapshotWriter::kFieldCells; ++i) {
      const float x = m.x_at(static_cast<float>(i * kCell) + 0.5F * (kCell - 1));
      out[j * SnapshotWriter::kFieldCells + i] = fn(context, x, y);
    }
  }
}

Rgb grey(float level) {
  const auto g = static_cast<std::uint8_t>(std::lround(255.0F * std::clamp(level, 0.0F, 1.0F)));
  return {g, g, g};
}

// Blue → cyan → green → yellow → red for t in [0,1].
Rgb colour_map(float t) {
  t = std::clamp(t, 0.0F, 1.0F);
  constexpr std::array<Rgb, 5> kStops{Rgb{20, 20, 160}, Rgb{0, 180, 230}, Rgb{40, 190, 60},
                                      Rgb{240, 220, 0}, Rgb{220, 30, 20}};
  const float s = t * 4.0F;
  const auto k = std::min(3, static_cast<int>(s));
  const float w = s - static_cast<float>(k);
  const Rgb a = kStops[static_cast<std::size_t>(k)];
  const Rgb b = kStops[static_cast<std::size_t>(k) + 1U];
  auto mix = [w](std::uint8_t p, std::uint8_t q) {
    return static_cast<std::uint8_t>(
        std::lround(static_cast<float>(p) + w * (static_cast<float>(q) - static_cast<float>(p))));
  };
  return {mix(a.r, b.r), mix(a.g, b.g), mix(a.b, b.b)};
}

Rgb occupancy_colour(float o, float threshold) {
  if (!std::isfinite(o)) return kNoData;
  if (o < threshold) return grey(1.0F - o);  // free: white, darker as occupancy rises
  const float k = std::clamp((o - threshold) / std::max(1e-3F, 1.0F - threshold), 0.0F, 1.0F);
  return {static_cast<std::uint8_t>(std::lround(200.0F - 90.0F * k)), 30, 30};
}

void fill_field_cell(Canvas& c, const PanelMap& m, int i, int j, Rgb colour) {
  constexpr int kCell = SnapshotWriter::kFieldCellPx;
  c.fill({m.x0 + i * kCell, m.y0 + j * kCell, m.x0 + (i + 1) * kCell, m.y0 + (j + 1) * kCell},
         colour);
}

void panel_title(Canvas& c, const PanelMap& m, const char* title) {
  c.clear_clip();
  c.text(m.x0, m.y0 - SnapshotWriter::kCellTopPx + 3, title, kInk);
}

void draw_readings(Canvas& c, const PanelMap& m, const SnapshotFrame& f) {
  panel_title(c, m, "1 READINGS ON THE FLOOR");
  c.set_clip(m.plot());
  c.fill(m.plot(), kInk);
  draw_truth(c, m, f);
  for (const SnapshotReading& r : f.readings) {
    if (!std::isfinite(r.m)) continue;
    c.square(m.u(r.x_m), m.v(r.y_m), 1, grey(0.25F + 0.75F * r.m));
  }
  draw_robot_outline(c, m, f, kRobot);
  Legend legend(c, m);
  legend.item(grey(0.25F), "M=0");
  legend.item(grey(1.0F), "M=1");
  legend.item(kTruth, "TRUTH");
  legend.item(kRobot, "ROBOT");
}

// `field` holds the panel's samples of f.occupancy already (sample_field).
void draw_occupancy(Canvas& c, const PanelMap& m, const SnapshotFrame& f, const float* field) {
  constexpr int kN = SnapshotWriter::kFieldCells;
  panel_title(c, m, "2 OCCUPANCY, MAX OVER HEIGHTS");
  c.set_clip(m.plot());
  if (f.occupancy == nullptr) {
    c.fill(m.plot(), kNoData);
  } else {
    const float th = f.occupancy_threshold;
    for (int j = 0; j < kN; ++j) {
      for (int i = 0; i < kN; ++i) {
        fill_field_cell(c, m, i, j, occupancy_colour(field[j * kN + i], th));
      }
    }
    // The m_safe contour: block edges where the threshold is crossed.
    constexpr int kCell = SnapshotWriter::kFieldCellPx;
    for (int j = 0; j < kN; ++j) {
      for (int i = 0; i < kN; ++i) {
        const bool in = field[j * kN + i] >= th;
        if (i + 1 < kN && in != (field[j * kN + i + 1] >= th)) {
          const auto x = static_cast<float>(m.x0 + (i + 1) * kCell);
          c.line(x, static_cast<float>(m.y0 + j * kCell), x,
                 static_cast<float>(m.y0 + (j + 1) * kCell - 1), kContour);
        }
        if (j + 1 < kN && in != (field[(j + 1) * kN + i] >= th)) {
          const auto y = static_cast<float>(m.y0 + (j + 1) * kCell);
          c.line(static_cast<float>(m.x0 + i * kCell), y,
                 static_cast<float>(m.x0 + (i + 1) * kCell - 1), y, kContour);
        }
      }
    }
  }
  draw_truth(c, m, f);
  draw_robot_outline(c, m, f, kRobot);
  Legend legend(c, m);
  char words[32];
  legend.item(grey(1.0F), "0");
  legend.item(grey(0.5F), "0.5");
  std::snprintf(words, sizeof words, ">=%.2f", static_cast<double>(f.occupancy_threshold));
  legend.item(occupancy_colour(1.0F, f.occupancy_threshold), words);
  legend.item(kContour, "CONTOUR");
}

void draw_navigation(Canvas& c, const PanelMap& m, const SnapshotFrame& f) {
  panel_title(c, m, "3 NAVIGATION POLYGON");
  c.set_clip(m.plot());
  c.fill(m.plot(), Rgb{255, 255, 255});
  fill_polygon(c, m, f.free_polygon, kFreeFill);
  fill_polygon(c, m, f.navigable_polygon, kNavigableFill);
  draw_polyline(c, m, f.free_polygon, true, kFreeLine);
  draw_polyline(c, m, f.navigable_polygon, true, kNavigableLine);
  draw_truth(c, m, f);
  draw_polyline(c, m, f.path, false, kPath);
  for (const core::Point2& p : f.obstacle_points) c.square(m.u(p.x_m), m.v(p.y_m), 2, kObstacle);
  for (const core::Point2& p : f.exploration_points) {
    c.square(m.u(p.x_m), m.v(p.y_m), 2, kExploration);
  }
  if (f.goal) {
    const float u = m.u(f.goal->x_m);
    const float v = m.v(f.goal->y_m);
    c.disc(u, v, 5.0F, kGoal);
  }
  const float u = m.u(f.robot.x_m);
  const float v = m.v(f.robot.y_m);
  const float r = std::max(3.0F, f.robot_radius_m * m.px_per_m);
  c.disc(u, v, r, kRobot);
  c.line(u, v, u + r * std::cos(f.robot.yaw_rad), v - r * std::sin(f.robot.yaw_rad), kInk);
  Legend legend(c, m);
  legend.item(kFreeFill, "FREE");
  legend.item(kNavigableFill, "NAV");
  legend.item(kObstacle, "OBST");
  legend.item(kExploration, "EXPL");
  legend.item(kGoal, "GOAL");
  legend.item(kPath, "PATH");
}

// `field` holds the panel's samples of f.value already (sample_field).
void draw_value(Canvas& c, const PanelMap& m, const SnapshotFrame& f, const float* field) {
  constexpr int kN = SnapshotWriter::kFieldCells;
  panel_title(c, m, "4 VALUE FUNCTION V(X,Y)");
  c.set_clip(m.plot());
  float lo = 0.0F;
  float hi = 0.0F;
  if (f.value == nullptr) {
    c.fill(m.plot(), kNoData);
  } else {
    bool any = false;
    for (int k = 0; k < kN * kN; ++k) {
      if (!std::isfinite(field[k])) continue;
      lo = any ? std::min(lo, field[k]) : field[k];
      hi = any ? std::max(hi, field[k]) : field[k];
      any = true;
    }
    const float range = hi - lo;
    for (int j = 0; j < kN; ++j) {
      for (int i = 0; i < kN; ++i) {
        const float v = field[j * kN + i];
        const Rgb colour =
            !std::isfinite(v) ? kNoData : colour_map(range > 1e-12F ? (v - lo) / range : 0.5F);
        fill_field_cell(c, m, i, j, colour);
      }
    }
  }
  draw_truth(c, m, f);
  draw_robot_outline(c, m, f, kStep);
  if (f.step_end) {
    const float ax = m.u(f.robot.x_m);
    const float ay = m.v(f.robot.y_m);
    const float bx = m.u(f.step_end->x_m);
    const float by = m.v(f.step_end->y_m);
    c.line(ax, ay, bx, by, kStep);
    const float heading = std::atan2(by - ay, bx - ax);
    for (float side : {-1.0F, 1.0F}) {
      const float a = heading + side * 2.6F;  // ±150°
      c.line(bx, by, bx + 9.0F * std::cos(a), by + 9.0F * std::sin(a), kStep);
    }
  }
  Legend legend(c, m);
  char words[32];
  std::snprintf(words, sizeof words, "%.3g", static_cast<double>(lo));
  legend.item(colour_map(0.0F), words);
  std::snprintf(words, sizeof words, "%.3g", static_cast<double>(hi));
  legend.item(colour_map(1.0F), words);
  legend.item(kStep, "STEP");
}

#ifdef BOTICELLI_HAVE_PNG
const char* errno_text(int e) {
  const char* s = strerrordesc_np(e);  // a constant string: no locale, no buffer, no heap
  return s != nullptr ? s : "unknown error";
}

// libpng callbacks. The memory functions receive the png_struct being built (even the temporary
// one inside png_create_write_struct_2), whose mem_ptr is the writer.
png_voidp arena_malloc(png_structp png, png_alloc_size_t size) {
  return static_cast<SnapshotWriter*>(png_get_mem_ptr(png))->arena_allocate(size);
}
void arena_free(png_structp /*png*/, png_voidp /*p*/) {}  // bump arena: reset per image

[[noreturn]] void on_png_error(png_structp png, png_const_charp message) {
  auto* text = static_cast<char*>(png_get_error_ptr(png));
  std::snprintf(text, 128, "%s", message);
  png_longjmp(png, 1);
}
void on_png_warning(png_structp /*png*/, png_const_charp /*message*/) {}

void on_png_write(png_structp png, png_bytep data, size_t length) {
  if (!static_cast<SnapshotWriter*>(png_get_io_ptr(png))->append_output(data, length)) {
    png_error(png, "write failed");
  }
}
void on_png_flush(png_structp /*png*/) {}

// The parts that libpng may longjmp out of: nothing with a destructor lives between here and
// the callbacks above (libpng's frames are C), and no local changes after setjmp.
bool png_start(png_structp png, png_infop info, SnapshotWriter* writer) {
  if (setjmp(png_jmpbuf(png)) != 0) return false;
  png_set_write_fn(png, writer, on_png_write, on_png_flush);
  // Level 3 and the Up filter: flat colours and smooth colour maps compress well enough,
  // several times faster than the default level 6 with adaptive filters.
  png_set_compression_level(png, 3);
  png_set_filter(png, PNG_FILTER_TYPE_BASE, PNG_FILTER_UP);
  png_set_IHDR(png, info, SnapshotWriter::kWidthPx, SnapshotWriter::kHeightPx, 8,
               PNG_COLOR_TYPE_RGB, PNG_INTERLACE_NONE, PNG_COMPRESSION_TYPE_DEFAULT,
               PNG_FILTER_TYPE_DEFAULT);
  png_write_info(png, info);
  return true;
}

bool png_rows(png_structp png, const std::uint8_t* rgb, int first, int last) {
  if (setjmp(png_jmpbuf(png)) != 0) return false;
  constexpr std::size_t kRowBytes = static_cast<std::size_t>(SnapshotWriter::kWidthPx) * 3U;
  for (int y = first; y < last; ++y) {
    // libpng 1.6 takes png_const_bytep rows: the canvas is only read.
    png_write_row(png, rgb + static_cast<std::size_t>(y) * kRowBytes);
  }
  return true;
}

bool png_finish(png_structp png) {
  if (setjmp(png_jmpbuf(png)) != 0) return false;
  png_write_end(png, nullptr);
  return true;
}
#endif

}  // namespace

SnapshotPixel SnapshotWriter::pixel_of(const SnapshotExtent& view, int panel, core::Point2 p) {
  const PanelMap m = panel_map(view, panel);
  return {static_cast<int>(std::floor(m.u(p.x_m))), static_cast<int>(std::floor(m.v(p.y_m)))};
}

SnapshotWriter::~SnapshotWriter() {
  if (busy()) fail("abandoned");  // no half-written file left behind
  if (dir_fd_ >= 0) ::close(dir_fd_);
}

bool SnapshotWriter::open(const char* dir, char* error, std::size_t error_size) {
#ifndef BOTICELLI_HAVE_PNG
  (void)dir;
  std::snprintf(error, error_size, "snapshots need libpng (this build has none)");
  return false;
#else
  if (dir_fd_ >= 0) {
    ::close(dir_fd_);
    dir_fd_ = -1;
  }
  const std::size_t length = std::strlen(dir);
  if (length == 0 || length >= kDirMax) {
    std::snprintf(error, error_size, "snapshot directory name empty or longer than %zu",
                  kDirMax - 1);
    return false;
  }
  std::memcpy(dir_, dir, length + 1);
  // Create missing levels, parents first (mkdir -p).
  for (std::size_t i = 1; i <= length; ++i) {
    if (dir_[i] != '/' && dir_[i] != '\0') continue;
    const char saved = dir_[i];
    dir_[i] = '\0';
    if (::mkdir(dir_, 0755) != 0 && errno != EEXIST) {
      std::snprintf(error, error_size, "cannot create snapshot directory %s: %s", dir_,
                    errno_text(errno));
      dir_[i] = saved;
      return false;
    }
    dir_[i] = saved;
  }
  dir_fd_ = ::open(dir_, O_RDONLY | O_DIRECTORY | O_CLOEXEC);
  if (dir_fd_ < 0) {
    std::snprintf(error, error_size, "cannot open snapshot directory %s: %s", dir_,
                  errno_text(errno));
    return false;
  }
  // Writable? Try it (access() says yes to root on a read-only mount).
  constexpr const char* kProbe = ".snapshot-probe.tmp";
  const int probe = ::openat(dir_fd_, kProbe, O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);
  if (probe < 0) {
    std::snprintf(error, error_size, "snapshot directory %s is not writable: %s", dir_,
                  errno_text(errno));
    ::close(dir_fd_);
    dir_fd_ = -1;
    return false;
  }
  ::close(probe);
  ::unlinkat(dir_fd_, kProbe, 0);
  return true;
#endif
}

void* SnapshotWriter::arena_allocate(std::size_t bytes) {
  const std::size_t capacity =
      arena_limit_ != 0 && arena_limit_ < kArenaBytes ? arena_limit_ : kArenaBytes;
  const std::size_t start = (arena_used_ + 15U) & ~static_cast<std::size_t>(15U);
  if (bytes > capacity || start > capacity - bytes) {
    arena_exhausted_ = true;
    return nullptr;
  }
  arena_used_ = start + bytes;
  ++arena_calls_;
  return arena_ + start;
}

bool SnapshotWriter::flush_output() {
  std::size_t done = 0;
  while (done < out_used_) {
    const ssize_t n = ::write(out_fd_, output_ + done, out_used_ - done);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) {
      out_errno_ = n < 0 ? errno : EIO;
      return false;
    }
    done += static_cast<std::size_t>(n);
  }
  out_used_ = 0;
  return true;
}

bool SnapshotWriter::append_output(const std::uint8_t* data, std::size_t bytes) {
  while (bytes > 0) {
    if (out_used_ == kOutputBufferBytes && !flush_output()) return false;
    const std::size_t n = std::min(bytes, kOutputBufferBytes - out_used_);
    std::memcpy(output_ + out_used_, data, n);
    out_used_ += n;
    file_bytes_ += n;
    data += n;
    bytes -= n;
  }
  return true;
}

void SnapshotWriter::draw(Stage stage) {
  const SnapshotFrame& f = frame_;
  Canvas c(canvas_, kWidthPx, kHeightPx);
  c.clear_clip();
  switch (stage) {
    case Stage::kTitle: {
      c.fill({0, 0, kWidthPx, kHeightPx}, kPaper);
      char title[160];
      std::snprintf(title, sizeof title, "CYCLE %u  STATE %s  ROBOT X=%.2f Y=%.2f YAW=%.0f DEG",
                    static_cast<unsigned>(f.cycle), f.state != nullptr ? f.state : "?",
                    static_cast<double>(f.robot.x_m), static_cast<double>(f.robot.y_m),
                    static_cast<double>(f.robot.yaw_rad * 57.29578F));
      c.text(kCellLeftPx, 7, title, kInk);
      return;
    }
    case Stage::kReadings:
      draw_readings(c, panel_map(f.view, 0), f);
      return;
    case Stage::kOccupancyField:
      if (f.occupancy != nullptr) {
        sample_field(panel_map(f.view, 1), f.occupancy, f.occupancy_context, field_, field_row_,
                     std::min(kFieldCells, field_row_ + kFieldBandRows));
      }
      return;
    case Stage::kValueField:
      if (f.value != nullptr) {
        sample_field(panel_map(f.view, 3), f.value, f.value_context, field_, field_row_,
                     std::min(kFieldCells, field_row_ + kFieldBandRows));
      }
      return;
    case Stage::kOccupancy:
      draw_occupancy(c, panel_map(f.view, 1), f, field_);
      return;
    case Stage::kNavigation:
      draw_navigation(c, panel_map(f.view, 2), f);
      return;
    case Stage::kValue:
      draw_value(c, panel_map(f.view, 3), f, field_);
      return;
    case Stage::kAxes:
      for (int k = 0; k < 4; ++k) draw_axes(c, panel_map(f.view, k));
      return;
    default:
      return;
  }
}

void SnapshotWriter::fail(const char* format, ...) {
  va_list args;
  va_start(args, format);
  std::vsnprintf(error_, sizeof error_, format, args);
  va_end(args);
  release_png();
  if (tmp_fd_ >= 0) {
    ::close(tmp_fd_);
    tmp_fd_ = -1;
    ::unlinkat(dir_fd_, tmp_name_, 0);
  }
  ok_ = false;
  stage_ = Stage::kIdle;
}

void SnapshotWriter::begin(const SnapshotFrame& frame) {
  if (busy()) fail("abandoned");
  frame_ = frame;
  ok_ = false;
  error_[0] = '\0';
  field_row_ = 0;
  stage_ = Stage::kTitle;
#ifndef BOTICELLI_HAVE_PNG
  fail("snapshots need libpng (this build has none)");
#else
  if (dir_fd_ < 0) fail("snapshot writer not opened");
#endif
}

bool SnapshotWriter::step() {
  switch (stage_) {
    case Stage::kIdle:
      return true;
    case Stage::kOccupancyField:
    case Stage::kValueField:
      // The sampled fields (the model, the value function) a band of rows at a time.
      draw(stage_);
      field_row_ += kFieldBandRows;
      if (field_row_ >= kFieldCells) {
        field_row_ = 0;
        stage_ = static_cast<Stage>(static_cast<std::uint8_t>(stage_) + 1);
      }
      return false;
    case Stage::kTitle:
    case Stage::kReadings:
    case Stage::kOccupancy:
    case Stage::kNavigation:
    case Stage::kValue:
    case Stage::kAxes:
      draw(stage_);
      stage_ = static_cast<Stage>(static_cast<std::uint8_t>(stage_) + 1);
      return false;
    case Stage::kOpen:
      if (open_file()) stage_ = Stage::kRows;
      return stage_ == Stage::kIdle;
    case Stage::kRows: {
#ifdef BOTICELLI_HAVE_PNG
      const int last = std::min(kHeightPx, next_row_ + kBandRows);
      if (!png_rows(static_cast<png_structp>(png_), canvas_, next_row_, last)) {
        encode_error();
        return true;
      }
      next_row_ = last;
      if (next_row_ == kHeightPx) stage_ = Stage::kFinish;
#endif
      return false;
    }
    case Stage::kFinish:
      if (finish_file()) {
        ok_ = true;
        stage_ = Stage::kIdle;
      }
      return true;
  }
  return true;
}

bool SnapshotWriter::write(const SnapshotFrame& frame, char* error, std::size_t error_size) {
  begin(frame);
  while (!step()) {
  }
  if (!ok_) std::snprintf(error, error_size, "%s", error_);
  return ok_;
}

#ifdef BOTICELLI_HAVE_PNG
bool SnapshotWriter::open_file() {
  std::snprintf(name_, sizeof name_, "cycle-%06u.png", static_cast<unsigned>(frame_.cycle));
  std::snprintf(tmp_name_, sizeof tmp_name_, "%s.tmp", name_);
  tmp_fd_ = ::openat(dir_fd_, tmp_name_, O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);
  if (tmp_fd_ < 0) {
    const int e = errno;
    fail("cannot create %s/%s: %s", dir_, tmp_name_, errno_text(e));
    return false;
  }
  arena_used_ = 0;
  arena_calls_ = 0;
  arena_exhausted_ = false;
  out_fd_ = tmp_fd_;
  out_used_ = 0;
  out_errno_ = 0;
  file_bytes_ = 0;
  png_message_[0] = '\0';
  next_row_ = 0;
  png_structp png = png_create_write_struct_2(PNG_LIBPNG_VER_STRING, png_message_, on_png_error,
                                              on_png_warning, this, arena_malloc, arena_free);
  png_infop info = png != nullptr ? png_create_info_struct(png) : nullptr;
  png_ = png;
  info_ = info;
  if (png == nullptr || info == nullptr || !png_start(png, info, this)) {
    encode_error();
    return false;
  }
  return true;
}

bool SnapshotWriter::finish_file() {
  if (!png_finish(static_cast<png_structp>(png_))) {
    encode_error();
    return false;
  }
  if (!flush_output()) {
    std::snprintf(png_message_, sizeof png_message_, "write failed");
    encode_error();
    return false;
  }
  release_png();
  if (::fsync(tmp_fd_) != 0) {
    const int e = errno;
    fail("cannot sync %s/%s: %s", dir_, tmp_name_, errno_text(e));
    return false;
  }
  const int fd = tmp_fd_;
  tmp_fd_ = -1;
  if (::close(fd) != 0) {
    const int e = errno;
    ::unlinkat(dir_fd_, tmp_name_, 0);
    fail("cannot close %s/%s: %s", dir_, tmp_name_, errno_text(e));
    return false;
  }
  if (::renameat(dir_fd_, tmp_name_, dir_fd_, name_) != 0) {
    const int e = errno;
    ::unlinkat(dir_fd_, tmp_name_, 0);
    fail("cannot rename %s/%s: %s", dir_, tmp_name_, errno_text(e));
    return false;
  }
  ::fsync(dir_fd_);  // the rename itself survives a power cut
  file_bytes_last_ = file_bytes_;
  return true;
}

void SnapshotWriter::release_png() {
  if (png_ == nullptr && info_ == nullptr) return;
  auto* png = static_cast<png_structp>(png_);
  auto* info = static_cast<png_infop>(info_);
  png_destroy_write_struct(png != nullptr ? &png : nullptr, info != nullptr ? &info : nullptr);
  png_ = nullptr;
  info_ = nullptr;
  arena_used_last_ = arena_used_;
  arena_calls_last_ = arena_calls_;
  arena_peak_ = std::max(arena_peak_, arena_used_);
  out_fd_ = -1;
}

// The encoder stopped: say why (arena, file or libpng) and leave nothing behind.
void SnapshotWriter::encode_error() {
  if (arena_exhausted_) {
    fail("snapshot arena of %zu bytes exhausted (libpng: %s)",
         arena_limit_ != 0 && arena_limit_ < kArenaBytes ? arena_limit_ : kArenaBytes,
         png_message_[0] != '\0' ? png_message_ : "out of memory");
  } else if (out_errno_ != 0) {
    fail("cannot write snapshot to %s: %s", dir_, errno_text(out_errno_));
  } else {
    fail("PNG encoding failed: %s",
         png_message_[0] != '\0' ? png_message_ : "libpng could not start");
  }
}
#else
bool SnapshotWriter::open_file() {
  fail("snapshots need libpng (this build has none)");
  return false;
}
bool SnapshotWriter::finish_file() {
  return false;
}
void SnapshotWriter::release_png() {}
void SnapshotWriter::encode_error() {}
#endif

}  // namespace boticelli::firmware
