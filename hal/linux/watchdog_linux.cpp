// WatchdogLinux: /dev/watchdog with timeout, keep-alive ioctl and magic close.
#include "hal/linux/watchdog_linux.h"

#include <fcntl.h>
#include <linux/watchdog.h>
#include <sys/ioctl.h>
#include <unistd.h>

#include <cerrno>
#include <cstdio>

#include "hal/linux/error_text.h"

namespace boticelli::hal_linux {

int SystemWatchdogIo::open(const char* path) {
  return ::open(path, O_WRONLY | O_CLOEXEC);
}
int SystemWatchdogIo::ioctl(int fd, unsigned long request, int* arg) {
  return ::ioctl(fd, request, arg);
}
long SystemWatchdogIo::write(int fd, const void* data, std::size_t size) {
  return static_cast<long>(::write(fd, data, size));
}
int SystemWatchdogIo::close(int fd) {
  return ::close(fd);
}

WatchdogLinux::WatchdogLinux(const WatchdogConfig& config, WatchdogIo* io)
    : config_(config), io_(io != nullptr ? *io : system_io_) {}

WatchdogLinux::~WatchdogLinux() {
  // An orderly destruction disarms; a crash (no destructor) leaves it armed, as intended.
  stop();
}

bool WatchdogLinux::start(std::uint32_t timeout_ms) {
  if (fd_ >= 0) stop();
  if (timeout_ms == 0) {
    set_error(error_, "watchdog: a zero timeout");
    return false;
  }
  fd_ = io_.open(config_.device);
  if (fd_ < 0) {
    const int err = errno;
    char what[140];
    if (err == EBUSY) {
      // The device has one opener at a time: systemd holds it when RuntimeWatchdogSec= is set.
      std::snprintf(what, sizeof what,
                    "watchdog: %s is busy (another process holds it, e.g. systemd with "
                    "RuntimeWatchdogSec=)",
                    config_.device);
    } else {
      std::snprintf(what, sizeof what, "watchdog: cannot open %s", config_.device);
    }
    set_error(error_, what, err);
    return false;
  }
  const int asked = static_cast<int>((timeout_ms + 999U) / 1000U);
  int seconds = asked;
  if (io_.ioctl(fd_, WDIOC_SETTIMEOUT, &seconds) != 0) {
    const int err = errno;
    stop();
    char what[140];
    // Drivers refuse a timeout outside their range with EINVAL; the Raspberry Pi's
    // (bcm2835-wdt) ends at about 15 s.
    std::snprintf(what, sizeof what,
                  "watchdog: the device refused a timeout of %d s (WDIOC_SETTIMEOUT; the "
                  "Raspberry Pi's accepts at most 15 s)",
                  asked);
    set_error(error_, what, err);
    return false;
  }
  timeout_s_ = seconds;  // the driver writes back the timeout it actually uses
  error_[0] = '\0';
  return true;
}

bool WatchdogLinux::kick() {
  if (fd_ < 0) return true;
  int dummy = 0;
  if (io_.ioctl(fd_, WDIOC_KEEPALIVE, &dummy) == 0) return true;
  // Some drivers only take writes as keep-alive.
  if (io_.write(fd_, "k", 1) == 1) return true;
  set_error(error_, "watchdog: keep-alive refused", errno);
  return false;
}

void WatchdogLinux::stop() {
  if (fd_ < 0) return;
  const long n = io_.write(fd_, "V", 1);  // magic close: disarm on close
  if (n != 1) set_error(error_, "watchdog: magic close failed; the board may reset", errno);
  io_.close(fd_);
  fd_ = -1;
}

}  // namespace boticelli::hal_linux
