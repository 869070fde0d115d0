// Snapshots: the SnapshotWriter (snapshot.h) steps through drawing the panels into its fixed
// canvas and encoding it into DIR/cycle-NNNNNN.png.
#include "firmware/telemetry/snapshot.h"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstdarg>
#include <cmath>
#include <cstdio>
#include <cstring>

#include "png_encoder.h"
#include "snapshot_canvas.h"
#include "snapshot_panels.h"

namespace boticelli::firmware {

using snapshot_detail::Canvas;
using snapshot_detail::draw_axes;
using snapshot_detail::draw_navigation;
using snapshot_detail::draw_occupancy;
using snapshot_detail::draw_readings;
using snapshot_detail::draw_value;
using snapshot_detail::kInk;
using snapshot_detail::kPaper;
using snapshot_detail::panel_map;
using snapshot_detail::PanelMap;
using snapshot_detail::sample_field;

#ifdef BOTICELLI_HAVE_PNG
using snapshot_detail::arena_free;
using snapshot_detail::arena_malloc;
using snapshot_detail::on_png_error;
using snapshot_detail::on_png_warning;
using snapshot_detail::png_finish;
using snapshot_detail::png_rows;
using snapshot_detail::png_start;

namespace {

const char* errno_text(int e) {
  const char* s = strerrordesc_np(e);  // a constant string: no locale, no buffer, no heap
  return s != nullptr ? s : "unknown error";
}

}  // namespace
#endif

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
  Canvas c(canvas_, kWidthPx, kHeightPx, &unit_work_.pixels_written);
  c.clear_clip();
  switch (stage) {
    case Stage::kClear:
      // The paper a band of rows at a time: the whole canvas at once was the longest unit
      // (9 ms of CPU on the development host, near a whole 10 ms frame).
      c.fill({0, clear_row_, kWidthPx, std::min(kHeightPx, clear_row_ + kBandRows)}, kPaper);
      return;
    case Stage::kTitle: {
      char title[160];
      std::snprintf(title, sizeof title, "CYCLE %u  STATE %s  ROBOT X=%.2f Y=%.2f YAW=%.0f DEG",
                    static_cast<unsigned>(f.cycle), f.state != nullptr ? f.state : "?",
                    static_cast<double>(f.robot.x_m), static_cast<double>(f.robot.y_m),
                    static_cast<double>(f.robot.yaw_rad * 57.29578F));
      c.text(kCellLeftPx, 7, title, kInk);
      return;
    }
    case Stage::kReadings:
      draw_readings(c, panel_map(f.view, 0), f, next_reading_,
                    std::min(f.readings.size(), next_reading_ + kReadingsPerUnit));
      return;
    case Stage::kOccupancyField:
      if (f.occupancy != nullptr) {
        const int end = std::min(kFieldCells, field_row_ + kFieldBandRows);
        sample_field(panel_map(f.view, 1), f.occupancy, f.occupancy_context, field_, field_row_,
                     end);
        unit_work_.field_rows = end - field_row_;
      }
      return;
    case Stage::kGridField:
      if (f.grid != nullptr) {
        const int end = std::min(kFieldCells, field_row_ + kFieldBandRows);
        sample_field(panel_map(f.view, 2), f.grid, f.grid_context, field_, field_row_, end);
        unit_work_.field_rows = end - field_row_;
      }
      return;
    case Stage::kValueField:
      if (f.value != nullptr) {
        const int end = std::min(kFieldCells, field_row_ + kFieldBandRows);
        sample_field(panel_map(f.view, 3), f.value, f.value_context, field_, field_row_, end);
        unit_work_.field_rows = end - field_row_;
      }
      return;
    case Stage::kOccupancy:
      draw_occupancy(c, panel_map(f.view, 1), f, field_);
      return;
    case Stage::kNavigation:
      draw_navigation(c, panel_map(f.view, 2), f, 0, field_);
      return;
    case Stage::kNavigationFree:
      draw_navigation(c, panel_map(f.view, 2), f, 1, field_);
      return;
    case Stage::kNavigationMarks:
      draw_navigation(c, panel_map(f.view, 2), f, 2, field_);
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
  clear_row_ = 0;
  next_reading_ = 0;
  stage_ = Stage::kClear;
#ifndef BOTICELLI_HAVE_PNG
  fail("snapshots need libpng (this build has none)");
#else
  if (dir_fd_ < 0) fail("snapshot writer not opened");
#endif
}

bool SnapshotWriter::run_unit() {
  unit_work_ = UnitWork{};
  switch (stage_) {
    case Stage::kIdle:
      return true;
    case Stage::kClear:
      draw(stage_);
      clear_row_ += kBandRows;
      if (clear_row_ >= kHeightPx) stage_ = Stage::kTitle;
      return false;
    case Stage::kOccupancyField:
    case Stage::kGridField:
    case Stage::kValueField:
      // The sampled fields (the model, the grid, the value function) a band of rows at a time.
      draw(stage_);
      field_row_ += kFieldBandRows;
      if (field_row_ >= kFieldCells) {
        field_row_ = 0;
        stage_ = static_cast<Stage>(static_cast<std::uint8_t>(stage_) + 1);
      }
      return false;
    case Stage::kReadings:
      // The readings a chunk at a time (a look can hold tens of thousands).
      draw(stage_);
      next_reading_ = std::min(frame_.readings.size(), next_reading_ + kReadingsPerUnit);
      if (next_reading_ == frame_.readings.size()) stage_ = Stage::kOccupancyField;
      return false;
    case Stage::kTitle:
    case Stage::kOccupancy:
    case Stage::kNavigation:
    case Stage::kNavigationFree:
    case Stage::kNavigationMarks:
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
      unit_work_.rows_encoded = last - next_row_;
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
  while (!run_unit()) {
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
