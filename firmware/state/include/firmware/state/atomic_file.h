// Atomic file replacement: temporary file, fsync, rename, directory fsync (state and parameters).
#pragma once

#include <cstddef>
#include <cstdint>
#include <string_view>

namespace boticelli::firmware {

// The steps of write_file_atomically(), for the crash hook.
enum class SaveStep : std::uint8_t {
  kTempCreated,   // the temporary file exists, empty
  kChunkWritten,  // another chunk of the file is written (not yet synced)
  kTempSynced,    // the temporary file is complete and fsynced
  kRenamed,       // it has replaced the file (directory not yet synced)
};
// Test seam: called after each step; returning true makes the write stop there as if the
// process had been killed (its descriptors closed, nothing cleaned up).
using SaveCrashHook = bool (*)(SaveStep step, void* context);

// The system calls a board's fault injection can make fail (the sim board's storage faults:
// a full or unwritable state directory, docs/reliability.md; kSync, the temporary file's
// fsync before the rename, lets tests see that the data is synced before it replaces the file;
// kSyncDirectory, the directory's fsync after it, that a failure there is reported and closes
// what it opened).
enum class StorageCall : std::uint8_t { kCreate, kWrite, kSync, kSyncDirectory };
// Returns 0 to let the call run, or the errno it fails with instead (EACCES, ENOSPC, EIO).
using StorageFaultHook = int (*)(StorageCall call, void* context);
// Installs the process-wide hook (nullptr: none, the default). Set by a board at init,
// before any save or thread; never on hardware.
void set_storage_fault_hook(StorageFaultHook hook, void* context);

// Bytes written per write() call (one kChunkWritten step each).
inline constexpr std::size_t kAtomicWriteChunkBytes = std::size_t{16} * 1024;

// Replaces `dir`/`name` with `data`: writes `dir`/`name`.tmp, fsyncs it, renames it over
// `dir`/`name` and fsyncs `dir`, so after a crash or power cut at any point the file holds
// either its previous content or `data`, never a mix. The temporary file is always created
// anew (a stale one, or a symlink at its name, is unlinked first; then O_EXCL | O_NOFOLLOW),
// so nothing outside `dir` is ever written through it. No allocation (the paths are built on
// the stack), so it may run on any thread; it blocks in fsync, so never on the executive's
// cyclic path. False with a one-line reason in `error` (the old file is then untouched).
bool write_file_atomically(const char* dir, const char* name, std::string_view data, char* error,
                           std::size_t error_size, SaveCrashHook hook = nullptr,
                           void* hook_context = nullptr);

}  // namespace boticelli::firmware
