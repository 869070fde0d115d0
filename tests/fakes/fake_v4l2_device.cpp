// FakeV4l2Device: in-memory V4L2 capture driver for the camera driver's tests.
#include "fake_v4l2_device.h"

#include <linux/videodev2.h>
#include <poll.h>

#include <algorithm>
#include <cerrno>
#include <cstring>

namespace boticelli::fakes {

int FakeV4l2Device::open(const char*) {
  ++slow_calls_;
  if (!present_) {
    errno = ENOENT;
    return -1;
  }
  ++opens_;
  ++open_fds_;
  return kFd;
}

int FakeV4l2Device::close(int fd) {
  if (fd != kFd) {
    errno = EBADF;
    return -1;
  }
  --open_fds_;
  streaming_ = false;
  queued_.clear();
  done_.clear();
  return 0;
}

void* FakeV4l2Device::mmap(std::size_t length, int fd, std::int64_t offset) {
  ++slow_calls_;
  const auto index = static_cast<std::size_t>(offset / 0x100000);
  if (fd != kFd || !present_ || index >= storage_.size() || length > storage_[index].size()) {
    errno = EINVAL;
    return nullptr;
  }
  ++mapped_;
  return storage_[index].data();
}

int FakeV4l2Device::munmap(void*, std::size_t) {
  --mapped_;
  return 0;
}

int FakeV4l2Device::poll_in(int fd, short& revents) {
  if (fd != kFd) {
    errno = EBADF;
    return -1;
  }
  revents = 0;
  if (!present_) {
    revents = POLLERR;
  } else if (!done_.empty()) {
    revents = POLLIN;
  }
  return revents != 0 ? 1 : 0;
}

bool FakeV4l2Device::capture(bool error_flag, std::uint32_t bytes_short) {
  if (!streaming_ || queued_.empty()) return false;
  const std::uint32_t index = queued_.front();
  queued_.pop_front();
  std::vector<std::uint8_t>& buf = storage_[index];
  std::fill(buf.begin(), buf.end(), static_cast<std::uint8_t>(sequence_ & 0xFFU));
  done_.push_back({index, error_flag ? static_cast<std::uint32_t>(V4L2_BUF_FLAG_ERROR) : 0U,
                   stride_ * height_ - bytes_short, sequence_});
  ++sequence_;
  return true;
}

int FakeV4l2Device::ioctl(int fd, unsigned long request, void* arg) {
  if (request != VIDIOC_QBUF && request != VIDIOC_DQBUF) ++slow_calls_;
  if (fd != kFd) {
    errno = EBADF;
    return -1;
  }
  if (eintr_next_) {
    eintr_next_ = false;
    errno = EINTR;
    return -1;
  }
  if (!present_) {
    errno = ENODEV;
    return -1;
  }
  switch (request) {
    case VIDIOC_QUERYCAP: {
      auto* cap = static_cast<v4l2_capability*>(arg);
      std::memset(cap, 0, sizeof *cap);
      std::uint32_t caps = 0;
      if (config_.capture) caps |= V4L2_CAP_VIDEO_CAPTURE;
      if (config_.streaming) caps |= V4L2_CAP_STREAMING;
      cap->device_caps = caps;
      cap->capabilities = caps | V4L2_CAP_DEVICE_CAPS;
      return 0;
    }
    case VIDIOC_S_FMT: {
      auto* f = static_cast<v4l2_format*>(arg);
      if (f->type != V4L2_BUF_TYPE_VIDEO_CAPTURE || streaming_) {
        errno = f->type != V4L2_BUF_TYPE_VIDEO_CAPTURE ? EINVAL : EBUSY;
        return -1;
      }
      requested_width_ = f->fmt.pix.width;
      width_ = std::min(f->fmt.pix.width, config_.max_width) & ~1U;
      height_ = std::min(f->fmt.pix.height, config_.max_height);
      stride_ = 2 * width_ + config_.stride_padding;
      f->fmt.pix.width = width_;
      f->fmt.pix.height = height_;
      f->fmt.pix.pixelformat = config_.offers_yuyv ? V4L2_PIX_FMT_YUYV : V4L2_PIX_FMT_MJPEG;
      f->fmt.pix.bytesperline = stride_;
      f->fmt.pix.sizeimage = stride_ * height_;
      f->fmt.pix.field = V4L2_FIELD_NONE;
      return 0;
    }
    case VIDIOC_REQBUFS: {
      auto* r = static_cast<v4l2_requestbuffers*>(arg);
      if (r->memory != V4L2_MEMORY_MMAP) {
        errno = EINVAL;
        return -1;
      }
      // count 0 frees the buffers; otherwise the driver's range applies.
      if (r->count > 0) {
        r->count = std::max(std::min(r->count, config_.max_buffers), config_.min_buffers);
      }
      storage_.assign(r->count, std::vector<std::uint8_t>(std::size_t{stride_} * height_));
      queued_.clear();
      done_.clear();
      return 0;
    }
    case VIDIOC_QUERYBUF: {
      auto* b = static_cast<v4l2_buffer*>(arg);
      if (b->index >= storage_.size()) {
        errno = EINVAL;
        return -1;
      }
      b->length = static_cast<std::uint32_t>(storage_[b->index].size());
      b->m.offset = b->index * 0x100000U;
      return 0;
    }
    case VIDIOC_QBUF: {
      auto* b = static_cast<v4l2_buffer*>(arg);
      if (b->index >= storage_.size() ||
          std::find(queued_.begin(), queued_.end(), b->index) != queued_.end()) {
        errno = EINVAL;
        return -1;
      }
      queued_.push_back(b->index);
      return 0;
    }
    case VIDIOC_DQBUF: {
      auto* b = static_cast<v4l2_buffer*>(arg);
      if (done_.empty()) {
        errno = EAGAIN;
        return -1;
      }
      const Done d = done_.front();
      done_.pop_front();
      b->index = d.index;
      b->flags = d.flags;
      b->bytesused = d.bytesused;
      b->sequence = d.sequence;
      return 0;
    }
    case VIDIOC_STREAMON:
      streaming_ = true;
      return 0;
    case VIDIOC_STREAMOFF:
      streaming_ = false;
      queued_.clear();
      done_.clear();
      return 0;
    default:
      errno = ENOTTY;
      return -1;
  }
}

}  // namespace boticelli::fakes
