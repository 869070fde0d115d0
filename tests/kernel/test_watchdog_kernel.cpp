// Kernel in the loop, watchdog: WatchdogLinux on softdog's /dev/watchdog (keepalive, magic
// close, a busy device, a refused timeout, and the reset when the kicks stop).
#include <fcntl.h>
#include <unistd.h>

#include <cstdio>
#include <cstring>

#include "hal/linux/watchdog_linux.h"
#include "kernel_rig.h"

#include "CppUTest/TestHarness.h"

using boticelli::hal_linux::WatchdogLinux;
using boticelli::kernel_test::Cycles;

namespace {

// softdog was loaded with soft_margin=5; the tests set their own timeouts.
void run_kicking(WatchdogLinux& wd, int ms) {
  Cycles cycles(100000);  // a kick every 100 ms
  for (int i = 0; i < ms / 100; ++i) {
    wd.kick();
    cycles.wait();
  }
}

void sleep_ms(int ms) {
  Cycles cycles(static_cast<std::uint32_t>(ms) * 1000U);
  cycles.wait();  // the first wait is one whole period
}

}  // namespace

TEST_GROUP(KernelWatchdog){};

TEST(KernelWatchdog, KeepalivesHoldOffTheResetPastTheTimeout) {
  WatchdogLinux wd;
  CHECK_TRUE_TEXT(wd.start(1000), wd.error());
  CHECK_EQUAL(1, wd.timeout_s());  // softdog takes any whole number of seconds
  run_kicking(wd, 2500);           // 2.5 times the timeout: only the kicks keep us alive
  STRCMP_EQUAL("", wd.error());
  wd.stop();
}

TEST(KernelWatchdog, TheMagicCloseDisarmsIt) {
  WatchdogLinux wd;
  CHECK_TRUE_TEXT(wd.start(1000), wd.error());
  wd.kick();
  wd.stop();
  STRCMP_EQUAL("", wd.error());
  sleep_ms(1500);  // past the 1 s timeout: still running, so it was disarmed
}

TEST(KernelWatchdog, ASecondOpenerIsToldTheDeviceIsBusy) {
  WatchdogLinux first;
  CHECK_TRUE_TEXT(first.start(3000), first.error());
  WatchdogLinux second;
  CHECK_FALSE(second.start(3000));
  STRCMP_CONTAINS("/dev/watchdog is busy (another process holds it", second.error());
  first.stop();
}

TEST(KernelWatchdog, ATimeoutTheDeviceRefusesIsReportedWithTheAskedValue) {
  WatchdogLinux wd;
  CHECK_FALSE(wd.start(70000U * 1000U));  // softdog's range ends at 65535 s
  STRCMP_CONTAINS("70000 s", wd.error());
  CHECK_FALSE(wd.armed());  // disarmed again by the magic close
}

// Run last, alone: the guest must be reset by softdog within the timeout after the last
// keepalive. The test writes the moment of its last keepalive to the kernel log, so the
// host (run.sh) can compare it with softdog's "Initiating system reboot" on the same clock.
// Reaching the end of the sleep fails the test.
TEST_GROUP(KernelWatchdogReset){};

TEST(KernelWatchdogReset, AFirmwareThatStopsKickingGetsTheMachineReset) {
  WatchdogLinux wd;
  CHECK_TRUE_TEXT(wd.start(2000), wd.error());
  run_kicking(wd, 300);
  wd.kick();
  const int kmsg = ::open("/dev/kmsg", O_WRONLY | O_CLOEXEC);
  CHECK(kmsg >= 0);
  const char marker[] = "<2>boticelli-kernel-test: last watchdog keepalive, timeout 2 s\n";
  CHECK(::write(kmsg, marker, std::strlen(marker)) > 0);
  ::close(kmsg);
  sleep_ms(6000);
  FAIL("still running 6 s after the last keepalive of a 2 s watchdog");
}
