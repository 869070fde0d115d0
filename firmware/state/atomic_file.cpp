// Atomic file replacement (see atomic_file.h).
#include "firmware/state/atomic_file.h"

#include <fcntl.h>
#include <unistd.h>

#include <array>
#include <cerrno>
#include <cstdio>
#include <cstring>

namespace boticelli::firmware {
namespace {

void set_error(char* error, std::size_t size, const char* what, const char* path) {
  std::snprintf(error, size, "%s %s: %s", what, path, std::strerror(errno));
}

bool write_all(int fd, const char* data, std::size_t size) {
  while (size > 0) {
    const ssize_t n = ::write(fd, data, size);
    if (n < 0) {
      if (errno == EINTR) continue;
      return false;
    }
    data += n;
    size -= static_cast<std::size_t>(n);
  }
  return true;
}

StorageFaultHook g_storage_fault = nullptr;
void* g_storage_fault_context = nullptr;

// The injected errno for this call, 0 for none.
int injected(StorageCall call) {
  return g_storage_fault != nullptr ? g_storage_fault(call, g_storage_fault_context) : 0;
}

}  // namespace

void set_storage_fault_hook(StorageFaultHook hook, void* context) {
  g_storage_fault = hook;
  g_storage_fault_context = context;
}

bool write_file_atomically(const char* dir, const char* name, std::string_view data, char* error,
                           std::size_t error_size, SaveCrashHook hook, void* hook_context) {
  std::array<char, 512> path{};
  std::array<char, 512> tmp_path{};
  const int n1 = std::snprintf(path.data(), path.size(), "%s/%s", dir, name);
  const int n2 = std::snprintf(tmp_path.data(), tmp_path.size(), "%s/%s.tmp", dir, name);
  if (n1 < 0 || n2 < 0 || static_cast<std::size_t>(n2) >= tmp_path.size()) {
    std::snprintf(error, error_size, "path too long: %s/%s", dir, name);
    return false;
  }
  auto crashed = [&](SaveStep step) {
    if (hook == nullptr || !hook(step, hook_context)) return false;
    std::snprintf(error, error_size, "save interrupted (test crash hook)");
    return true;
  };
  // The temporary file is always a new file of our own: a stale one (left by a crash) is
  // unlinked first — unlink removes a symlink itself, never its target — and it is then
  // created with O_EXCL | O_NOFOLLOW, so whatever appears at that name in between (a
  // symlink, another file) makes the save fail instead of being written through. This
  // rather than O_TMPFILE + linkat: O_TMPFILE depends on the file system (and is missing
  // on some), linkat cannot replace a name either (a named temporary and the rename are
  // still needed), and the save keeps the steps the crash hook and the tests know.
  const int fault = injected(StorageCall::kCreate);
  if (fault != 0) errno = fault;
  if (fault == 0 && ::unlink(tmp_path.data()) != 0 && errno != ENOENT) {
    set_error(error, error_size, "cannot remove the stale", tmp_path.data());
    return false;
  }
  const int fd = fault != 0 ? -1
                            : ::open(tmp_path.data(),
                                     O_WRONLY | O_CREAT | O_EXCL | O_NOFOLLOW | O_CLOEXEC, 0640);
  if (fd < 0) {
    set_error(error, error_size, "cannot create", tmp_path.data());
    return false;
  }
  if (crashed(SaveStep::kTempCreated)) {
    ::close(fd);
    return false;
  }
  for (std::size_t done = 0; done < data.size();) {
    const std::size_t left = data.size() - done;
    const std::size_t n = left < kAtomicWriteChunkBytes ? left : kAtomicWriteChunkBytes;
    const int write_fault = injected(StorageCall::kWrite);
    if (write_fault != 0) errno = write_fault;
    if (write_fault != 0 || !write_all(fd, data.data() + done, n)) {
      set_error(error, error_size, "cannot write", tmp_path.data());
      ::close(fd);
      ::unlink(tmp_path.data());
      return false;
    }
    done += n;
    if (crashed(SaveStep::kChunkWritten)) {
      ::close(fd);
      return false;
    }
  }
  const int sync_fault = injected(StorageCall::kSync);
  if (sync_fault != 0) errno = sync_fault;
  if (sync_fault != 0 || ::fsync(fd) != 0) {
    set_error(error, error_size, "cannot sync", tmp_path.data());
    ::close(fd);
    ::unlink(tmp_path.data());
    return false;
  }
  if (::close(fd) != 0) {
    set_error(error, error_size, "cannot close", tmp_path.data());
    ::unlink(tmp_path.data());
    return false;
  }
  if (crashed(SaveStep::kTempSynced)) return false;
  if (::rename(tmp_path.data(), path.data()) != 0) {
    set_error(error, error_size, "cannot rename onto", path.data());
    ::unlink(tmp_path.data());
    return false;
  }
  if (crashed(SaveStep::kRenamed)) return false;
  // Make the rename itself durable.
  const int dfd = ::open(dir, O_RDONLY | O_DIRECTORY | O_CLOEXEC);
  const int dir_fault = injected(StorageCall::kSyncDirectory);
  if (dir_fault != 0) errno = dir_fault;
  if (dfd < 0 || dir_fault != 0 || ::fsync(dfd) != 0) {
    set_error(error, error_size, "cannot sync directory", dir);
    if (dfd >= 0) ::close(dfd);
    return false;
  }
  ::close(dfd);
  return true;
}

}  // namespace boticelli::firmware
