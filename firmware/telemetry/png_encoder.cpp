// Snapshot PNG encoding with libpng: the callbacks and the start, rows and finish steps
// (png_encoder.h). Empty in a build without libpng.
#include "png_encoder.h"

#ifdef BOTICELLI_HAVE_PNG
#include <cstddef>
#include <cstdio>

namespace boticelli::firmware::snapshot_detail {
namespace {

void on_png_write(png_structp png, png_bytep data, size_t length) {
  if (!static_cast<SnapshotWriter*>(png_get_io_ptr(png))->append_output(data, length)) {
    png_error(png, "write failed");
  }
}
void on_png_flush(png_structp /*png*/) {}

}  // namespace

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

}  // namespace boticelli::firmware::snapshot_detail
#endif
