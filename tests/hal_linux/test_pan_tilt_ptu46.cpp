// Tests of PanTiltPtu46 against the PTU-D46 emulator on a pseudo-terminal pair.
#include <poll.h>

#include <cmath>
#include <cstdint>
#include <functional>
#include <memory>
#include <string>

#include "fake_clock.h"
#include "fake_serial_port.h"
#include "hal/linux/pan_tilt_ptu46.h"
#include "hal/linux/serial_termios.h"
#include "ptu46_emulator.h"

#include "CppUTest/TestHarness.h"
#include "alloc_guard.h"

using boticelli::fakes::FakeClock;
using boticelli::fakes::FakeSerialPort;
using boticelli::fakes::Ptu46Emulator;
using boticelli::fakes::Ptu46EmulatorConfig;
using boticelli::hal_linux::PanTiltPtu46;
using boticelli::hal_linux::PanTiltPtu46Config;
using boticelli::hal_linux::SerialConfig;
using boticelli::hal_linux::SerialTermios;

namespace {

constexpr double kPanArcsec = 185.1428;
constexpr double kTiltArcsec = 46.2857;
double pan_rad(int counts) {
  return counts * kPanArcsec / 3600.0 * M_PI / 180.0;
}
double tilt_rad(int counts) {
  return counts * kTiltArcsec / 3600.0 * M_PI / 180.0;
}

// One rig per test: emulator, port, fake clock and driver. Each step runs the driver and the
// emulator once, waits (bounded, 2 ms at most) for bytes on either side of the pty, and
// advances fake time by 1 ms, so timeouts are measured in fake time only.
struct Rig {
  explicit Rig(const PanTiltPtu46Config& cfg = rig_config(),
               const Ptu46EmulatorConfig& emu_cfg = {})
      : emu(emu_cfg), clock(1000000) {
    CHECK_TRUE(emu.open());
    port = std::make_unique<SerialTermios>(SerialConfig{emu.slave_path(), 9600});
    ptu = std::make_unique<PanTiltPtu46>(*port, clock, cfg);
  }
  static PanTiltPtu46Config rig_config() {
    PanTiltPtu46Config c;
    c.reply_timeout_ms = 200;
    c.retry_backoff_ms = 500;
    c.position_poll_ms = 20;
    return c;
  }
  void step() {
    ptu->update();
    emu.service(clock.peek_us());
    pollfd fds[2] = {{emu.master_fd(), POLLIN, 0}, {port->fd(), POLLIN, 0}};
    ::poll(fds, emu.master_fd() >= 0 ? 2 : 1, 2);
    clock.advance_us(1000);
  }
  bool run_until(const std::function<bool()>& done, int max_steps = 5000) {
    for (int i = 0; i < max_steps; ++i) {
      if (done()) return true;
      step();
    }
    return done();
  }
  bool start() {
    if (!ptu->init()) return false;
    return run_until([&] { return ptu->ready(); });
  }
  Ptu46Emulator emu;
  FakeClock clock;
  std::unique_ptr<SerialTermios> port;
  std::unique_ptr<PanTiltPtu46> ptu;
};

}  // namespace

TEST_GROUP(PanTiltPtu46){};

TEST(PanTiltPtu46, StartUpSwitchesToTerseWithoutEchoAndQueriesResolutionAndLimits) {
  Rig rig;
  CHECK_TRUE_TEXT(rig.start(), rig.ptu->error());
  CHECK_TRUE(rig.emu.terse());
  CHECK_FALSE(rig.emu.echo());
  for (const char* c : {"FT", "ED", "CI", "PR", "TR", "PN", "PX", "TN", "TX", "PU", "TU"}) {
    CHECK_EQUAL_TEXT(1U, rig.emu.count_commands(c), c);
  }
  const auto lim = rig.ptu->limits();
  DOUBLES_EQUAL(pan_rad(-3090), lim.pan_min_rad, 1e-5);
  DOUBLES_EQUAL(pan_rad(3090), lim.pan_max_rad, 1e-5);
  DOUBLES_EQUAL(tilt_rad(-907), lim.tilt_min_rad, 1e-5);
  DOUBLES_EQUAL(tilt_rad(604), lim.tilt_max_rad, 1e-5);
  DOUBLES_EQUAL(pan_rad(1), lim.pan_resolution_rad, 1e-7);
  CHECK_FALSE(rig.ptu->state().fault);
  STRCMP_EQUAL("", rig.ptu->error());
}

TEST(PanTiltPtu46, AMoveIsSentInCountsAndCompletesWhenTheUnitArrives) {
  Rig rig;
  CHECK_TRUE(rig.start());
  CHECK_TRUE(
      rig.ptu->move_to(static_cast<float>(pan_rad(500)), static_cast<float>(tilt_rad(-200))));
  CHECK_TRUE(rig.ptu->state().moving);
  CHECK_TRUE(rig.run_until([&] { return !rig.ptu->state().moving; }));
  CHECK_EQUAL(1U, rig.emu.count_commands("PP500"));
  CHECK_EQUAL(1U, rig.emu.count_commands("TP-200"));
  CHECK_EQUAL(500, rig.ptu->pan_counts());
  CHECK_EQUAL(-200, rig.ptu->tilt_counts());
  DOUBLES_EQUAL(pan_rad(500), rig.ptu->state().pan_rad, 1e-5);
  // 500 counts at 1000 counts/s take 0.5 s of (fake) time: the move was not instantaneous.
  CHECK(rig.clock.peek_us() > 1000000U + 500000U);
}

TEST(PanTiltPtu46, AMoveOutsideTheLimitsIsRefusedWithoutSendingAnything) {
  Rig rig;
  CHECK_TRUE(rig.start());
  const std::size_t before = rig.emu.commands().size();
  CHECK_FALSE(rig.ptu->move_to(static_cast<float>(pan_rad(3200)), 0.0F));
  CHECK_FALSE(rig.ptu->move_to(0.0F, static_cast<float>(tilt_rad(-1000))));
  CHECK_FALSE(rig.ptu->move_to(NAN, 0.0F));
  for (int i = 0; i < 50; ++i) rig.step();
  CHECK_EQUAL(before, rig.emu.commands().size());
}

TEST(PanTiltPtu46, MovesBeforeStartUpAreRefused) {
  Rig rig;
  CHECK_FALSE(rig.ptu->move_to(0.0F, 0.0F));
  CHECK_FALSE(rig.ptu->set_speed(0.1F, 0.1F));
}

TEST(PanTiltPtu46, SpeedsAreConvertedAndCheckedAgainstTheUpperLimit) {
  Rig rig;
  CHECK_TRUE(rig.start());
  CHECK_TRUE(
      rig.ptu->set_speed(static_cast<float>(pan_rad(2000)), static_cast<float>(tilt_rad(500))));
  CHECK_TRUE(rig.run_until([&] { return rig.emu.tilt_speed() == 500; }));
  CHECK_EQUAL(2000, rig.emu.pan_speed());
  CHECK_FALSE(rig.ptu->set_speed(static_cast<float>(pan_rad(3000)), 0.1F));  // above PU 2902
  CHECK_FALSE(rig.ptu->set_speed(-0.1F, 0.1F));
}

TEST(PanTiltPtu46, HaltStopsBothAxesWhereTheyAre) {
  Rig rig;
  CHECK_TRUE(rig.start());
  CHECK_TRUE(rig.ptu->move_to(static_cast<float>(pan_rad(3000)), 0.0F));
  CHECK_TRUE(rig.run_until([&] { return rig.emu.pan_counts() > 100; }));
  rig.ptu->halt();
  CHECK_TRUE(
      rig.run_until([&] { return !rig.ptu->state().moving && rig.emu.count_commands("H") == 1; }));
  for (int i = 0; i < 100; ++i) rig.step();
  const int stopped_at = rig.emu.pan_counts();
  CHECK(stopped_at > 100 && stopped_at < 3000);
  CHECK_EQUAL(stopped_at, rig.ptu->pan_counts());
}

TEST(PanTiltPtu46, AnErrorReplyToAMoveIsReportedAndTheDriverCarriesOn) {
  Rig rig;
  CHECK_TRUE(rig.start());
  rig.emu.answer_next_with_error("Illegal Command Argument");
  CHECK_TRUE(rig.ptu->move_to(static_cast<float>(pan_rad(100)), 0.0F));
  CHECK_TRUE(rig.run_until([&] { return rig.ptu->state().fault; }));
  STRCMP_CONTAINS("PP100", rig.ptu->error());
  STRCMP_CONTAINS("Illegal Command Argument", rig.ptu->error());
  CHECK_TRUE(rig.ptu->ready());
  CHECK_TRUE(rig.ptu->move_to(static_cast<float>(pan_rad(50)), 0.0F));
  CHECK_FALSE(rig.ptu->state().fault);
  CHECK_TRUE(rig.run_until([&] { return !rig.ptu->state().moving; }));
  CHECK_EQUAL(50, rig.ptu->pan_counts());
}

TEST(PanTiltPtu46, AnUnsolicitedLimitReportFaultsThatAxis) {
  Rig rig;
  CHECK_TRUE(rig.start());
  rig.emu.hit_pan_limit();
  CHECK_TRUE(rig.run_until([&] { return rig.ptu->state().fault; }));
  STRCMP_CONTAINS("pan axis hit a limit", rig.ptu->error());
  CHECK_TRUE(rig.run_until([&] { return rig.ptu->pan_counts() == 3090; }));  // re-queried
}

TEST(PanTiltPtu46, SilenceFromTheUnitIsATimeoutAndTheDriverReinitialises) {
  Rig rig;
  CHECK_TRUE(rig.start());
  rig.emu.set_silent(true);
  CHECK_TRUE(rig.ptu->move_to(static_cast<float>(pan_rad(10)), 0.0F));
  const std::uint64_t t0 = rig.clock.peek_us();
  CHECK_TRUE(rig.run_until([&] { return rig.ptu->state().fault; }));
  STRCMP_CONTAINS("no reply to 'PP10 '", rig.ptu->error());
  CHECK(rig.clock.peek_us() - t0 >= 200000U);  // not before the configured timeout
  CHECK_FALSE(rig.ptu->ready());
  CHECK_EQUAL(1U, rig.ptu->timeouts());
  rig.emu.set_silent(false);
  CHECK_TRUE(rig.run_until([&] { return rig.ptu->ready(); }));
  CHECK_EQUAL(2U, rig.emu.count_commands("FT"));
  CHECK_FALSE(rig.ptu->state().fault);
}

TEST(PanTiltPtu46, GarbageOnTheLineIsCountedAndSkipped) {
  Rig rig;
  CHECK_TRUE(rig.start());
  rig.emu.send_raw("\x01\x02zz\xff\r\nnoise\r\n");
  CHECK_TRUE(rig.ptu->move_to(static_cast<float>(pan_rad(-30)), static_cast<float>(tilt_rad(20))));
  CHECK_TRUE(rig.run_until([&] { return !rig.ptu->state().moving; }));
  CHECK(rig.ptu->garbage_lines() >= 2U);
  CHECK_FALSE(rig.ptu->state().fault);
  CHECK_EQUAL(-30, rig.ptu->pan_counts());
  CHECK_EQUAL(20, rig.ptu->tilt_counts());
}

TEST(PanTiltPtu46, ResetRunsToTheLimitsAndReportsHomeAtTheEnd) {
  Ptu46EmulatorConfig ec;
  ec.reset_duration_us = 300000;
  Rig rig(Rig::rig_config(), ec);
  CHECK_TRUE(rig.start());
  CHECK_TRUE(rig.ptu->move_to(static_cast<float>(pan_rad(40)), 0.0F));
  CHECK_TRUE(rig.run_until([&] { return !rig.ptu->state().moving; }));
  CHECK_TRUE(rig.ptu->reset());
  CHECK_TRUE(rig.ptu->state().moving);
  CHECK_TRUE(rig.run_until([&] { return !rig.ptu->state().moving; }));
  CHECK_FALSE_TEXT(rig.ptu->state().fault, rig.ptu->error());  // the !T!T!P!P are expected
  CHECK_TRUE(rig.run_until([&] { return rig.ptu->pan_counts() == 0; }));
}

TEST(PanTiltPtu46, AwaitIsAnsweredWhenTheMoveHasCompleted) {
  Rig rig;
  CHECK_TRUE(rig.start());
  CHECK_TRUE(rig.ptu->move_to(static_cast<float>(pan_rad(300)), 0.0F));
  CHECK_TRUE(rig.ptu->await_move());
  CHECK_TRUE(
      rig.run_until([&] { return !rig.ptu->state().moving && rig.emu.count_commands("A") == 1; }));
  CHECK_EQUAL(300, rig.emu.pan_counts());
  CHECK_FALSE(rig.ptu->state().fault);
}

TEST(PanTiltPtu46, AnUnpluggedUnitIsAFaultNotACrash) {
  Rig rig;
  CHECK_TRUE(rig.start());
  rig.emu.unplug();
  CHECK_TRUE(rig.run_until([&] { return rig.ptu->state().fault; }));
  STRCMP_CONTAINS("serial read failed", rig.ptu->error());
  CHECK_FALSE(rig.ptu->move_to(0.0F, 0.0F));
}

TEST(PanTiltPtu46, TheCyclicCallsDoNotAllocate) {
  Rig rig;
  CHECK_TRUE(rig.start());
  bool ok = false;
  CHECK_NO_ALLOCATION(ok = rig.ptu->move_to(static_cast<float>(pan_rad(20)), 0.0F));
  CHECK_TRUE(ok);
  for (int i = 0; i < 300; ++i) {
    CHECK_NO_ALLOCATION(rig.ptu->update());
    CHECK_NO_ALLOCATION((void)rig.ptu->state());
    rig.emu.service(rig.clock.peek_us());
    pollfd fd{rig.port->fd(), POLLIN, 0};
    ::poll(&fd, 1, 2);
    rig.clock.advance_us(1000);
  }
  CHECK_FALSE(rig.ptu->state().moving);
  CHECK_NO_ALLOCATION(rig.ptu->halt());
}

TEST(PanTiltPtu46, OneCommandIsOutstandingAtATimeAndPartialWritesAreCompleted) {
  FakeSerialPort port;
  FakeClock clock;
  PanTiltPtu46 ptu(port, clock);
  port.set_write_limit(2);  // a nearly full line: two bytes per write
  CHECK_TRUE(ptu.init());
  for (int i = 0; i < 5; ++i) ptu.update();
  STRCMP_EQUAL("FT ", port.written().c_str());  // complete, and nothing after it yet
  port.feed("*\r\n");
  for (int i = 0; i < 5; ++i) ptu.update();
  STRCMP_EQUAL("FT ED ", port.written().c_str());
  port.feed("* 12\r\n");  // a reply with a value where none is needed is still an OK
  for (int i = 0; i < 5; ++i) ptu.update();
  STRCMP_EQUAL("FT ED CI ", port.written().c_str());
  port.feed("!");  // half a line: not a reply yet
  for (int i = 0; i < 5; ++i) ptu.update();
  STRCMP_EQUAL("FT ED CI ", port.written().c_str());
  port.feed(" Illegal Command\r\n");
  ptu.update();
  CHECK_TRUE(ptu.state().fault);  // an error during start-up is a fault ...
  STRCMP_CONTAINS("'CI ' rejected: ! Illegal Command", ptu.error());
  clock.advance_us(2000001);  // ... and the sequence starts again after the backoff
  port.clear_written();
  port.set_write_limit(100);
  ptu.update();
  STRCMP_EQUAL("FT ", port.written().c_str());
}

TEST(PanTiltPtu46, ImplausibleStartUpAnswersAreRefused) {
  FakeSerialPort port;
  FakeClock clock;
  PanTiltPtu46 ptu(port, clock);
  CHECK_TRUE(ptu.init());
  const char* answers[] = {"*", "*", "*", "* 0"};  // a resolution of 0 arc-seconds per count
  for (const char* a : answers) {
    ptu.update();
    port.feed(a);
    port.feed("\r\n");
  }
  ptu.update();
  CHECK_TRUE(ptu.state().fault);
  STRCMP_CONTAINS("implausible resolution", ptu.error());
  CHECK_FALSE(ptu.ready());
}

TEST(PanTiltPtu46, ALimitAnswerOutsideTheQueriedRangeIsAStartUpFault) {
  FakeSerialPort port;
  FakeClock clock;
  PanTiltPtu46 ptu(port, clock);
  CHECK_TRUE(ptu.init());
  // FT ED CI PR TR PN PX TN TX PU TU PP TP; PN answers above PX.
  const char* answers[] = {"*",     "*",    "*",      "* 185.1428", "* 46.2857", "* 100", "* -100",
                           "* -10", "* 10", "* 2000", "* 2000",     "* 0",       "* 0"};
  for (const char* a : answers) {
    ptu.update();
    port.feed(a);
    port.feed("\r\n");
  }
  ptu.update();
  CHECK_FALSE(ptu.ready());
  STRCMP_CONTAINS("inconsistent limits", ptu.error());
}

TEST(PanTiltPtu46, ALimitReportWhileAMoveIsInFlightDoesNotShiftTheLaterReplies) {
  FakeSerialPort port;
  FakeClock clock;
  PanTiltPtu46 ptu(port, clock);
  CHECK_TRUE(ptu.init());
  // The start-up sequence, answered one command at a time.
  for (const char* reply : {"*", "*", "*", "* 185.1428", "* 46.2857", "* -3090", "* 3090", "* -907",
                            "* 604", "* 2902", "* 2902", "* 0", "* 0"}) {
    ptu.update();
    port.feed(reply);
    port.feed("\r\n");
  }
  ptu.update();
  CHECK_TRUE(ptu.ready());
  CHECK_TRUE(ptu.move_to(static_cast<float>(pan_rad(100)), static_cast<float>(tilt_rad(50))));
  port.clear_written();
  ptu.update();
  STRCMP_EQUAL("PP100 ", port.written().c_str());
  port.feed("!P\r\n");  // the pan axis reports its limit while PP is in flight ...
  ptu.update();
  port.feed("*\r\n");  // ... and the unit still answers PP
  ptu.update();
  port.feed("*\r\n");  // TP's answer
  ptu.update();
  port.feed("* 3090\r\n");  // the position query after the limit report
  ptu.update();
  // Had PP's '*' been taken for TP's, TP's '*' would have answered the position query,
  // which needs a number: a fault and a re-initialisation.
  STRNCMP_EQUAL("PP100 TP50 PP ", port.written().c_str(), 14);
  CHECK_TRUE(ptu.ready());
  STRCMP_CONTAINS("pan axis hit a limit", ptu.error());
  CHECK_EQUAL(3090, ptu.pan_counts());
}

TEST(PanTiltPtu46, AMoveCommandedEveryCycleStillHasItsPositionPolled) {
  Rig rig;
  CHECK_TRUE(rig.start());
  const auto target = static_cast<float>(pan_rad(300));
  // The mission's controller may repeat its target every frame.
  CHECK_TRUE(rig.run_until(
      [&] {
        rig.ptu->move_to(target, 0.0F);
        return !rig.ptu->state().moving && rig.ptu->pan_counts() == 300;
      },
      3000));
  CHECK_EQUAL(300, rig.emu.pan_counts());
}

TEST(PanTiltPtu46, AUnitThatFallsSilentWhileIdleIsAFault) {
  Rig rig;
  CHECK_TRUE(rig.start());
  rig.emu.set_silent(true);
  // No command from the firmware at all: the driver's own liveness query must notice.
  const std::uint64_t t0 = rig.clock.peek_us();
  CHECK_TRUE(rig.run_until([&] { return rig.ptu->state().fault; }, 3000));
  STRCMP_CONTAINS("no reply to 'PP '", rig.ptu->error());
  CHECK(rig.clock.peek_us() - t0 <= 1300000U);  // idle_query_ms + reply_timeout_ms
}
