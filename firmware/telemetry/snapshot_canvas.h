// Snapshot drawing: RGB colours, a clipping canvas with lines, discs, squares and 3x5-font text.
#pragma once

#include <cstdint>

namespace boticelli::firmware::snapshot_detail {

// Colours (RGB). Tests read some of them back from the file.
struct Rgb {
  std::uint8_t r, g, b;
};
inline constexpr Rgb kPaper{235, 235, 235};  // around the panels
inline constexpr Rgb kInk{0, 0, 0};          // text, ticks
inline constexpr Rgb kFrameLine{90, 90, 90};
inline constexpr Rgb kTruth{255, 0, 255};  // true walls and colliders, 1 px
inline constexpr Rgb kRobot{255, 140, 0};
inline constexpr Rgb kObstacle{220, 0, 0};
inline constexpr Rgb kExploration{0, 90, 255};
inline constexpr Rgb kGoal{0, 200, 200};
inline constexpr Rgb kFreeFill{225, 240, 225};
inline constexpr Rgb kFreeLine{60, 140, 60};
inline constexpr Rgb kNavigableFill{170, 220, 170};
inline constexpr Rgb kNavigableLine{0, 100, 0};
inline constexpr Rgb kPath{60, 60, 60};
inline constexpr Rgb kContour{255, 220, 0};
inline constexpr Rgb kStep{255, 255, 255};
inline constexpr Rgb kNoData{128, 128, 128};
inline constexpr Rgb kGridFreeFill{232, 232, 232};   // the world memory's free cells
inline constexpr Rgb kGridOccupiedFill{70, 70, 70};  // ... and its occupied ones
inline constexpr Rgb kGridGoal{150, 0, 200};         // the last plan's goal on the grid

// The 3x5 bitmap font (snapshot_canvas.cpp) drawn at kTextScale.
inline constexpr int kTextScale = 2;                    // each font pixel is 2x2 picture pixels
inline constexpr int kGlyphAdvancePx = 4 * kTextScale;  // 3 columns + 1 space
inline constexpr int kGlyphHeightPx = 5 * kTextScale;

// Width of `s` in pixels as Canvas::text draws it.
int text_width(const char* s);

// Drawing on the canvas. Every primitive clips to a rectangle, so no world coordinate can write
// outside the canvas or loop for long.
struct Rect {
  int x0, y0, x1, y1;  // half-open: [x0, x1) x [y0, y1)
};

class Canvas {
 public:
  // `writes`, when given, counts every pixel written (the work a drawing step did).
  Canvas(std::uint8_t* rgb, int width, int height, std::uint64_t* writes = nullptr)
      : rgb_(rgb), width_(width), height_(height), writes_(writes) {}

  void set_clip(Rect r) { clip_ = r; }
  void clear_clip() { clip_ = {0, 0, width_, height_}; }

  void put(int x, int y, Rgb c);
  void fill(Rect r, Rgb c);
  // A segment between pixel positions (float, so far-off points clip exactly): Liang-Barsky
  // against the clip rectangle, then Bresenham.
  void line(float ax, float ay, float bx, float by, Rgb c);
  void disc(float cx, float cy, float r, Rgb c);
  // A circle outline as a polygon of short chords (at most 256 of them).
  void circle(float cx, float cy, float r, Rgb c);
  void square(float cx, float cy, int half, Rgb c);
  // Text in the 3x5 font; lower case prints as upper case, other characters as '?'.
  void text(int x, int y, const char* s, Rgb c);

 private:
  std::uint8_t* rgb_;
  int width_;
  int height_;
  std::uint64_t* writes_;
  Rect clip_{0, 0, 0, 0};
};

}  // namespace boticelli::firmware::snapshot_detail
