// FakeV4l2Device: a V4L2 capture device behind the V4l2Io seam (formats, buffers, errors,
// unplugging).
#pragma once

#include <cstddef>
#include <cstdint>
#include <deque>
#include <vector>

#include "hal/linux/v4l2_io.h"

namespace boticelli::fakes {

struct FakeV4l2Config {
  std::uint32_t max_width = 640;  // S_FMT clamps the size to these
  std::uint32_t max_height = 480;
  std::uint32_t stride_padding = 0;  // bytes added to each row (bytesperline)
  std::uint32_t max_buffers = 4;     // REQBUFS grants at most this many
  std::uint32_t min_buffers = 0;     // ... and at least this many (a driver's minimum)
  bool offers_yuyv = true;           // false: S_FMT answers with MJPEG
  bool capture = true;               // capabilities: VIDEO_CAPTURE
  bool streaming = true;             // capabilities: STREAMING
};

// A "driver" in memory: S_FMT adjusts the request like a real one, REQBUFS/QUERYBUF/mmap
// hand out its own storage, the test captures frames (capture()) into queued buffers
// (each filled with the sequence number), and can flag them as errors, make the next call
// fail with EINTR, or unplug the device (ENODEV everywhere, POLLERR, open fails) and plug it
// back.
class FakeV4l2Device final : public hal_linux::V4l2Io {
 public:
  explicit FakeV4l2Device(const FakeV4l2Config& config = {}) : config_(config) {}

  int open(const char* path) override;
  int close(int fd) override;
  int ioctl(int fd, unsigned long request, void* arg) override;
  void* mmap(std::size_t length, int fd, std::int64_t offset) override;
  int munmap(void* address, std::size_t length) override;
  int poll_in(int fd, short& revents) override;

  // Test side.
  // Fills the oldest queued buffer as a captured frame; false when none is queued (the
  // frame is lost, as with a real driver).
  bool capture(bool error_flag = false, std::uint32_t bytes_short = 0);
  void interrupt_next_call() { eintr_next_ = true; }
  void unplug() { present_ = false; }
  void plug() { present_ = true; }
  bool streaming() const { return streaming_; }
  std::size_t queued() const { return queued_.size(); }
  std::size_t mapped() const { return mapped_; }
  int opens() const { return opens_; }
  int open_fds() const { return open_fds_; }
  std::uint32_t requested_width() const { return requested_width_; }
  // Calls that may wait on a real device (open, mmap, every ioctl but QBUF and DQBUF).
  int slow_calls() const { return slow_calls_; }

 private:
  static constexpr int kFd = 42;
  FakeV4l2Config config_;
  bool present_ = true;
  bool eintr_next_ = false;
  bool streaming_ = false;
  int opens_ = 0;
  int open_fds_ = 0;
  int slow_calls_ = 0;
  std::uint32_t width_ = 0;
  std::uint32_t height_ = 0;
  std::uint32_t stride_ = 0;
  std::uint32_t requested_width_ = 0;
  std::vector<std::vector<std::uint8_t>> storage_;
  std::deque<std::uint32_t> queued_;
  struct Done {
    std::uint32_t index;
    std::uint32_t flags;
    std::uint32_t bytesused;
    std::uint32_t sequence;
  };
  std::deque<Done> done_;
  std::uint32_t sequence_ = 0;
  std::size_t mapped_ = 0;
};

}  // namespace boticelli::fakes
