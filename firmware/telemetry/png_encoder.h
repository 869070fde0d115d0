// Snapshot PNG encoding with libpng: arena allocation and error callbacks, and the setjmp-guarded
// start, rows and finish steps the SnapshotWriter calls. Empty in a build without libpng.
#pragma once

#ifdef BOTICELLI_HAVE_PNG
#include <png.h>

#include <cstdint>

#include "firmware/telemetry/snapshot.h"

namespace boticelli::firmware::snapshot_detail {

// libpng callbacks for png_create_write_struct_2: memory from the writer's arena (mem_ptr is the
// SnapshotWriter), errors into a 128-byte message buffer (error_ptr) and a longjmp.
png_voidp arena_malloc(png_structp png, png_alloc_size_t size);
void arena_free(png_structp png, png_voidp p);
[[noreturn]] void on_png_error(png_structp png, png_const_charp message);
void on_png_warning(png_structp png, png_const_charp message);

// The steps libpng may longjmp out of; false when libpng failed (its message is in error_ptr).
// Settings and the PNG header, written through the writer's append_output.
bool png_start(png_structp png, png_infop info, SnapshotWriter* writer);
// Rows [first, last) of the RGB canvas `rgb` (SnapshotWriter::kWidthPx wide).
bool png_rows(png_structp png, const std::uint8_t* rgb, int first, int last);
// The end of the image.
bool png_finish(png_structp png);

}  // namespace boticelli::firmware::snapshot_detail
#endif
