// SystemV4l2Io: the real system calls behind the V4L2 seam.
#include "hal/linux/v4l2_io.h"

#include <fcntl.h>
#include <poll.h>
#include <sys/ioctl.h>
#include <sys/mman.h>
#include <unistd.h>

namespace boticelli::hal_linux {

int SystemV4l2Io::open(const char* path) {
  return ::open(path, O_RDWR | O_NONBLOCK | O_CLOEXEC);
}
int SystemV4l2Io::close(int fd) {
  return ::close(fd);
}
int SystemV4l2Io::ioctl(int fd, unsigned long request, void* arg) {
  return ::ioctl(fd, request, arg);
}

void* SystemV4l2Io::mmap(std::size_t length, int fd, std::int64_t offset) {
  void* p =
      ::mmap(nullptr, length, PROT_READ | PROT_WRITE, MAP_SHARED, fd, static_cast<off_t>(offset));
  return p == MAP_FAILED ? nullptr : p;
}

int SystemV4l2Io::munmap(void* address, std::size_t length) {
  return ::munmap(address, length);
}

int SystemV4l2Io::poll_in(int fd, short& revents) {
  pollfd p{fd, POLLIN, 0};
  const int rc = ::poll(&p, 1, 0);
  revents = p.revents;
  return rc;
}

}  // namespace boticelli::hal_linux
