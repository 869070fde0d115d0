// Snapshots (--snapshots DIR): one PNG per Look-Think-Drive cycle, four top-view panels like the
// thesis's GUI (Fig 6.2, 6.5), rendered and encoded without the heap.
#pragma once

#include <cstddef>
#include <cstdint>
#include <optional>
#include <span>

#include "algo/core/geometry.h"

namespace boticelli::firmware {

// A range reading projected on the floor, world frame [m], with its evidence m in [0,1] (Eq 3.8).
struct SnapshotReading {
  float x_m = 0.0F;
  float y_m = 0.0F;
  float m = 0.0F;
};

// A circle on the floor, world frame [m] (a cylinder collider seen from above).
struct SnapshotCircle {
  core::Point2 centre{};
  float radius_m = 0.0F;
};

// The world rectangle every panel shows [m]; the longer side fills the panel, the shorter is
// centred (same scale on both axes).
struct SnapshotExtent {
  float min_x_m = -2.0F;
  float min_y_m = -2.0F;
  float max_x_m = 2.0F;
  float max_y_m = 2.0F;
};

// A scalar field on the floor, world frame [m] in, value out; `context` is passed back as given.
using SnapshotField = float (*)(const void* context, float x_m, float y_m);
// What SnapshotFrame::grid returns for a cell.
inline constexpr float kGridUnknown = 0.0F;
inline constexpr float kGridFree = 1.0F;
inline constexpr float kGridOccupied = 2.0F;

// Everything one picture shows. Plain data: the spans and the state name are only read during
// write(), nothing is kept. Polygons are world-frame vertex lists, closed implicitly.
struct SnapshotFrame {
  std::uint32_t cycle = 0;
  const char* state = "";  // mission state name, for the title
  core::Pose2 robot{};
  float robot_radius_m = 0.2F;
  SnapshotExtent view{};

  // Panel 1: readings on the floor, brightness = m.
  std::span<const SnapshotReading> readings{};
  // Panel 2: occupancy at a floor point, already the max over the slice heights, in [0,1].
  SnapshotField occupancy = nullptr;
  const void* occupancy_context = nullptr;
  float occupancy_threshold = 0.6F;  // m_safe: the contour drawn (thesis §5.2)
  // Panel 3: navigation (free) polygon, navigable (shrunk by the robot radius) polygon, points.
  std::span<const core::Point2> free_polygon{};
  std::span<const core::Point2> navigable_polygon{};
  std::span<const core::Point2> obstacle_points{};
  std::span<const core::Point2> exploration_points{};
  std::optional<core::Point2> goal{};
  std::span<const core::Point2> path{};  // the robot's path so far
  // Under it, the world memory: a cell's state at a floor point (kGridUnknown, kGridFree,
  // kGridOccupied), and the last plan's goal on it (a frontier or the target's stand-off).
  SnapshotField grid = nullptr;
  const void* grid_context = nullptr;
  std::optional<core::Point2> grid_goal{};
  // Panel 4: the value function V(x, y) (§5.5) and the chosen step's end.
  SnapshotField value = nullptr;
  const void* value_context = nullptr;
  std::optional<core::Point2> step_end{};

  // Ground truth (sim board only): walls and boxes as polygons, cylinders as circles; drawn
  // thinly in every panel.
  std::span<const std::span<const core::Point2>> truth_polygons{};
  std::span<const SnapshotCircle> truth_circles{};
};

// Where a world point lands in the picture (pixel column, row from the top-left).
struct SnapshotPixel {
  int x = 0;
  int y = 0;
};

// Renders SnapshotFrames into a fixed RGB canvas and writes them as DIR/cycle-NNNNNN.png. All
// storage is inside the object (about 3.1 MB: give it static storage); libpng and zlib allocate
// from a fixed arena inside it, reset per image. After open(), write() makes no heap allocation.
class SnapshotWriter {
 public:
  static constexpr int kPanelPx = 400;  // plot area of one panel, square
  static constexpr int kCellLeftPx = 52;
  static constexpr int kCellRightPx = 12;
  static constexpr int kCellTopPx = 16;
  static constexpr int kCellBottomPx = 44;
  static constexpr int kTitlePx = 24;
  static constexpr int kCellWidthPx = kCellLeftPx + kPanelPx + kCellRightPx;
  static constexpr int kCellHeightPx = kCellTopPx + kPanelPx + kCellBottomPx;
  static constexpr int kWidthPx = 2 * kCellWidthPx;
  static constexpr int kHeightPx = kTitlePx + 2 * kCellHeightPx;
  static constexpr int kFieldCellPx = 4;  // occupancy and V are sampled once per 4x4 pixels
  static constexpr int kFieldCells = kPanelPx / kFieldCellPx;
  // libpng 1.6.39 + zlib 1.2.13 (level 3, 32 KB window, memLevel 8) take 286,336 bytes in 11
  // calls for this canvas, zlib's deflate state being most of it (measured; the same every
  // image, since libpng frees nothing that is not reused): 512 KB leaves a margin of 1.8x.
  static constexpr std::size_t kArenaBytes = std::size_t{512} * 1024;
  static constexpr std::size_t kOutputBufferBytes = std::size_t{64} * 1024;
  static constexpr std::size_t kDirMax = 256;

  SnapshotWriter() = default;
  ~SnapshotWriter();
  SnapshotWriter(const SnapshotWriter&) = delete;
  SnapshotWriter& operator=(const SnapshotWriter&) = delete;

  // Uses `dir`, creating it (and missing parents) when absent, and proves it writable by creating
  // and removing a probe file. False with a reason in `error` otherwise ("snapshots need libpng"
  // in a build without it).
  bool open(const char* dir, char* error, std::size_t error_size);
  // Renders `frame` and writes DIR/cycle-NNNNNN.png atomically (a .tmp file, fsync, rename,
  // fsync of the directory). On failure nothing is left behind and `error` says why.
  bool write(const SnapshotFrame& frame, char* error, std::size_t error_size);

  // The same in bounded steps, for a background slice: begin() takes the frame (its spans and
  // the fields' contexts must stay valid and unchanged until the picture is done), then each
  // run_unit() clears kBandRows rows of the canvas, draws the title or one panel, samples
  // kFieldBandRows rows of a field or encodes kBandRows rows; it returns true when the
  // picture is written or has failed (ok(), error()). A begin() while busy abandons the
  // picture before.
  static constexpr int kBandRows = 96;
  static constexpr int kFieldBandRows = 10;              // field rows sampled per step
  static constexpr std::size_t kReadingsPerUnit = 8192;  // readings drawn per step
  void begin(const SnapshotFrame& frame);
  bool run_unit();
  // The work of the last run_unit(), counted (not timed): every unit stays within its share
  // (kMaxUnitPixels pixels written, kBandRows rows encoded, kFieldBandRows field rows), so
  // none is much longer than another on any host: at most two panels' area (a panel's plot
  // and a fill or marks over it) of the canvas's 920,576 pixels.
  struct UnitWork {
    std::uint64_t pixels_written = 0;
    int rows_encoded = 0;
    int field_rows = 0;
  };
  static constexpr std::uint64_t kMaxUnitPixels = std::uint64_t{2} * kPanelPx * kPanelPx;
  [[nodiscard]] const UnitWork& last_unit_work() const { return unit_work_; }
  [[nodiscard]] bool busy() const { return stage_ != Stage::kIdle; }
  [[nodiscard]] bool ok() const { return ok_; }
  [[nodiscard]] const char* error() const { return error_; }

  // Arena use of the last write [bytes, calls] and the most any write needed [bytes].
  std::size_t arena_bytes_last() const { return arena_used_last_; }
  std::size_t arena_allocations_last() const { return arena_calls_last_; }
  std::size_t arena_bytes_peak() const { return arena_peak_; }
  // Size of the last file written [bytes].
  std::size_t file_bytes_last() const { return file_bytes_last_; }
  // Caps the arena below kArenaBytes (0 restores it); tests force the out-of-memory path with it.
  void limit_arena(std::size_t bytes) { arena_limit_ = bytes; }

  // The rendered picture of the last write(), RGB rows top to bottom.
  const std::uint8_t* pixels() const { return canvas_; }

  // Pixel of world point `p` in panel 0..3 (1 readings, 2 occupancy, 3 navigation, 4 value,
  // numbered left to right, top to bottom) for the view `view`.
  static SnapshotPixel pixel_of(const SnapshotExtent& view, int panel, core::Point2 p);

  // For the libpng callbacks in png_encoder.cpp.
  void* arena_allocate(std::size_t bytes);
  bool flush_output();
  bool append_output(const std::uint8_t* data, std::size_t bytes);

 private:
  enum class Stage : std::uint8_t {
    kIdle,
    kClear,
    kTitle,
    kReadings,
    kOccupancyField,
    kOccupancy,
    kGridField,
    kNavigation,
    kNavigationFree,
    kNavigationMarks,
    kValueField,
    kValue,
    kAxes,
    kOpen,
    kRows,
    kFinish
  };
  void draw(Stage stage);
  bool open_file();
  bool finish_file();
  void fail(const char* format, ...) __attribute__((format(printf, 2, 3)));
  void release_png();
  void encode_error();

  SnapshotFrame frame_{};
  Stage stage_ = Stage::kIdle;
  bool ok_ = false;
  char error_[200] = {};
  int tmp_fd_ = -1;
  char name_[48] = {};
  char tmp_name_[56] = {};
  int next_row_ = 0;
  int field_row_ = 0;
  int clear_row_ = 0;
  std::size_t next_reading_ = 0;
  UnitWork unit_work_{};
  void* png_ = nullptr;   // png_structp while encoding
  void* info_ = nullptr;  // png_infop

  int dir_fd_ = -1;
  char dir_[kDirMax] = {};
  int out_fd_ = -1;
  int out_errno_ = 0;
  std::size_t out_used_ = 0;
  std::size_t file_bytes_ = 0;
  std::size_t file_bytes_last_ = 0;
  std::size_t arena_used_ = 0;
  std::size_t arena_calls_ = 0;
  std::size_t arena_limit_ = 0;
  bool arena_exhausted_ = false;
  std::size_t arena_used_last_ = 0;
  std::size_t arena_calls_last_ = 0;
  std::size_t arena_peak_ = 0;
  char png_message_[128] = {};

  float field_[kFieldCells * kFieldCells] = {};
  alignas(16) std::uint8_t arena_[kArenaBytes] = {};
  std::uint8_t output_[kOutputBufferBytes] = {};
  std::uint8_t canvas_[static_cast<std::size_t>(kWidthPx) * kHeightPx * 3] = {};
};

}  // namespace boticelli::firmware
