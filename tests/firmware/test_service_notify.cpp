// Tests of the systemd notify protocol: datagrams on a path socket and an abstract socket named by
// $NOTIFY_SOCKET.
#include <stdlib.h>
#include <sys/socket.h>
#include <sys/un.h>
#include <unistd.h>

#include <cstddef>
#include <cstring>
#include <string>

#include "firmware/service_notify.h"

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
