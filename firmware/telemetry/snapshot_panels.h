// Snapshot panels: the world-to-panel mapping, axes and the four panels (readings, occupancy,
// navigation, value) drawn on the canvas.
#pragma once

#include "firmware/telemetry/snapshot.h"
#include "snapshot_canvas.h"

namespace boticelli::firmware::snapshot_detail {

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

// The map of panel 0..3 (left to right, top to bottom) for the view.
PanelMap panel_map(const SnapshotExtent& view, int panel);

// The frame around the plot area, ticks and tick labels.
void draw_axes(Canvas& c, const PanelMap& m);

// Samples a field once per kFieldCellPx x kFieldCellPx block (at the block's centre).
// Field rows [j0, j1) of the panel's kFieldCells × kFieldCells samples.
void sample_field(const PanelMap& m, SnapshotField fn, const void* context, float* out, int j0,
                  int j1);

// The four panels: title, plot area and legend (not the axes), each in one or more parts
// (a part is one of the SnapshotWriter's units of work).
// Readings [first, end) of f.readings; the first part (first == 0) draws the title, the plot
// and the truth under them, the last (end == f.readings.size()) the robot and the legend.
void draw_readings(Canvas& c, const PanelMap& m, const SnapshotFrame& f, std::size_t first,
                   std::size_t end);
// `field` holds the panel's samples of f.occupancy already (sample_field).
void draw_occupancy(Canvas& c, const PanelMap& m, const SnapshotFrame& f, const float* field);
// Part 0: the plot and the world memory's cells (`grid_field`: f.grid sampled already); part
// 1: the free polygon's fill; part 2: the title and everything drawn over the fill.
void draw_navigation(Canvas& c, const PanelMap& m, const SnapshotFrame& f, int part,
                     const float* grid_field);
// `field` holds the panel's samples of f.value already (sample_field).
void draw_value(Canvas& c, const PanelMap& m, const SnapshotFrame& f, const float* field);

}  // namespace boticelli::firmware::snapshot_detail
