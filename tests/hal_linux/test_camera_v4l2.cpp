// Tests of CameraV4l2 through its ioctl seam against a fake V4L2 device.
#include <cstdint>

#include "fake_clock.h"
#include "fake_v4l2_device.h"
#include "hal/linux/camera_v4l2.h"

#include "CppUTest/TestHarness.h"
#include "alloc_guard.h"

using boticelli::fakes::FakeClock;
using boticelli::fakes::FakeV4l2Config;
using boticelli::fakes::FakeV4l2Device;
using boticelli::hal::CameraPoll;
using boticelli::hal::Frame;
using boticelli::hal_linux::CameraV4l2;
using boticelli::hal_linux::CameraV4l2Config;

TEST_GROUP(CameraV4l2) {
  FakeClock clock{1000000};
  CameraV4l2Config config;
};

TEST(CameraV4l2, StartsStreamingYuyvAt640x480WithAllBuffersQueued) {
  FakeV4l2Device dev;
  CameraV4l2 cam(config, clock, &dev);
  CHECK_TRUE_TEXT(cam.init(), cam.error());
  CHECK_TRUE(dev.streaming());
  CHECK_EQUAL(640U, cam.width_px());
  CHECK_EQUAL(480U, cam.height_px());
  CHECK_EQUAL(1280U, cam.stride_bytes());
  CHECK_EQUAL(4U, cam.buffers());
  CHECK_EQUAL(4U, dev.queued());
  CHECK_EQUAL(4U, dev.mapped());
}

TEST(CameraV4l2, UsesTheSizeAndStrideTheDriverReturns) {
  FakeV4l2Config fc;
  fc.max_width = 320;
  fc.max_height = 240;
  fc.stride_padding = 64;
  FakeV4l2Device dev(fc);
  CameraV4l2 cam(config, clock, &dev);
  CHECK_TRUE(cam.init());
  CHECK_EQUAL(640U, dev.requested_width());
  CHECK_EQUAL(320U, cam.width_px());
  CHECK_EQUAL(240U, cam.height_px());
  CHECK_EQUAL(704U, cam.stride_bytes());
  CHECK_TRUE(dev.capture());
  Frame f;
  CHECK(cam.poll(f) == CameraPoll::kFrame);
  CHECK_EQUAL(320U, f.width_px);
  CHECK_EQUAL(704U, f.stride_bytes);
}

TEST(CameraV4l2, RefusesADeviceWithoutCaptureOrStreaming) {
  FakeV4l2Config fc;
  fc.streaming = false;
  FakeV4l2Device dev(fc);
  CameraV4l2 cam(config, clock, &dev);
  CHECK_FALSE(cam.init());
  STRCMP_CONTAINS("streaming", cam.error());
  CHECK_EQUAL(0, dev.open_fds());
}

TEST(CameraV4l2, RefusesADriverWithoutYuyv) {
  FakeV4l2Config fc;
  fc.offers_yuyv = false;
  FakeV4l2Device dev(fc);
  CameraV4l2 cam(config, clock, &dev);
  CHECK_FALSE(cam.init());
  STRCMP_CONTAINS("YUYV", cam.error());
}

TEST(CameraV4l2, RefusesFewerThanTwoBuffersAndUnmapsEverything) {
  FakeV4l2Config fc;
  fc.max_buffers = 1;
  FakeV4l2Device dev(fc);
  CameraV4l2 cam(config, clock, &dev);
  CHECK_FALSE(cam.init());
  STRCMP_CONTAINS("fewer than two", cam.error());
  CHECK_EQUAL(0U, dev.mapped());
  CHECK_EQUAL(0, dev.open_fds());
}

TEST(CameraV4l2, NoFrameYetIsReportedAtOnce) {
  FakeV4l2Device dev;
  CameraV4l2 cam(config, clock, &dev);
  CHECK_TRUE(cam.init());
  Frame f;
  CHECK(cam.poll(f) == CameraPoll::kNoFrame);
}

TEST(CameraV4l2, TheNewestFrameIsLentUntilReleasedAndTheOlderOnesGoBackAtOnce) {
  FakeV4l2Device dev;
  CameraV4l2 cam(config, clock, &dev);
  CHECK_TRUE(cam.init());
  CHECK_TRUE(dev.capture());
  CHECK_TRUE(dev.capture());
  CHECK_TRUE(dev.capture());
  Frame f;
  CHECK(cam.poll(f) == CameraPoll::kFrame);
  CHECK_EQUAL(2U, f.sequence);  // the newest of the three
  CHECK_EQUAL(2, f.data[0]);
  CHECK_EQUAL(1000000U, f.timestamp_us);  // no kernel timestamp: the board's clock
  CHECK_EQUAL(2U, cam.skipped_frames());
  CHECK_EQUAL(3U, dev.queued());  // the two older ones were re-queued at once
  cam.release();
  CHECK_EQUAL(4U, dev.queued());
  CHECK(cam.poll(f) == CameraPoll::kNoFrame);
  CHECK_TRUE(dev.capture());
  CHECK(cam.poll(f) == CameraPoll::kFrame);
  CHECK_EQUAL(3U, f.sequence);
  CHECK_EQUAL(3, f.data[640]);
  // The next poll gives the lent buffer back by itself.
  CHECK(cam.poll(f) == CameraPoll::kNoFrame);
  CHECK_EQUAL(4U, dev.queued());
}

TEST(CameraV4l2, MoreBuffersThanItCanMapAreNotAnError) {
  FakeV4l2Config fc;
  fc.max_buffers = 12;
  fc.min_buffers = 10;  // a driver whose minimum is above CameraV4l2::kMaxBuffers
  FakeV4l2Device dev(fc);
  CameraV4l2 cam(config, clock, &dev);
  CHECK_TRUE_TEXT(cam.init(), cam.error());
  CHECK_EQUAL(8U, cam.buffers());
  CHECK_EQUAL(8U, dev.mapped());
  CHECK_EQUAL(1U, cam.surplus_buffer_grants());
  CHECK_TRUE(dev.capture());
  Frame f;
  CHECK(cam.poll(f) == CameraPoll::kFrame);
}

TEST(CameraV4l2, ErrorFlaggedAndShortFramesAreDroppedAndRequeued) {
  FakeV4l2Device dev;
  CameraV4l2 cam(config, clock, &dev);
  CHECK_TRUE(cam.init());
  CHECK_TRUE(dev.capture(true));        // V4L2_BUF_FLAG_ERROR
  CHECK_TRUE(dev.capture(false, 100));  // truncated
  CHECK_TRUE(dev.capture());
  Frame f;
  CHECK(cam.poll(f) == CameraPoll::kFrame);
  CHECK_EQUAL(2U, f.sequence);
  CHECK_EQUAL(2U, cam.dropped_frames());
  CHECK_EQUAL(3U, dev.queued());  // both dropped buffers went back at once
}

TEST(CameraV4l2, AnInterruptedCallIsRetried) {
  FakeV4l2Device dev;
  CameraV4l2 cam(config, clock, &dev);
  CHECK_TRUE(cam.init());
  CHECK_TRUE(dev.capture());
  dev.interrupt_next_call();
  Frame f;
  CHECK(cam.poll(f) == CameraPoll::kFrame);
}

TEST(CameraV4l2, AnUnpluggedDeviceIsReopenedWithBackoff) {
  config.reopen_backoff_ms = 100;
  config.reopen_backoff_max_ms = 400;
  FakeV4l2Device dev;
  CameraV4l2 cam(config, clock, &dev);
  CHECK_TRUE(cam.init());
  CHECK_TRUE(dev.capture());
  Frame f;
  CHECK(cam.poll(f) == CameraPoll::kFrame);
  cam.release();
  dev.unplug();
  CHECK(cam.poll(f) == CameraPoll::kFault);
  STRCMP_CONTAINS("disappeared", cam.error());
  CHECK_FALSE(cam.streaming());
  CHECK_EQUAL(0U, dev.mapped());
  CHECK_EQUAL(0, dev.open_fds());
  // Attempts at +100 ms, then +200, +400, +400 (capped) while it stays away.
  const int expected_attempts[] = {0, 1, 1, 2, 2, 2, 2, 3};
  for (int step = 0; step < 8; ++step) {
    CHECK(cam.poll(f) == CameraPoll::kFault);
    CHECK_EQUAL(static_cast<unsigned>(expected_attempts[step]), cam.reopen_attempts());
    clock.advance_us(100000);
  }
  dev.plug();
  clock.advance_us(400000);
  CameraPoll r = CameraPoll::kFault;
  for (int i = 0; i < 10 && r == CameraPoll::kFault; ++i) r = cam.poll(f);
  CHECK(r == CameraPoll::kNoFrame);
  CHECK_TRUE(cam.streaming());
  STRCMP_EQUAL("", cam.error());
  CHECK_TRUE(dev.capture());
  CHECK(cam.poll(f) == CameraPoll::kFrame);
}

// A UVC camera answers open, S_FMT, REQBUFS, STREAMON ... with USB control transfers that
// can take hundreds of milliseconds each: a re-open inside one 10 ms frame would overrun it.
TEST(CameraV4l2, AReopenTakesAtMostTwoDeviceCallsPerPoll) {
  config.reopen_backoff_ms = 100;
  FakeV4l2Device dev;
  CameraV4l2 cam(config, clock, &dev);
  CHECK_TRUE(cam.init());
  dev.unplug();
  Frame f;
  CHECK(cam.poll(f) == CameraPoll::kFault);
  dev.plug();
  clock.advance_us(100000);
  int polls = 0;
  CameraPoll r = CameraPoll::kFault;
  while (r == CameraPoll::kFault && polls < 20) {
    const int before = dev.slow_calls();
    r = cam.poll(f);
    CHECK_TEXT(dev.slow_calls() - before <= 2, "one poll() made more than two device calls");
    ++polls;
  }
  CHECK(r == CameraPoll::kNoFrame);
  CHECK_EQUAL(8, polls);  // open, format, buffers, four mmaps, stream on
  CHECK_EQUAL(1U, cam.reopen_attempts());
}

TEST(CameraV4l2, LosingTheDeviceWhileAFrameIsLentIsAFaultToo) {
  FakeV4l2Device dev;
  CameraV4l2 cam(config, clock, &dev);
  CHECK_TRUE(cam.init());
  CHECK_TRUE(dev.capture());
  Frame f;
  CHECK(cam.poll(f) == CameraPoll::kFrame);
  dev.unplug();
  CHECK(cam.poll(f) == CameraPoll::kFault);  // re-queueing the lent buffer fails: ENODEV
  STRCMP_CONTAINS("No such device", cam.error());
  CHECK_EQUAL(0U, dev.mapped());
}

TEST(CameraV4l2, ADeviceMissingAtStartIsPickedUpLater) {
  FakeV4l2Device dev;
  dev.unplug();
  CameraV4l2 cam(config, clock, &dev);
  CHECK_FALSE(cam.init());
  STRCMP_CONTAINS("cannot open", cam.error());
  dev.plug();
  Frame f;
  CHECK(cam.poll(f) == CameraPoll::kFault);  // still backing off
  clock.advance_us(300000);
  CameraPoll r = CameraPoll::kFault;
  for (int i = 0; i < 10 && r == CameraPoll::kFault; ++i) r = cam.poll(f);
  CHECK(r == CameraPoll::kNoFrame);
  CHECK_TRUE(cam.streaming());
}

TEST(CameraV4l2, PollingAndReleasingDoNotAllocate) {
  FakeV4l2Device dev;
  CameraV4l2 cam(config, clock, &dev);
  CHECK_TRUE(cam.init());
  Frame f;
  for (int i = 0; i < 20; ++i) {
    CHECK_TRUE(dev.capture(i % 5 == 0));  // the fake allocates; the driver must not
    CameraPoll r = CameraPoll::kFault;
    CHECK_NO_ALLOCATION(r = cam.poll(f));
    CHECK(r == (i % 5 == 0 ? CameraPoll::kNoFrame : CameraPoll::kFrame));
    CHECK_NO_ALLOCATION(cam.release());
  }
}
