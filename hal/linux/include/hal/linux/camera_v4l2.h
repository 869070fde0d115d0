// CameraV4l2: hal::Camera for a V4L2 capture device (UVC webcam) with mmap streaming, YUYV.
#pragma once

#include <cstddef>
#include <cstdint>

#include "hal/camera.h"
#include "hal/clock.h"
#include "hal/linux/v4l2_io.h"

struct v4l2_buffer;

namespace boticelli::hal_linux {

struct CameraV4l2Config {
  const char* device = "/dev/video0";
  std::uint32_t width_px = 640;  // requested; the size the driver returns is the one used
  std::uint32_t height_px = 480;
  std::uint32_t buffer_count = 4;    // requested mmap buffers; fewer than 2 granted is an error
  std::uint32_t frame_rate_hz = 25;  // asked with VIDIOC_S_PARM (0: the driver's default)
  std::uint32_t reopen_backoff_ms = 250;       // first wait before re-opening a lost device
  std::uint32_t reopen_backoff_max_ms = 4000;  // the wait doubles up to this
};

// init(): open, VIDIOC_QUERYCAP (capture + streaming), VIDIOC_S_FMT YUYV (keeps the size and
// stride the driver returns), VIDIOC_S_PARM (frame rate; the interval the driver answers is
// kept), VIDIOC_REQBUFS mmap, QUERYBUF + mmap each, QBUF all, STREAMON.
// poll(): zero-timeout poll, then non-blocking VIDIOC_DQBUF until the queue is empty; frames
// flagged V4L2_BUF_FLAG_ERROR (or shorter than a full image) are re-queued and skipped, and
// of the good ones only the newest is lent (older ones are re-queued: skipped_frames()).
// EAGAIN is "no frame", EINTR is retried. A timestamp later than the clock or more than 1 s
// old is replaced by the clock's time. A device that fails (unplugged: ENODEV, EIO,
// POLLERR) is torn down and re-opened with exponential backoff by later poll() calls, one
// bounded step per call (open, format, buffers, one mmap per call, stream on); they report
// kFault meanwhile. One frame is lent at a time, until release() or the next poll().
class CameraV4l2 final : public hal::Camera {
 public:
  static constexpr std::size_t kMaxBuffers = 8;

  // `io` defaults to the real system calls; it and `clock` must outlive the camera.
  CameraV4l2(const CameraV4l2Config& config, hal::Clock& clock, V4l2Io* io = nullptr);
  ~CameraV4l2() override;

  bool init() override;
  hal::CameraPoll poll(hal::Frame& frame) override;
  void release() override;
  std::uint32_t width_px() const override { return width_px_; }
  std::uint32_t height_px() const override { return height_px_; }
  const char* error() const override { return error_; }

  std::uint32_t stride_bytes() const { return stride_bytes_; }
  std::uint32_t buffers() const { return buffer_count_; }
  std::uint32_t dropped_frames() const { return dropped_frames_; }
  std::uint32_t reopen_attempts() const { return reopen_attempts_; }
  std::uint32_t skipped_frames() const { return skipped_frames_; }  // older frames not lent
  std::uint32_t implausible_timestamps() const { return implausible_timestamps_; }
  std::uint32_t surplus_buffer_grants() const { return surplus_buffer_grants_; }
  std::uint32_t frame_interval_us() const { return frame_interval_us_; }  // 0: not set
  bool streaming() const { return streaming_; }

 private:
  struct Buffer {
    void* start = nullptr;
    std::size_t length = 0;
  };
  // Bringing the device up, in steps of at most two slow calls (see step()).
  enum class Stage : std::uint8_t { kOpen, kFormat, kRequest, kMap, kStart, kStreaming };
  bool open_and_start();  // all steps at once (init)
  bool step();            // one step; false: failed, torn down, error_ set
  bool fail_step(const char* what, int err);
  std::uint64_t capture_time(const v4l2_buffer& b);
  void teardown();
  void lose_device(const char* what, int err);
  bool queue(std::uint32_t index);
  int xioctl(unsigned long request, void* arg);

  CameraV4l2Config config_;
  hal::Clock& clock_;
  SystemV4l2Io system_io_;
  V4l2Io& io_;
  int fd_ = -1;
  bool streaming_ = false;
  bool initialised_ = false;
  Buffer buffers_[kMaxBuffers];
  std::uint32_t buffer_count_ = 0;
  std::uint32_t width_px_ = 0;
  std::uint32_t height_px_ = 0;
  std::uint32_t stride_bytes_ = 0;
  std::uint32_t image_bytes_ = 0;
  int held_index_ = -1;
  std::uint64_t reopen_at_us_ = 0;
  std::uint32_t backoff_ms_ = 0;
  std::uint32_t dropped_frames_ = 0;
  std::uint32_t reopen_attempts_ = 0;
  std::uint32_t skipped_frames_ = 0;
  std::uint32_t implausible_timestamps_ = 0;
  std::uint32_t surplus_buffer_grants_ = 0;
  std::uint32_t frame_interval_us_ = 0;
  Stage stage_ = Stage::kOpen;
  std::uint32_t map_index_ = 0;
  char error_[160] = "";
};

}  // namespace boticelli::hal_linux
