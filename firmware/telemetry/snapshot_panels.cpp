// Snapshot panels: axes, legend, polygon fill, field colours and the four panel drawers
// (snapshot_panels.h).
#include "snapshot_panels.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <span>

namespace boticelli::firmware::snapshot_detail {
namespace {

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

}  // namespace

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

void draw_readings(Canvas& c, const PanelMap& m, const SnapshotFrame& f, std::size_t first,
                   std::size_t end) {
  if (first == 0) {
    panel_title(c, m, "1 READINGS ON THE FLOOR");
    c.set_clip(m.plot());
    c.fill(m.plot(), kInk);
    draw_truth(c, m, f);
  }
  c.set_clip(m.plot());
  for (const SnapshotReading& r : f.readings.subspan(first, end - first)) {
    if (!std::isfinite(r.m)) continue;
    c.square(m.u(r.x_m), m.v(r.y_m), 1, grey(0.25F + 0.75F * r.m));
  }
  if (end < f.readings.size()) return;
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

void draw_navigation(Canvas& c, const PanelMap& m, const SnapshotFrame& f, int part,
                     const float* grid_field) {
  constexpr int kN = SnapshotWriter::kFieldCells;
  if (part == 0) {
    // The world memory under everything: free cells pale, occupied ones dark, unknown white.
    c.set_clip(m.plot());
    c.fill(m.plot(), Rgb{255, 255, 255});
    if (f.grid != nullptr) {
      for (int j = 0; j < kN; ++j) {
        for (int i = 0; i < kN; ++i) {
          const float g = grid_field[j * kN + i];
          if (g == kGridFree) fill_field_cell(c, m, i, j, kGridFreeFill);
          if (g == kGridOccupied) fill_field_cell(c, m, i, j, kGridOccupiedFill);
        }
      }
    }
    return;
  }
  if (part == 1) {
    c.set_clip(m.plot());
    fill_polygon(c, m, f.free_polygon, kFreeFill);
    return;
  }
  panel_title(c, m, "3 NAVIGATION POLYGON");
  c.set_clip(m.plot());
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
  if (f.grid_goal) {
    const float u = m.u(f.grid_goal->x_m);
    const float v = m.v(f.grid_goal->y_m);
    c.line(u - 6.0F, v - 6.0F, u + 6.0F, v + 6.0F, kGridGoal);
    c.line(u - 6.0F, v + 6.0F, u + 6.0F, v - 6.0F, kGridGoal);
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
  if (f.grid != nullptr) legend.item(kGridOccupiedFill, "MAP");
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

}  // namespace boticelli::firmware::snapshot_detail
