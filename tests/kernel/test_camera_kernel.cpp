// Kernel in the loop, camera: CameraV4l2 against vivid's webcam input (/dev/video0): format,
// frame rate, newest frame, timestamps, vivid's error injection, and a module reload.
#include <fcntl.h>
#include <linux/videodev2.h>
#include <sys/ioctl.h>
#include <unistd.h>

#include <algorithm>
#include <cstdint>
#include <cstdio>
#include <cstring>

#include "hal/linux/camera_v4l2.h"
#include "kernel_rig.h"

#include "CppUTest/TestHarness.h"
#include "alloc_guard.h"

using boticelli::hal::CameraPoll;
using boticelli::hal::Frame;
using boticelli::hal_linux::CameraV4l2;
using boticelli::hal_linux::CameraV4l2Config;
using boticelli::kernel_test::Cycles;
using boticelli::kernel_test::sh;

namespace {

constexpr const char* kDevice = "/dev/video0";
constexpr std::uint64_t kPeriodUs = 40000;  // 25 fps, vivid's most at 640x480

// Sets one of vivid's controls, found by its name, through a second file descriptor (as a
// test tool would); true when the driver took it.
bool set_vivid_control(const char* name, int value) {
  const int fd = ::open(kDevice, O_RDWR | O_CLOEXEC);
  if (fd < 0) return false;
  bool ok = false;
  v4l2_queryctrl q{};
  q.id = V4L2_CTRL_FLAG_NEXT_CTRL;
  while (::ioctl(fd, VIDIOC_QUERYCTRL, &q) == 0) {
    if (std::strcmp(reinterpret_cast<const char*>(q.name), name) == 0) {
      v4l2_control c{};
      c.id = q.id;
      c.value = value;
      ok = ::ioctl(fd, VIDIOC_S_CTRL, &c) == 0;
      break;
    }
    q.id |= V4L2_CTRL_FLAG_NEXT_CTRL;
  }
  ::close(fd);
  return ok;
}

struct CameraRig {
  CameraRig() : camera(config(), cycles.clock()) {}
  static CameraV4l2Config config() {
    CameraV4l2Config c;
    c.device = kDevice;
    c.reopen_backoff_ms = 50;
    c.reopen_backoff_max_ms = 200;
    return c;
  }
  // Polls every 10 ms for `ms`, checking each frame; returns the frames seen.
  int stream_ms(int ms) {
    const std::uint64_t end = cycles.now_us() + static_cast<std::uint64_t>(ms) * 1000U;
    int frames = 0;
    while (cycles.now_us() < end) {
      Frame f;
      const CameraPoll r = camera.poll(f);
      CHECK_TEXT(r != CameraPoll::kFault, camera.error());
      if (r == CameraPoll::kFrame) {
        if (frames > 0) CHECK(f.sequence > last_sequence);
        max_gap = std::max(max_gap, f.sequence - last_sequence);
        last_sequence = f.sequence;
        ++frames;
        camera.release();
      }
      cycles.wait();
    }
    return frames;
  }
  Cycles cycles;
  CameraV4l2 camera;
  std::uint32_t last_sequence = 0;
  std::uint32_t max_gap = 0;
};

}  // namespace

TEST_GROUP(KernelCamera){};

TEST(KernelCamera, NegotiatesYuyv640x480At25FramesASecondWithIncreasingSequences) {
  CameraRig rig;
  CHECK_TRUE_TEXT(rig.camera.init(), rig.camera.error());
  CHECK_EQUAL(640U, rig.camera.width_px());
  CHECK_EQUAL(480U, rig.camera.height_px());
  CHECK_EQUAL(1280U, rig.camera.stride_bytes());
  CHECK_EQUAL(kPeriodUs, rig.camera.frame_interval_us());
  boticelli::test::AllocationGuard guard;  // the cyclic path against the real driver
  const int frames = rig.stream_ms(2000);
  guard.stop();
  CHECK_EQUAL(0U, guard.allocations());
  std::printf("\ncamera: %d frames in 2 s\n", frames);
  CHECK(frames >= 40);  // 50 at 25 fps; vivid's default would give 10
}

TEST(KernelCamera, ASlowConsumerGetsTheNewestFrame) {
  CameraRig rig;
  CHECK_TRUE_TEXT(rig.camera.init(), rig.camera.error());
  rig.stream_ms(200);
  for (int round = 0; round < 4; ++round) {
    Cycles slow(200000);  // the consumer comes every 200 ms: five frames each time
    slow.wait();
    Frame f;
    CHECK(rig.camera.poll(f) == CameraPoll::kFrame);
    // Everything older went back to the driver: nothing else is waiting.
    CHECK_TRUE_TEXT(rig.camera.poll(f) == CameraPoll::kNoFrame, "an older frame was still queued");
  }
  CHECK(rig.camera.skipped_frames() >= 8U);
}

TEST(KernelCamera, FrameTimestampsAreNeverAheadOfTheClock) {
  CameraRig rig;
  CHECK_TRUE_TEXT(rig.camera.init(), rig.camera.error());
  int frames = 0;
  for (int i = 0; i < 100; ++i) {
    Frame f;
    if (rig.camera.poll(f) == CameraPoll::kFrame) {
      const std::uint64_t now = rig.cycles.now_us();
      CHECK_TEXT(f.timestamp_us <= now, "a frame stamped in the future");
      CHECK(now - f.timestamp_us < 2 * kPeriodUs);
      ++frames;
    }
    rig.cycles.wait();
  }
  CHECK(frames >= 15);
}

TEST(KernelCamera, AnErrorFlaggedBufferIsDroppedAndStreamingGoesOn) {
  CameraRig rig;
  CHECK_TRUE_TEXT(rig.camera.init(), rig.camera.error());
  rig.stream_ms(200);
  CHECK_EQUAL(0U, rig.camera.dropped_frames());
  CHECK_TRUE(set_vivid_control("Inject V4L2_BUF_FLAG_ERROR", 1));
  CHECK(rig.stream_ms(500) >= 8);
  CHECK_EQUAL(1U, rig.camera.dropped_frames());
}

TEST(KernelCamera, DroppedBuffersAreSequenceGapsNotFaults) {
  CameraRig rig;
  CHECK_TRUE_TEXT(rig.camera.init(), rig.camera.error());
  CHECK_TRUE(set_vivid_control("Percentage of Dropped Buffers", 50));
  const int frames = rig.stream_ms(1500);
  CHECK_TRUE(set_vivid_control("Percentage of Dropped Buffers", 0));
  CHECK(frames >= 8);
  CHECK(rig.max_gap >= 2U);
}

TEST(KernelCamera, ADisconnectIsAFaultAndFramesComeBackAfterTheModuleIsReloaded) {
  CameraRig rig;
  CHECK_TRUE_TEXT(rig.camera.init(), rig.camera.error());
  rig.stream_ms(200);
  CHECK_TRUE(set_vivid_control("Disconnect", 1));
  Frame f;
  CameraPoll r = CameraPoll::kNoFrame;
  for (int i = 0; i < 20 && r != CameraPoll::kFault; ++i) {
    r = rig.camera.poll(f);
    rig.cycles.wait();
  }
  CHECK_TRUE(r == CameraPoll::kFault);
  STRCMP_CONTAINS("disappeared", rig.camera.error());
  CHECK_FALSE(rig.camera.streaming());
  // The driver closed its descriptor, so the module can go.
  CHECK_EQUAL(0, sh("rmmod vivid && modprobe vivid n_devs=1 node_types=0x1"));
  std::uint64_t longest_poll_us = 0;
  const std::uint64_t start = rig.cycles.now_us();
  r = CameraPoll::kFault;
  while (r != CameraPoll::kFrame && rig.cycles.now_us() - start < 3000000U) {
    const std::uint64_t t0 = rig.cycles.now_us();
    r = rig.camera.poll(f);
    longest_poll_us = std::max(longest_poll_us, rig.cycles.now_us() - t0);
    rig.cycles.wait();
  }
  std::printf("\ncamera: frames back %.2f s after the reload, longest poll() %.1f ms\n",
              static_cast<double>(rig.cycles.now_us() - start) * 1e-6,
              static_cast<double>(longest_poll_us) * 1e-3);
  CHECK_TRUE_TEXT(r == CameraPoll::kFrame, rig.camera.error());
  STRCMP_EQUAL("", rig.camera.error());
}
