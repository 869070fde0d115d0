// Tests of the systemd notify protocol (datagrams on a path socket and an abstract socket named by
// $NOTIFY_SOCKET) and of stderr lines for the journal.
#include <fcntl.h>
#include <stdlib.h>
#include <sys/socket.h>
#include <sys/stat.h>
#include <sys/un.h>
#include <unistd.h>

#include <cstddef>
#include <cstdio>
#include <cstring>
#include <string>

#include "firmware/common/log.h"
#include "firmware/app/service_notify.h"

#include "CppUTest/TestHarness.h"

using boticelli::firmware::ServiceNotifier;

namespace {

// A bound datagram socket standing in for systemd's notify socket.
int bind_socket(const std::string& name, bool abstract) {
  const int fd = socket(AF_UNIX, SOCK_DGRAM | SOCK_CLOEXEC, 0);
  sockaddr_un a{};
  a.sun_family = AF_UNIX;
  std::memcpy(a.sun_path + (abstract ? 1 : 0), name.data(), name.size());
  // Abstract: the leading NUL plus the name, no terminator; path: the name plus its NUL.
  const auto len = static_cast<socklen_t>(offsetof(sockaddr_un, sun_path) + name.size() + 1U);
  CHECK_EQUAL(0, bind(fd, reinterpret_cast<sockaddr*>(&a), len));
  return fd;
}

std::string receive(int fd) {
  char buf[256];
  const ssize_t n = recv(fd, buf, sizeof buf, MSG_DONTWAIT);
  return n > 0 ? std::string(buf, static_cast<std::size_t>(n)) : std::string();
}

}  // namespace

TEST_GROUP(ServiceNotifier){void teardown() override{unsetenv("NOTIFY_SOCKET");
unsetenv("WATCHDOG_USEC");
unsetenv("WATCHDOG_PID");
}
}
;

TEST(ServiceNotifier, SendsReadyAndWatchdogAsDatagramsToThePathInNotifySocket) {
  const std::string path = "/tmp/boticelli-notify-" + std::to_string(getpid());
  unlink(path.c_str());
  const int server = bind_socket(path, false);
  setenv("NOTIFY_SOCKET", path.c_str(), 1);
  setenv("WATCHDOG_USEC", "3000000", 1);
  ServiceNotifier n;
  CHECK_TEXT(n.open(), n.error());
  CHECK(n.enabled());
  CHECK_EQUAL(3000000U, n.watchdog_interval_us());
  CHECK(n.ready());
  CHECK(n.watchdog());
  CHECK(n.stopping());
  STRCMP_EQUAL("READY=1", receive(server).c_str());
  STRCMP_EQUAL("WATCHDOG=1", receive(server).c_str());
  STRCMP_EQUAL("STOPPING=1", receive(server).c_str());
  close(server);
  unlink(path.c_str());
}

TEST(ServiceNotifier, ReachesAnAbstractSocketNamedWithAnAt) {
  const std::string name = "boticelli-notify-abstract-" + std::to_string(getpid());
  const int server = bind_socket(name, true);
  setenv("NOTIFY_SOCKET", ("@" + name).c_str(), 1);
  ServiceNotifier n;
  CHECK(n.open());
  CHECK(n.send("STATUS=exploring"));
  STRCMP_EQUAL("STATUS=exploring", receive(server).c_str());
  close(server);
}

TEST(ServiceNotifier, DoesNothingWithoutNotifySocketAndIgnoresAnotherProcesssWatchdog) {
  setenv("WATCHDOG_USEC", "1000", 1);
  setenv("WATCHDOG_PID", "1", 1);
  ServiceNotifier n;
  CHECK(n.open());
  CHECK_FALSE(n.enabled());
  CHECK(n.ready());
  CHECK_EQUAL(0U, n.sent());
  CHECK_EQUAL(0U, n.watchdog_interval_us());
}

TEST(ServiceNotifier, RefusesANotifySocketThatIsNotAUnixAddress) {
  setenv("NOTIFY_SOCKET", "vsock:2:1234", 1);
  ServiceNotifier n;
  CHECK_FALSE(n.open());
  STRCMP_CONTAINS("NOTIFY_SOCKET", n.error());
}

namespace {

// Runs `body` with stderr sent to a fresh file and returns what was written to it.
template <typename Body>
std::string capture_stderr(const std::string& path, Body body) {
  std::fflush(stderr);
  const int saved = dup(2);
  const int fd = ::open(path.c_str(), O_CREAT | O_TRUNC | O_WRONLY | O_CLOEXEC, 0600);
  dup2(fd, 2);
  body();
  std::fflush(stderr);
  dup2(saved, 2);
  close(saved);
  close(fd);
  char buf[512];
  const int in = ::open(path.c_str(), O_RDONLY | O_CLOEXEC);
  const ssize_t n = read(in, buf, sizeof buf);
  close(in);
  unlink(path.c_str());
  return n > 0 ? std::string(buf, static_cast<std::size_t>(n)) : std::string();
}

}  // namespace

TEST_GROUP(ServiceLog){void teardown() override{unsetenv("JOURNAL_STREAM");
}
}
;

TEST(ServiceLog, PrefixesThePriorityOnlyWhenStderrIsTheJournalsStream) {
  const std::string path = "/tmp/boticelli-stderr-" + std::to_string(getpid());
  using boticelli::firmware::LogLevel;
  boticelli::firmware::LogRing ring;
  boticelli::firmware::ServiceLog log;
  log.attach(&ring, nullptr);
  // Not started by systemd: the program's name, for a person reading a terminal.
  unsetenv("JOURNAL_STREAM");
  std::string out = capture_stderr(path, [&] {
    log.open();
    log.log(LogLevel::kWarn, "watchdog not armed (%s)", "busy");
  });
  STRCMP_EQUAL("boticelli: watchdog not armed (busy)\n", out.c_str());
  CHECK_FALSE(log.to_journal());
  // JOURNAL_STREAM names this very stderr: sd-daemon priorities, no name (journald adds it).
  out = capture_stderr(path, [&] {
    struct stat st {};
    fstat(2, &st);
    const std::string stream = std::to_string(st.st_dev) + ":" + std::to_string(st.st_ino);
    setenv("JOURNAL_STREAM", stream.c_str(), 1);
    log.open();
    log.log(LogLevel::kError, "camera: no such device");
    log.log(LogLevel::kWarn, "w");
    log.log(LogLevel::kInfo, "i");
    log.log(LogLevel::kDebug, "d");
  });
  STRCMP_EQUAL("<3>camera: no such device\n<4>w\n<6>i\n<7>d\n", out.c_str());
  // A stream of another file (stderr redirected after systemd started us): plain again.
  setenv("JOURNAL_STREAM", "1:1", 1);
  out = capture_stderr(path, [&] {
    log.open();
    log.log(LogLevel::kInfo, "resumed");
  });
  STRCMP_EQUAL("boticelli: resumed\n", out.c_str());
  CHECK_EQUAL(6U, ring.size());
  CHECK(ring.find(0)->view() == "watchdog not armed (busy)");
}
