// ServiceNotifier: systemd's notify protocol (READY=1, WATCHDOG=1, STOPPING=1) as a datagram on
// $NOTIFY_SOCKET.
#pragma once

#include <sys/socket.h>
#include <sys/un.h>

#include <cstdint>

namespace boticelli::firmware {

// sd_notify(3) without libsystemd: each message is one datagram sent to the AF_UNIX socket
// named by $NOTIFY_SOCKET (a leading '@' means Linux's abstract namespace). When the
// variable is unset (not started by systemd with Type=notify) every send is a no-op.
class ServiceNotifier {
 public:
  ServiceNotifier() = default;
  ~ServiceNotifier();
  ServiceNotifier(const ServiceNotifier&) = delete;
  ServiceNotifier& operator=(const ServiceNotifier&) = delete;

  // Reads the environment and opens the socket (at init: getenv is not for the cyclic path).
  // False with error() set when the variable is set but unusable.
  bool open();
  bool enabled() const { return fd_ >= 0; }
  // $WATCHDOG_USEC when systemd set it for this process, else 0 [µs].
  std::uint64_t watchdog_interval_us() const { return watchdog_us_; }

  bool ready() { return send("READY=1"); }
  bool watchdog() { return send("WATCHDOG=1"); }
  bool stopping() { return send("STOPPING=1"); }
  // One datagram with `message` (e.g. "STATUS=exploring"); true when sent or disabled.
  bool send(const char* message);
  std::uint64_t sent() const { return sent_; }
  const char* error() const { return error_; }

 private:
  int fd_ = -1;
  sockaddr_un address_{};
  socklen_t address_size_ = 0;
  std::uint64_t watchdog_us_ = 0;
  std::uint64_t sent_ = 0;
  char error_[128] = "";
};

}  // namespace boticelli::firmware
