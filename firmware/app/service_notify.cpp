// ServiceNotifier: the sd_notify datagram protocol over an AF_UNIX socket (see service_notify.h).
#include "firmware/app/service_notify.h"

#include <fcntl.h>
#include <unistd.h>

#include <cerrno>
#include <cstddef>
#include <cstdio>
#include <cstdlib>
#include <cstring>

namespace boticelli::firmware {

ServiceNotifier::~ServiceNotifier() {
  if (fd_ >= 0) ::close(fd_);
}

bool ServiceNotifier::open() {
  const char* path = std::getenv("NOTIFY_SOCKET");
  if (const char* wd = std::getenv("WATCHDOG_USEC"); wd != nullptr) {
    // Only meant for us when WATCHDOG_PID is unset or names this process (sd_watchdog_enabled).
    const char* pid = std::getenv("WATCHDOG_PID");
    char* end = nullptr;
    const unsigned long long us = std::strtoull(wd, &end, 10);
    const bool for_us =
        pid == nullptr || std::strtol(pid, nullptr, 10) == static_cast<long>(::getpid());
    if (end != wd && *end == '\0' && for_us) watchdog_us_ = us;
  }
  if (path == nullptr || path[0] == '\0') return true;
  const std::size_t len = std::strlen(path);
  if ((path[0] != '/' && path[0] != '@') || len >= sizeof address_.sun_path) {
    std::snprintf(error_, sizeof error_, "NOTIFY_SOCKET '%s' is not a unix socket address", path);
    return false;
  }
  address_ = sockaddr_un{};
  address_.sun_family = AF_UNIX;
  std::memcpy(address_.sun_path, path, len);
  if (path[0] == '@') address_.sun_path[0] = '\0';  // abstract namespace
  address_size_ =
      static_cast<socklen_t>(offsetof(sockaddr_un, sun_path) + len + (path[0] == '@' ? 0U : 1U));
  fd_ = ::socket(AF_UNIX, SOCK_DGRAM | SOCK_CLOEXEC | SOCK_NONBLOCK, 0);
  if (fd_ < 0) {
    std::snprintf(error_, sizeof error_, "notify socket: %s", std::strerror(errno));
    return false;
  }
  return true;
}

bool ServiceNotifier::send(const char* message) {
  if (fd_ < 0) return true;
  const std::size_t len = std::strlen(message);
  const ssize_t n = ::sendto(fd_, message, len, MSG_NOSIGNAL,
                             reinterpret_cast<const sockaddr*>(&address_), address_size_);
  if (n != static_cast<ssize_t>(len)) {
    std::snprintf(error_, sizeof error_, "notify '%s': %s", message,
                  n < 0 ? std::strerror(errno) : "short send");
    return false;
  }
  ++sent_;
  return true;
}

}  // namespace boticelli::firmware
