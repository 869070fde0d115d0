// Helpers of the kernel-in-the-loop tests (shell, files, fixed-rate cycles).
#include "kernel_rig.h"

#include <fcntl.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cstdlib>
#include <cstring>

namespace boticelli::kernel_test {

int sh(const char* command) {
  const int status = std::system(command);
  if (status < 0 || !WIFEXITED(status)) return -1;
  return WEXITSTATUS(status);
}

bool read_text(const char* path, char* out, unsigned size) {
  const int fd = ::open(path, O_RDONLY | O_CLOEXEC);
  if (fd < 0 || size == 0) return false;
  const ssize_t n = ::read(fd, out, size - 1);
  ::close(fd);
  if (n < 0) return false;
  out[n] = '\0';
  return true;
}

bool write_text(const char* path, const char* text) {
  const int fd = ::open(path, O_WRONLY | O_CLOEXEC);
  if (fd < 0) return false;
  const auto len = static_cast<ssize_t>(std::strlen(text));
  const bool ok = ::write(fd, text, static_cast<std::size_t>(len)) == len;
  return ::close(fd) == 0 && ok;
}

void Cycles::wait() {
  const std::uint64_t now = clock_.now_us();
  if (next_us_ == 0 || next_us_ + period_us_ < now) next_us_ = now;  // first call, or late
  next_us_ += period_us_;
  clock_.sleep_until_us(next_us_);
}

}  // namespace boticelli::kernel_test
