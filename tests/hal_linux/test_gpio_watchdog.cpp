// Tests of the libgpiod wrappers' failure paths (no GPIO chip in the test kernel) and of
// WatchdogLinux through its system-call seam.
#include <linux/watchdog.h>

#include <cerrno>
#include <cstdint>
#include <string>
#include <vector>

#include "fake_clock.h"
#include "hal/linux/gpio_gpiod.h"
#include "hal/linux/watchdog_linux.h"

#include "CppUTest/TestHarness.h"
#include "alloc_guard.h"

using boticelli::fakes::FakeClock;
using boticelli::hal_linux::DigitalInGpiod;
using boticelli::hal_linux::DigitalOutGpiod;
using boticelli::hal_linux::GpioLineConfig;
using boticelli::hal_linux::WatchdogConfig;
using boticelli::hal_linux::WatchdogIo;
using boticelli::hal_linux::WatchdogLinux;

TEST_GROUP(GpioGpiod){};

TEST(GpioGpiod, AMissingChipIsAClearErrorAndAnEstopInputFailsSafe) {
  FakeClock clock;
  GpioLineConfig c;
  c.chip = "/nonexistent/gpiochip9";
  c.offset = 17;
  DigitalInGpiod estop(c, clock, true);
  CHECK_FALSE(estop.init());
  STRCMP_CONTAINS("gpio /nonexistent/gpiochip9:17", estop.error());
  CHECK_TRUE(estop.read());  // fail safe: treated as pressed
  CHECK_TRUE(estop.activated_since_last_poll());
  DigitalInGpiod bumper(c, clock, false);
  CHECK_FALSE(bumper.init());
  CHECK_FALSE(bumper.read());
}

TEST(GpioGpiod, AMissingChipForTheLedIsAClearErrorAndWritesAreHarmless) {
  GpioLineConfig c;
  c.chip = "/nonexistent/gpiochip9";
  DigitalOutGpiod led(c);
  CHECK_FALSE(led.init());
  STRCMP_CONTAINS("cannot open the chip", led.error());
  led.write(true);
  led.write(false);
}

namespace {

// Records the watchdog system calls; can make SETTIMEOUT answer another value or fail.
class FakeWatchdogIo final : public WatchdogIo {
 public:
  int open(const char*) override {
    if (fail_open) {
      errno = ENOENT;
      return -1;
    }
    log.push_back("open");
    open_ = true;
    return 7;
  }
  int ioctl(int fd, unsigned long request, int* arg) override {
    if (fd != 7 || !open_) {
      errno = EBADF;
      return -1;
    }
    if (request == WDIOC_SETTIMEOUT) {
      log.push_back("settimeout " + std::to_string(*arg));
      if (fail_settimeout) {
        errno = EINVAL;
        return -1;
      }
      if (driver_timeout_s > 0) *arg = driver_timeout_s;
      return 0;
    }
    if (request == WDIOC_KEEPALIVE) {
      if (refuse_keepalive) {
        errno = EIO;
        return -1;
      }
      ++keepalives;
      return 0;
    }
    errno = ENOTTY;
    return -1;
  }
  long write(int fd, const void* data, std::size_t size) override {
    if (fd != 7 || !open_) return -1;
    if (refuse_keepalive && size == 1 && *static_cast<const char*>(data) == 'k') {
      errno = EIO;
      return -1;
    }
    log.push_back("write " + std::string(static_cast<const char*>(data), size));
    return static_cast<long>(size);
  }
  int close(int) override {
    log.push_back("close");
    open_ = false;
    return 0;
  }
  std::vector<std::string> log;
  int keepalives = 0;
  bool fail_open = false;
  bool fail_settimeout = false;
  bool refuse_keepalive = false;  // the ioctl and the write both fail (EIO)
  int driver_timeout_s = 0;

 private:
  bool open_ = false;
};

std::string joined(const std::vector<std::string>& v) {
  std::string s;
  for (const std::string& x : v) s += (s.empty() ? "" : "|") + x;
  return s;
}

}  // namespace

TEST_GROUP(WatchdogLinux){};

TEST(WatchdogLinux, StartSetsTheTimeoutRoundedUpToSeconds) {
  FakeWatchdogIo io;
  WatchdogLinux wd(WatchdogConfig{}, &io);
  CHECK_TRUE(wd.start(1500));
  STRCMP_EQUAL("open|settimeout 2", joined(io.log).c_str());
  CHECK_EQUAL(2, wd.timeout_s());
  CHECK_TRUE(wd.armed());
}

TEST(WatchdogLinux, TheTimeoutTheDriverChoseIsReported) {
  FakeWatchdogIo io;
  io.driver_timeout_s = 15;
  WatchdogLinux wd(WatchdogConfig{}, &io);
  CHECK_TRUE(wd.start(10000));
  CHECK_EQUAL(15, wd.timeout_s());
}

TEST(WatchdogLinux, KickIsAKeepAliveIoctlAndDoesNotAllocate) {
  FakeWatchdogIo io;
  WatchdogLinux wd(WatchdogConfig{}, &io);
  CHECK_TRUE(wd.kick());  // not started: nothing to keep alive
  CHECK_EQUAL(0, io.keepalives);
  CHECK_TRUE(wd.start(1000));
  CHECK_NO_ALLOCATION(wd.kick());
  CHECK_EQUAL(1, io.keepalives);
}

TEST(WatchdogLinux, AKeepAliveRefusedByIoctlAndWriteIsReportedWithTheError) {
  FakeWatchdogIo io;
  WatchdogLinux wd(WatchdogConfig{}, &io);
  CHECK_TRUE(wd.start(1000));
  io.refuse_keepalive = true;
  CHECK_FALSE(wd.kick());
  STRCMP_CONTAINS("keep-alive refused", wd.error());
  STRCMP_CONTAINS("Input/output error", wd.error());
  io.refuse_keepalive = false;
  CHECK_TRUE(wd.kick());
  CHECK_EQUAL(1, io.keepalives);
}

TEST(WatchdogLinux, StopIsAMagicClose) {
  FakeWatchdogIo io;
  WatchdogLinux wd(WatchdogConfig{}, &io);
  CHECK_TRUE(wd.start(1000));
  wd.stop();
  STRCMP_EQUAL("open|settimeout 1|write V|close", joined(io.log).c_str());
  CHECK_FALSE(wd.armed());
  wd.stop();  // twice is harmless
  CHECK_EQUAL(4U, io.log.size());
}

TEST(WatchdogLinux, AFailedTimeoutDisarmsAndReportsTheError) {
  FakeWatchdogIo io;
  io.fail_settimeout = true;
  WatchdogLinux wd(WatchdogConfig{}, &io);
  CHECK_FALSE(wd.start(1000));
  STRCMP_CONTAINS("refused a timeout of 1 s", wd.error());
  STRCMP_EQUAL("open|settimeout 1|write V|close", joined(io.log).c_str());
}

TEST(WatchdogLinux, AMissingDeviceIsAClearError) {
  FakeWatchdogIo io;
  io.fail_open = true;
  WatchdogLinux wd(WatchdogConfig{}, &io);
  CHECK_FALSE(wd.start(1000));
  STRCMP_CONTAINS("cannot open", wd.error());
  CHECK_FALSE(wd.start(0));
  STRCMP_CONTAINS("zero timeout", wd.error());
}

TEST(WatchdogLinux, DestructionDisarms) {
  FakeWatchdogIo io;
  {
    WatchdogLinux wd(WatchdogConfig{}, &io);
    CHECK_TRUE(wd.start(1000));
  }
  STRCMP_EQUAL("write V", io.log[2].c_str());
}
