// Tests of ClockPosix (CLOCK_MONOTONIC) and SerialTermios / SerialStdio on a pseudo-terminal.
#include <dirent.h>
#include <fcntl.h>
#include <signal.h>
#include <sys/time.h>
#include <unistd.h>

#include <cerrno>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <ctime>
#include <string>

#include "hal/linux/clock_posix.h"
#include "hal/linux/console_port.h"
#include "hal/linux/serial_termios.h"

#include "CppUTest/TestHarness.h"
#include "alloc_guard.h"

using boticelli::hal_linux::ClockPosix;
using boticelli::hal_linux::SerialConfig;
using boticelli::hal_linux::SerialStdio;
using boticelli::hal_linux::SerialTermios;

TEST_GROUP(ClockPosix){};

TEST(ClockPosix, TimeIsMonotonic) {
  ClockPosix c;
  std::uint64_t prev = c.now_us();
  for (int i = 0; i < 1000; ++i) {
    const std::uint64_t t = c.now_us();
    CHECK(t >= prev);
    prev = t;
  }
}

// The wall clock (how old a resumed pose is) is the real time in milliseconds, not the
// monotonic clock (within 2 s of time(): the two are read by different calls).
TEST(ClockPosix, TheWallClockIsTheRealtimeClockInMilliseconds) {
  ClockPosix c;
  const std::int64_t wall = c.wall_time_ms();
  const std::int64_t now_ms = static_cast<std::int64_t>(std::time(nullptr)) * 1000;
  CHECK_TEXT(wall > now_ms - 2000 && wall < now_ms + 2000, std::to_string(wall).c_str());
}

TEST(ClockPosix, SleepsUntilTheAbsoluteDeadline) {
  ClockPosix c;
  const std::uint64_t deadline = c.now_us() + 20000;
  c.sleep_until_us(deadline);
  CHECK(c.now_us() >= deadline);
}

namespace {
volatile sig_atomic_t g_alarms = 0;
void on_alarm(int) {
  g_alarms = g_alarms + 1;
}
}  // namespace

TEST(ClockPosix, SignalsDuringTheSleepDoNotCutItShort) {
  struct sigaction sa {};
  sa.sa_handler = on_alarm;
  sigemptyset(&sa.sa_mask);
  sa.sa_flags = 0;  // no SA_RESTART: the sleep sees EINTR
  struct sigaction old {};
  CHECK_EQUAL(0, ::sigaction(SIGALRM, &sa, &old));
  itimerval every_5ms{{0, 5000}, {0, 5000}};
  g_alarms = 0;
  ClockPosix c;
  const std::uint64_t deadline = c.now_us() + 60000;
  CHECK_EQUAL(0, ::setitimer(ITIMER_REAL, &every_5ms, nullptr));
  c.sleep_until_us(deadline);
  const std::uint64_t woke = c.now_us();
  itimerval off{};
  ::setitimer(ITIMER_REAL, &off, nullptr);
  ::sigaction(SIGALRM, &old, nullptr);
  CHECK(g_alarms >= 1);     // the sleep was interrupted at least once ...
  CHECK(woke >= deadline);  // ... and still lasted until the deadline
}

TEST(ClockPosix, ReturnsAtOnceForAPastDeadline) {
  ClockPosix c;
  const std::uint64_t start = c.now_us();
  c.sleep_until_us(start > 1000000 ? start - 1000000 : 0);
  CHECK(c.now_us() - start < 1000000U);  // generous: no wait of the missed second
}

TEST(ClockPosix, ReportsHowLateEachSleepWokeOnTheMonotonicClock) {
  ClockPosix c;
  CHECK_EQUAL(-1, c.last_wake_latency_ns());  // no sleep yet
  const std::uint64_t deadline = c.now_us() + 2000;
  c.sleep_until_us(deadline);
  const std::int64_t late_ns = c.last_wake_latency_ns();
  CHECK(late_ns >= 0);
  // Never more than the time between the deadline and now (both on CLOCK_MONOTONIC).
  CHECK(late_ns <= static_cast<std::int64_t>(c.now_us() - deadline + 1) * 1000);
  // A deadline a second past: that second is how late the frame started.
  c.sleep_until_us(c.now_us() - 1000000);
  CHECK(c.last_wake_latency_ns() >= 1000000000LL);
}

TEST(ClockPosix, ReadingTheTimeDoesNotAllocate) {
  ClockPosix c;
  std::uint64_t t = 0;
  CHECK_NO_ALLOCATION(t = c.now_us());
  CHECK(t > 0);
}

namespace {

// A pty pair: the master stays here, the slave's path is handed to the driver.
struct Pty {
  int master = -1;
  char slave[128] = "";
  Pty() {
    master = ::posix_openpt(O_RDWR | O_NOCTTY);
    if (master >= 0 && ::grantpt(master) == 0 && ::unlockpt(master) == 0) {
      ::ptsname_r(master, slave, sizeof slave);
      ::fcntl(master, F_SETFL, ::fcntl(master, F_GETFL) | O_NONBLOCK);
    }
  }
  ~Pty() {
    if (master >= 0) ::close(master);
  }
  // Reads what the driver wrote, waiting a bounded time for `want` bytes.
  std::size_t read_master(char* buf, std::size_t want) {
    std::size_t got = 0;
    for (int i = 0; i < 2000 && got < want; ++i) {
      const ssize_t n = ::read(master, buf + got, want - got);
      if (n > 0) {
        got += static_cast<std::size_t>(n);
      } else {
        ::usleep(1000);
      }
    }
    return got;
  }
};

std::ptrdiff_t read_bounded(SerialTermios& s, std::uint8_t* buf, std::size_t want) {
  std::size_t got = 0;
  for (int i = 0; i < 2000 && got < want; ++i) {
    const std::ptrdiff_t n = s.read(buf + got, want - got);
    if (n < 0) return n;
    got += static_cast<std::size_t>(n);
    if (got < want) ::usleep(1000);
  }
  return static_cast<std::ptrdiff_t>(got);
}

}  // namespace

TEST_GROUP(SerialTermios){};

TEST(SerialTermios, OpensAPtyAndMovesBytesBothWays) {
  Pty pty;
  CHECK(pty.master >= 0);
  SerialTermios s(SerialConfig{pty.slave, 9600});
  CHECK_TRUE_TEXT(s.open(), s.error());
  const char msg[] = "PP100 ";
  CHECK_EQUAL(6, s.write(reinterpret_cast<const std::uint8_t*>(msg), 6));
  char got[8] = {};
  CHECK_EQUAL(6U, pty.read_master(got, 6));
  STRNCMP_EQUAL(msg, got, 6);
  CHECK_EQUAL(5, ::write(pty.master, "* OK\n", 5));
  std::uint8_t in[8] = {};
  CHECK_EQUAL(5, read_bounded(s, in, 5));
  MEMCMP_EQUAL("* OK\n", in, 5);
}

TEST(SerialTermios, ConfiguresRaw8N1AtTheRequestedRate) {
  Pty pty;
  SerialTermios s(SerialConfig{pty.slave, 9600});
  CHECK_TRUE(s.open());
  termios t{};
  CHECK_EQUAL(0, ::tcgetattr(s.fd(), &t));
  CHECK_EQUAL(B9600, ::cfgetospeed(&t));
  CHECK_EQUAL(static_cast<tcflag_t>(CS8), t.c_cflag & CSIZE);
  CHECK_EQUAL(0U, t.c_cflag & PARENB);
  CHECK_EQUAL(0U, t.c_cflag & CSTOPB);
  CHECK_EQUAL(0U, t.c_lflag & (ICANON | ECHO));
}

TEST(SerialTermios, ReadReturnsZeroAtOnceWhenNothingArrivedAndDoesNotAllocate) {
  Pty pty;
  SerialTermios s(SerialConfig{pty.slave, 115200});
  CHECK_TRUE(s.open());
  std::uint8_t buf[16];
  std::ptrdiff_t n = -2;
  CHECK_NO_ALLOCATION(n = s.read(buf, sizeof buf));
  CHECK_EQUAL(0, n);
}

TEST(SerialTermios, AFullLineAcceptsFewerBytesInsteadOfBlocking) {
  Pty pty;
  SerialTermios s(SerialConfig{pty.slave, 115200});
  CHECK_TRUE(s.open());
  static const std::uint8_t block[4096] = {};
  std::size_t total = 0;
  std::ptrdiff_t n = 1;
  for (int i = 0; i < 1000 && n > 0; ++i) {  // nobody reads the master: the pty fills up
    n = s.write(block, sizeof block);
    CHECK(n >= 0);
    total += static_cast<std::size_t>(n);
  }
  CHECK_EQUAL(0, n);
  CHECK(total > 0U);
}

TEST(SerialTermios, RefusesAMissingDeviceWithAClearError) {
  SerialTermios s(SerialConfig{"/nonexistent/tty", 9600});
  CHECK_FALSE(s.open());
  STRCMP_EQUAL("serial /nonexistent/tty: open failed: No such file or directory", s.error());
  std::uint8_t b = 0;
  CHECK_EQUAL(-1, s.read(&b, 1));
}

TEST(SerialTermios, RefusesANonStandardBaudRate) {
  Pty pty;
  SerialTermios s(SerialConfig{pty.slave, 12345});
  CHECK_FALSE(s.open());
  STRCMP_CONTAINS("baud", s.error());
}

TEST(SerialTermios, RefusesAFileThatIsNotATerminal) {
  SerialTermios s(SerialConfig{"/dev/null", 9600});
  CHECK_FALSE(s.open());
  STRCMP_CONTAINS("serial /dev/null: not a terminal", s.error());
}

TEST(SerialTermios, ReportsAFaultWhenThePeerHangsUp) {
  Pty* pty = new Pty;
  SerialTermios s(SerialConfig{pty->slave, 9600});
  CHECK_TRUE(s.open());
  delete pty;  // closes the master: the slave reads EIO
  std::uint8_t b = 0;
  std::ptrdiff_t n = 0;
  for (int i = 0; i < 2000 && n == 0; ++i) {  // the kernel hangs the slave up asynchronously
    n = s.read(&b, 1);
    if (n == 0) ::usleep(1000);
  }
  CHECK_EQUAL(-1, n);
  STRCMP_CONTAINS("read failed", s.error());
}

TEST(SerialTermios, RestoresTheSavedSettingsOnClose) {
  Pty pty;
  const int probe = ::open(pty.slave, O_RDWR | O_NOCTTY);
  CHECK(probe >= 0);
  termios before{};
  ::tcgetattr(probe, &before);
  {
    SerialTermios s(SerialConfig{pty.slave, 9600});
    CHECK_TRUE(s.open());
  }
  termios after{};
  ::tcgetattr(probe, &after);
  CHECK_EQUAL(before.c_lflag, after.c_lflag);
  CHECK_EQUAL(::cfgetospeed(&before), ::cfgetospeed(&after));
  ::close(probe);
}

namespace {

// Swaps stdin and stdout for a pty slave (or other fds) for one test, restoring them after.
struct StdioRedirect {
  int saved_in = ::dup(STDIN_FILENO);
  int saved_out = ::dup(STDOUT_FILENO);
  StdioRedirect(int in_fd, int out_fd) {
    std::fflush(stdout);  // the test runner's buffered output must not go to the redirect
    ::dup2(in_fd, STDIN_FILENO);
    ::dup2(out_fd, STDOUT_FILENO);
  }
  ~StdioRedirect() {
    std::fflush(stdout);
    ::dup2(saved_in, STDIN_FILENO);
    ::dup2(saved_out, STDOUT_FILENO);
    ::close(saved_in);
    ::close(saved_out);
  }
};

}  // namespace

TEST_GROUP(SerialStdio){};

TEST(SerialStdio, UsesRawModeOnATerminalAndRestoresItOnClose) {
  Pty pty;
  const int slave = ::open(pty.slave, O_RDWR | O_NOCTTY);
  CHECK(slave >= 0);
  termios before{};
  ::tcgetattr(slave, &before);
  CHECK(before.c_lflag & ICANON);
  {
    StdioRedirect redirect(slave, slave);
    SerialStdio s;
    CHECK_TRUE(s.open());
    termios during{};
    ::tcgetattr(STDIN_FILENO, &during);
    CHECK_EQUAL(0U, during.c_lflag & (ICANON | ECHO));
    // The descriptors shared with the parent shell stay blocking (a crash would leave it
    // with a non-blocking terminal); the port reads through one of its own.
    const bool in_nonblocking = (::fcntl(STDIN_FILENO, F_GETFL) & O_NONBLOCK) != 0;
    const bool out_nonblocking = (::fcntl(STDOUT_FILENO, F_GETFL) & O_NONBLOCK) != 0;
    std::uint8_t b[4];
    CHECK_EQUAL(0, s.read(b, sizeof b));  // non-blocking: nothing typed yet
    CHECK_EQUAL(1, ::write(pty.master, "x", 1));
    std::ptrdiff_t n = 0;
    for (int i = 0; i < 2000 && n == 0; ++i) {
      n = s.read(b, sizeof b);
      if (n == 0) ::usleep(1000);
    }
    CHECK_EQUAL(1, n);  // byte at a time: no Enter needed in raw mode
    CHECK_EQUAL('x', b[0]);
    CHECK_EQUAL(3, s.write(reinterpret_cast<const std::uint8_t*>("ok\n"), 3));
    s.close();
    CHECK_FALSE(in_nonblocking);
    CHECK_FALSE(out_nonblocking);
    termios after{};
    ::tcgetattr(STDIN_FILENO, &after);
    CHECK(after.c_lflag & ICANON);
    CHECK_FALSE(::fcntl(STDIN_FILENO, F_GETFL) & O_NONBLOCK);
  }
  ::close(slave);
}

TEST(SerialStdio, WorksOnAPipeWithoutTouchingTermios) {
  int in_pipe[2];
  int out_pipe[2];
  CHECK_EQUAL(0, ::pipe(in_pipe));
  CHECK_EQUAL(0, ::pipe(out_pipe));
  {
    StdioRedirect redirect(in_pipe[0], out_pipe[1]);
    SerialStdio s;
    CHECK_TRUE(s.open());
    const bool in_nonblocking = (::fcntl(STDIN_FILENO, F_GETFL) & O_NONBLOCK) != 0;
    std::uint8_t b[8];
    CHECK_EQUAL(0, s.read(b, sizeof b));  // nothing written yet: at once, not blocking
    CHECK_FALSE(in_nonblocking);
    CHECK_EQUAL(4, ::write(in_pipe[1], "help", 4));
    CHECK_EQUAL(4, s.read(b, sizeof b));
    MEMCMP_EQUAL("help", b, 4);
    CHECK_EQUAL(2, s.write(reinterpret_cast<const std::uint8_t*>("ok"), 2));
    char out[4] = {};
    CHECK_EQUAL(2, ::read(out_pipe[0], out, sizeof out));
    STRNCMP_EQUAL("ok", out, 2);
  }
  for (int fd : {in_pipe[0], in_pipe[1], out_pipe[0], out_pipe[1]}) ::close(fd);
}

namespace {

int open_descriptors() {
  int n = 0;
  DIR* d = ::opendir("/proc/self/fd");
  while (d != nullptr && ::readdir(d) != nullptr) ++n;
  if (d != nullptr) ::closedir(d);
  return n;
}

}  // namespace

TEST_GROUP(ConsolePort){};

TEST(ConsolePort, OpeningAPtyConsoleAgainLeavesNoDescriptorBehind) {
  boticelli::hal_linux::ConsolePort console("/dev/null", 115200);
  console.select(boticelli::hal_linux::ConsoleMode::kPty, nullptr);
  CHECK_TRUE_TEXT(console.open(), console.error());
  const int after_first = open_descriptors();
  CHECK_TRUE_TEXT(console.open(), console.error());  // a new pair: the old one must go
  CHECK_EQUAL(after_first, open_descriptors());
}
