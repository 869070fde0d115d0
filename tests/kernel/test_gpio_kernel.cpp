// Kernel in the loop, GPIO: the e-stop, bumper and LED drivers on a gpio-sim chip, whose lines
// the test drives through the chip's sysfs attributes (sim_gpioN/pull, sim_gpioN/value).
#include <unistd.h>

#include <cstdint>
#include <cstdio>
#include <cstdlib>

#include "hal/linux/gpio_gpiod.h"
#include "kernel_rig.h"

#include "CppUTest/TestHarness.h"
#include "alloc_guard.h"

using boticelli::hal_linux::DigitalInGpiod;
using boticelli::hal_linux::DigitalOutGpiod;
using boticelli::hal_linux::GpioLineConfig;
using boticelli::kernel_test::Cycles;
using boticelli::kernel_test::read_text;
using boticelli::kernel_test::write_text;

namespace {

// The chip's device directory, set by the guest's init.
const char* chip_dir() {
  const char* d = std::getenv("GPIO_SIM_LINES");
  return d != nullptr ? d : "/sys/devices/platform/gpio-sim.0/gpiochip0";
}

void set_level(unsigned offset, bool high) {
  char path[160];
  std::snprintf(path, sizeof path, "%s/sim_gpio%u/pull", chip_dir(), offset);
  CHECK_TRUE_TEXT(write_text(path, high ? "pull-up" : "pull-down"), path);
}

int line_value(unsigned offset) {
  char path[160];
  char text[8];
  std::snprintf(path, sizeof path, "%s/sim_gpio%u/value", chip_dir(), offset);
  CHECK_TRUE_TEXT(read_text(path, text, sizeof text), path);
  return std::atoi(text);
}

GpioLineConfig line(unsigned offset, bool active_low = false) {
  GpioLineConfig c;
  c.chip = "gpiochip0";
  c.offset = offset;
  c.active_low = active_low;
  c.debounce_ms = 10;
  return c;
}

// Toggles the line `toggles` times, 1 ms apart (so that each edge reaches the event queue;
// the queue holds 16), without polling in between.
void bounce(unsigned offset, bool from_high, int toggles) {
  bool high = from_high;
  for (int i = 0; i < toggles; ++i) {
    high = !high;
    set_level(offset, high);
    ::usleep(1000);
  }
}

}  // namespace

TEST_GROUP(KernelGpio) {
  Cycles cycles;
  // Polls every 10 ms for `ms` (past the debounce), returning the last level read.
  bool poll_for(DigitalInGpiod & in, int ms) {
    bool level = false;
    for (int i = 0; i < ms / 10; ++i) {
      level = in.read();
      cycles.wait();
    }
    return level;
  }
};

TEST(KernelGpio, AnEstopPressIsSeenInTheNextPollAndLatched) {
  set_level(0, false);
  DigitalInGpiod estop(line(0), cycles.clock(), true);
  CHECK_TRUE_TEXT(estop.init(), estop.error());
  CHECK_FALSE(estop.read());
  set_level(0, true);
  ::usleep(1000);
  CHECK_TRUE(estop.activated_since_last_poll());
  CHECK_TRUE(estop.read());
  set_level(0, false);
  CHECK_FALSE(poll_for(estop, 50));
  CHECK_FALSE(estop.activated_since_last_poll());
}

TEST(KernelGpio, AContactBouncingMoreThan16TimesBetweenTwoPollsEndsAtTheRightLevel) {
  set_level(0, false);
  DigitalInGpiod estop(line(0), cycles.clock(), true);
  CHECK_TRUE_TEXT(estop.init(), estop.error());
  CHECK_FALSE(estop.read());
  // 41 edges from low end high; the queue keeps the first 16, the 16th a falling one.
  bounce(0, false, 41);
  CHECK_EQUAL(1, line_value(0));
  const std::uint32_t before = estop.events();
  bool level = false;
  CHECK_NO_ALLOCATION(level = estop.read());  // 16 events and the level in one poll
  CHECK_TRUE(level);
  CHECK_TRUE(poll_for(estop, 50));
  CHECK_EQUAL_TEXT(16U, estop.events() - before, "the bounce did not fill the kernel's queue");
  // And back: 41 edges from high end low; the 16th kept is a rising one.
  bounce(0, true, 41);
  CHECK_EQUAL(0, line_value(0));
  const std::uint32_t middle = estop.events();
  CHECK_FALSE(poll_for(estop, 50));
  CHECK_EQUAL_TEXT(16U, estop.events() - middle, "the bounce did not fill the kernel's queue");
}

TEST(KernelGpio, EdgesAreDebouncedAtTheirKernelTimestampsNotAtThePoll) {
  set_level(0, false);
  DigitalInGpiod estop(line(0), cycles.clock(), true);
  CHECK_TRUE_TEXT(estop.init(), estop.error());
  CHECK_FALSE(estop.read());
  set_level(0, true);  // a 3 ms press ...
  ::usleep(3000);
  set_level(0, false);
  ::usleep(30000);                                // ... seen by a poll 30 ms later
  CHECK_TRUE(estop.activated_since_last_poll());  // latched, so not missed
  // Released 27 ms ago, past the 10 ms debounce: inactive now. Debounced at the poll's time,
  // the release would still be held back for 10 ms.
  CHECK_FALSE(estop.read());
}

TEST(KernelGpio, TheBumperIsActiveLowWithItsLinePulledDown) {
  set_level(1, true);
  DigitalInGpiod bumper(line(1, true), cycles.clock());
  CHECK_TRUE_TEXT(bumper.init(), bumper.error());
  CHECK_FALSE(bumper.read());
  set_level(1, false);
  CHECK_TRUE(poll_for(bumper, 20));
  set_level(1, true);
  CHECK_FALSE(poll_for(bumper, 50));
}

TEST(KernelGpio, TheStatusLedDrivesItsLineWithItsPolarity) {
  DigitalOutGpiod led(line(2));
  CHECK_TRUE_TEXT(led.init(), led.error());
  CHECK_EQUAL(0, line_value(2));
  led.write(true);
  CHECK_EQUAL(1, line_value(2));
  led.write(false);
  CHECK_EQUAL(0, line_value(2));
  DigitalOutGpiod inverted(line(3, true));
  CHECK_TRUE_TEXT(inverted.init(), inverted.error());
  CHECK_EQUAL(1, line_value(3));  // inactive = high
  inverted.write(true);
  CHECK_EQUAL(0, line_value(3));
}

TEST(KernelGpio, AnEstopOnAMissingChipFailsSafe) {
  GpioLineConfig c = line(0);
  c.chip = "gpiochip7";
  DigitalInGpiod estop(c, cycles.clock(), true);
  CHECK_FALSE(estop.init());
  CHECK_TRUE(estop.read());  // an e-stop that cannot be read counts as pressed
}
