// CameraV4l2: V4L2 mmap streaming capture with error-frame dropping and re-open with backoff.
#include "hal/linux/camera_v4l2.h"

#include <linux/videodev2.h>
#include <poll.h>

#include <algorithm>
#include <cerrno>
#include <cstdio>

#include "hal/linux/error_text.h"

namespace boticelli::hal_linux {

CameraV4l2::CameraV4l2(const CameraV4l2Config& config, hal::Clock& clock, V4l2Io* io)
    : config_(config), clock_(clock), io_(io != nullptr ? *io : system_io_) {}

CameraV4l2::~CameraV4l2() {
  teardown();
}

int CameraV4l2::xioctl(unsigned long request, void* arg) {
  int rc = 0;
  int tries = 0;
  do {
    rc = io_.ioctl(fd_, request, arg);
  } while (rc == -1 && errno == EINTR && ++tries < 8);
  return rc;
}

bool CameraV4l2::init() {
  initialised_ = true;
  backoff_ms_ = config_.reopen_backoff_ms;
  if (open_and_start()) return true;
  // The device may appear later (USB enumeration): poll() keeps trying with backoff.
  reopen_at_us_ = clock_.now_us() + std::uint64_t{backoff_ms_} * 1000U;
  return false;
}

bool CameraV4l2::open_and_start() {
  stage_ = Stage::kOpen;
  for (int i = 0; i < 4 + static_cast<int>(kMaxBuffers) && stage_ != Stage::kStreaming; ++i) {
    if (!step()) return false;
  }
  return stage_ == Stage::kStreaming;
}

bool CameraV4l2::fail_step(const char* what, int err) {
  set_error(error_, what, err);
  teardown();
  return false;
}

// One bounded step of bringing the device up: each makes at most two calls that may wait
// on the device (a UVC camera answers S_FMT, S_PARM and STREAMON with USB control transfers
// of tens to hundreds of milliseconds), so a re-open spreads over several poll() calls.
bool CameraV4l2::step() {
  switch (stage_) {
    case Stage::kOpen: {
      teardown();
      fd_ = io_.open(config_.device);
      if (fd_ < 0) return fail_step("camera: cannot open the device", errno);
      v4l2_capability cap{};
      if (xioctl(VIDIOC_QUERYCAP, &cap) != 0) {
        return fail_step("camera: VIDIOC_QUERYCAP failed (not a V4L2 device?)", errno);
      }
      const std::uint32_t caps =
          (cap.capabilities & V4L2_CAP_DEVICE_CAPS) != 0 ? cap.device_caps : cap.capabilities;
      if ((caps & V4L2_CAP_VIDEO_CAPTURE) == 0 || (caps & V4L2_CAP_STREAMING) == 0) {
        return fail_step("camera: the device cannot capture video with streaming I/O", 0);
      }
      stage_ = Stage::kFormat;
      return true;
    }
    case Stage::kFormat: {
      v4l2_format fmt{};
      fmt.type = V4L2_BUF_TYPE_VIDEO_CAPTURE;
      fmt.fmt.pix.width = config_.width_px;
      fmt.fmt.pix.height = config_.height_px;
      fmt.fmt.pix.pixelformat = V4L2_PIX_FMT_YUYV;
      fmt.fmt.pix.field = V4L2_FIELD_ANY;
      if (xioctl(VIDIOC_S_FMT, &fmt) != 0) return fail_step("camera: VIDIOC_S_FMT failed", errno);
      // The driver adjusts the request to what it supports: use what it returned.
      if (fmt.fmt.pix.pixelformat != V4L2_PIX_FMT_YUYV) {
        return fail_step("camera: the driver does not offer YUYV", 0);
      }
      const std::uint32_t w = fmt.fmt.pix.width;
      const std::uint32_t h = fmt.fmt.pix.height;
      std::uint32_t stride = fmt.fmt.pix.bytesperline;
      if (stride == 0) stride = 2 * w;  // some drivers leave it 0 for packed formats
      if (w == 0 || h == 0 || w > 16384 || h > 16384 || stride < 2 * w ||
          std::uint64_t{stride} * h > 0xFFFFFFFFULL) {
        return fail_step("camera: the driver returned an unusable format", 0);
      }
      width_px_ = w;
      height_px_ = h;
      stride_bytes_ = stride;
      image_bytes_ = stride * h;
      // The frame rate: without S_PARM a driver keeps its default (vivid's is 5 fps). A
      // driver without V4L2_CAP_TIMEPERFRAME refuses or ignores it; what it answers is used.
      frame_interval_us_ = 0;
      if (config_.frame_rate_hz > 0) {
        v4l2_streamparm parm{};
        parm.type = V4L2_BUF_TYPE_VIDEO_CAPTURE;
        parm.parm.capture.timeperframe.numerator = 1;
        parm.parm.capture.timeperframe.denominator = config_.frame_rate_hz;
        if (xioctl(VIDIOC_S_PARM, &parm) == 0 && parm.parm.capture.timeperframe.denominator != 0) {
          frame_interval_us_ =
              static_cast<std::uint32_t>(std::uint64_t{parm.parm.capture.timeperframe.numerator} *
                                         1000000U / parm.parm.capture.timeperframe.denominator);
        }
      }
      stage_ = Stage::kRequest;
      return true;
    }
    case Stage::kRequest: {
      v4l2_requestbuffers req{};
      req.count = std::min<std::uint32_t>(config_.buffer_count, kMaxBuffers);
      req.type = V4L2_BUF_TYPE_VIDEO_CAPTURE;
      req.memory = V4L2_MEMORY_MMAP;
      if (xioctl(VIDIOC_REQBUFS, &req) != 0) {
        return fail_step("camera: VIDIOC_REQBUFS (mmap) failed", errno);
      }
      // More than asked for is allowed (a driver's minimum): the extra buffers stay with the
      // driver, never mapped or queued. Fewer than two cannot stream.
      buffer_count_ = std::min<std::uint32_t>(req.count, kMaxBuffers);
      if (req.count > kMaxBuffers) ++surplus_buffer_grants_;
      if (req.count < 2) return fail_step("camera: the driver granted fewer than two buffers", 0);
      map_index_ = 0;
      stage_ = Stage::kMap;
      return true;
    }
    case Stage::kMap: {
      v4l2_buffer b{};
      b.type = V4L2_BUF_TYPE_VIDEO_CAPTURE;
      b.memory = V4L2_MEMORY_MMAP;
      b.index = map_index_;
      if (xioctl(VIDIOC_QUERYBUF, &b) != 0) {
        return fail_step("camera: VIDIOC_QUERYBUF failed", errno);
      }
      if (b.length < image_bytes_)
        return fail_step("camera: a buffer is smaller than one image", 0);
      void* p = io_.mmap(b.length, fd_, b.m.offset);
      if (p == nullptr) return fail_step("camera: mmap of a capture buffer failed", errno);
      buffers_[map_index_] = {p, b.length};
      if (++map_index_ == buffer_count_) stage_ = Stage::kStart;
      return true;
    }
    case Stage::kStart: {
      // QBUF only hands the driver a buffer (no device I/O); STREAMON is the slow one.
      for (std::uint32_t i = 0; i < buffer_count_; ++i) {
        if (!queue(i)) return fail_step("camera: VIDIOC_QBUF failed", errno);
      }
      int type = V4L2_BUF_TYPE_VIDEO_CAPTURE;
      if (xioctl(VIDIOC_STREAMON, &type) != 0) {
        return fail_step("camera: VIDIOC_STREAMON failed", errno);
      }
      streaming_ = true;
      stage_ = Stage::kStreaming;
      backoff_ms_ = config_.reopen_backoff_ms;
      error_[0] = '\0';
      return true;
    }
    case Stage::kStreaming:
      return true;
  }
  return false;
}

bool CameraV4l2::queue(std::uint32_t index) {
  v4l2_buffer b{};
  b.type = V4L2_BUF_TYPE_VIDEO_CAPTURE;
  b.memory = V4L2_MEMORY_MMAP;
  b.index = index;
  return xioctl(VIDIOC_QBUF, &b) == 0;
}

void CameraV4l2::teardown() {
  if (fd_ >= 0 && streaming_) {
    int type = V4L2_BUF_TYPE_VIDEO_CAPTURE;
    (void)xioctl(VIDIOC_STREAMOFF, &type);
  }
  streaming_ = false;
  for (std::uint32_t i = 0; i < kMaxBuffers; ++i) {
    if (buffers_[i].start != nullptr) io_.munmap(buffers_[i].start, buffers_[i].length);
    buffers_[i] = {};
  }
  if (fd_ >= 0) {
    if (buffer_count_ > 0) {
      v4l2_requestbuffers req{};
      req.count = 0;  // frees the driver's buffers (harmless when the device is gone)
      req.type = V4L2_BUF_TYPE_VIDEO_CAPTURE;
      req.memory = V4L2_MEMORY_MMAP;
      (void)xioctl(VIDIOC_REQBUFS, &req);
    }
    io_.close(fd_);
  }
  fd_ = -1;
  buffer_count_ = 0;
  held_index_ = -1;
  stage_ = Stage::kOpen;
}

void CameraV4l2::lose_device(const char* what, int err) {
  set_error(error_, what, err);
  teardown();
  reopen_at_us_ = clock_.now_us() + std::uint64_t{backoff_ms_} * 1000U;
}

hal::CameraPoll CameraV4l2::poll(hal::Frame& frame) {
  if (!initialised_) return hal::CameraPoll::kFault;
  if (!streaming_) {
    // Re-opening, one bounded step per call (step()); kFault until streaming again.
    const std::uint64_t now = clock_.now_us();
    if (now < reopen_at_us_) return hal::CameraPoll::kFault;
    if (stage_ == Stage::kOpen) ++reopen_attempts_;
    if (!step()) {
      backoff_ms_ = std::min(backoff_ms_ * 2U, config_.reopen_backoff_max_ms);
      reopen_at_us_ = now + std::uint64_t{backoff_ms_} * 1000U;
      return hal::CameraPoll::kFault;
    }
    if (!streaming_) return hal::CameraPoll::kFault;
    return hal::CameraPoll::kNoFrame;
  }
  release();  // the previous frame's buffer goes back to the driver
  if (!streaming_) return hal::CameraPoll::kFault;  // release() may have lost the device
  short revents = 0;
  int rc = 0;
  int tries = 0;
  do {
    rc = io_.poll_in(fd_, revents);
  } while (rc < 0 && errno == EINTR && ++tries < 8);
  if (rc < 0) {
    lose_device("camera: poll failed", errno);
    return hal::CameraPoll::kFault;
  }
  if ((revents & (POLLERR | POLLHUP | POLLNVAL)) != 0) {
    lose_device("camera: the device reported an error or disappeared (POLLERR)", 0);
    return hal::CameraPoll::kFault;
  }
  if ((revents & POLLIN) == 0) return hal::CameraPoll::kNoFrame;
  // Drain every finished buffer (at most all of them): error frames are re-queued, and of
  // the good ones only the newest is lent, the older ones go straight back to the driver,
  // so a consumer slower than the camera gets the latest image, not one periods old.
  int newest = -1;
  v4l2_buffer got{};
  for (std::uint32_t attempt = 0; attempt < buffer_count_; ++attempt) {
    v4l2_buffer b{};
    b.type = V4L2_BUF_TYPE_VIDEO_CAPTURE;
    b.memory = V4L2_MEMORY_MMAP;
    if (xioctl(VIDIOC_DQBUF, &b) != 0) {
      if (errno == EAGAIN || errno == EINTR) break;
      lose_device("camera: VIDIOC_DQBUF failed", errno);
      return hal::CameraPoll::kFault;
    }
    if (b.index >= buffer_count_) {
      lose_device("camera: the driver returned an invalid buffer index", 0);
      return hal::CameraPoll::kFault;
    }
    // An error frame, or the older of two good ones, goes back to the driver at once.
    if ((b.flags & V4L2_BUF_FLAG_ERROR) != 0 || b.bytesused < image_bytes_) {
      ++dropped_frames_;
      if (!queue(b.index)) {
        lose_device("camera: VIDIOC_QBUF failed", errno);
        return hal::CameraPoll::kFault;
      }
      continue;
    }
    if (newest >= 0) {
      ++skipped_frames_;
      if (!queue(static_cast<std::uint32_t>(newest))) {
        lose_device("camera: VIDIOC_QBUF failed", errno);
        return hal::CameraPoll::kFault;
      }
    }
    newest = static_cast<int>(b.index);
    got = b;
  }
  if (newest < 0) return hal::CameraPoll::kNoFrame;
  held_index_ = newest;
  frame.data = static_cast<const std::uint8_t*>(buffers_[got.index].start);
  frame.width_px = width_px_;
  frame.height_px = height_px_;
  frame.stride_bytes = stride_bytes_;
  frame.format = hal::PixelFormat::kYuyv;
  frame.sequence = got.sequence;
  frame.timestamp_us = capture_time(got);
  return hal::CameraPoll::kFrame;
}

// Kernel timestamps are CLOCK_MONOTONIC when flagged so, like the board's clock; but a
// driver may stamp ahead (vivid stamps about 0.9 frame period in the future) or on another
// clock. A capture cannot be later than now nor, for a buffer just dequeued, more than a
// second old: outside that the board's clock at dequeue is used, and counted.
std::uint64_t CameraV4l2::capture_time(const v4l2_buffer& b) {
  const std::uint64_t now = clock_.now_us();
  if ((b.flags & V4L2_BUF_FLAG_TIMESTAMP_MASK) != V4L2_BUF_FLAG_TIMESTAMP_MONOTONIC ||
      (b.timestamp.tv_sec == 0 && b.timestamp.tv_usec == 0)) {
    return now;
  }
  const std::uint64_t t = static_cast<std::uint64_t>(b.timestamp.tv_sec) * 1000000U +
                          static_cast<std::uint64_t>(b.timestamp.tv_usec);
  if (t > now || now - t > 1000000U) {
    ++implausible_timestamps_;
    return now;
  }
  return t;
}

void CameraV4l2::release() {
  if (held_index_ < 0) return;
  const auto index = static_cast<std::uint32_t>(held_index_);
  held_index_ = -1;
  if (streaming_ && !queue(index)) lose_device("camera: VIDIOC_QBUF failed", errno);
}

}  // namespace boticelli::hal_linux
