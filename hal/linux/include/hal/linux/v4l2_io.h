// V4l2Io: the thin seam between CameraV4l2 and the kernel (open, ioctl, mmap, poll), fakeable in
// tests.
#pragma once

#include <cstddef>
#include <cstdint>

namespace boticelli::hal_linux {

// Each call has the contract of the system call of the same name: −1 (or nullptr for mmap)
// with errno set on failure. SystemV4l2Io forwards to the kernel; tests pass a fake device.
class V4l2Io {
 public:
  virtual ~V4l2Io() = default;
  virtual int open(const char* path) = 0;  // O_RDWR | O_NONBLOCK | O_CLOEXEC
  virtual int close(int fd) = 0;
  virtual int ioctl(int fd, unsigned long request, void* arg) = 0;
  virtual void* mmap(std::size_t length, int fd, std::int64_t offset) = 0;  // shared, R/W
  virtual int munmap(void* address, std::size_t length) = 0;
  // Zero-timeout poll for input; `revents` gets the returned events.
  virtual int poll_in(int fd, short& revents) = 0;
};

class SystemV4l2Io final : public V4l2Io {
 public:
  int open(const char* path) override;
  int close(int fd) override;
  int ioctl(int fd, unsigned long request, void* arg) override;
  void* mmap(std::size_t length, int fd, std::int64_t offset) override;
  int munmap(void* address, std::size_t length) override;
  int poll_in(int fd, short& revents) override;
};

}  // namespace boticelli::hal_linux
