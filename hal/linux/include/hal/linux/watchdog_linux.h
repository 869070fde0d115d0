// WatchdogLinux: hal::Watchdog on the kernel watchdog device (/dev/watchdog): timeout, keep-alive,
// magic close.
#pragma once

#include <cstddef>
#include <cstdint>

#include "hal/watchdog.h"

namespace boticelli::hal_linux {

// The system calls the watchdog uses, as a seam (tests record them; the kernel's watchdog
// cannot be opened in a test without arming a reset).
class WatchdogIo {
 public:
  virtual ~WatchdogIo() = default;
  virtual int open(const char* path) = 0;  // O_WRONLY | O_CLOEXEC
  virtual int ioctl(int fd, unsigned long request, int* arg) = 0;
  virtual long write(int fd, const void* data, std::size_t size) = 0;
  virtual int close(int fd) = 0;
};

class SystemWatchdogIo final : public WatchdogIo {
 public:
  int open(const char* path) override;
  int ioctl(int fd, unsigned long request, int* arg) override;
  long write(int fd, const void* data, std::size_t size) override;
  int close(int fd) override;
};

struct WatchdogConfig {
  const char* device = "/dev/watchdog";
};

// start(): opening the device arms it; WDIOC_SETTIMEOUT with the timeout rounded up to whole
// seconds (the driver may pick another value: timeout_s() is what it answered). kick():
// WDIOC_KEEPALIVE. stop(): the magic close ('V' written, then close) disarms it — drivers
// built with nowayout ignore that, and the board then resets unless kicked. A failed
// SETTIMEOUT disarms (magic close) and reports the error.
class WatchdogLinux final : public hal::Watchdog {
 public:
  explicit WatchdogLinux(const WatchdogConfig& config = {}, WatchdogIo* io = nullptr);
  ~WatchdogLinux() override;

  bool start(std::uint32_t timeout_ms) override;
  bool kick() override;
  void stop() override;
  const char* error() const override { return error_; }
  int timeout_s() const { return timeout_s_; }
  bool armed() const { return fd_ >= 0; }

 private:
  WatchdogConfig config_;
  SystemWatchdogIo system_io_;
  WatchdogIo& io_;
  int fd_ = -1;
  int timeout_s_ = 0;
  char error_[160] = "";
};

}  // namespace boticelli::hal_linux
