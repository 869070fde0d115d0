// boticelli-box-devices: the robot's base and PTU for the robot computer in a box
// (tests/box/run.sh).
//
//   boticelli-box-devices odrive IFACE   in the box: two ODrive axes on the SocketCAN IFACE
//   boticelli-box-devices ptu LINK       on the host: a PTU-D46 on a pty, LINK a symlink to
//                                        its slave (qemu opens it as the box's ttyS2)
//
// Each runs the test fakes' emulator on the real clock (service every millisecond) until
// SIGTERM or SIGINT. The ODrive emulator's raw socket outlives a link taken down and up.
#include <csignal>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <ctime>
#include <string>

#include <unistd.h>

#include "odrive_can_emulator.h"
#include "ptu46_emulator.h"

namespace {

volatile std::sig_atomic_t g_stop = 0;
void on_signal(int /*signal*/) {
  g_stop = 1;
}

std::uint64_t now_us() {
  timespec t{};
  clock_gettime(CLOCK_MONOTONIC, &t);
  return static_cast<std::uint64_t>(t.tv_sec) * 1000000U +
         static_cast<std::uint64_t>(t.tv_nsec) / 1000U;
}

void sleep_1ms() {
  timespec t{0, 1000000};
  nanosleep(&t, nullptr);
}

int usage() {
  std::fprintf(stderr, "usage: boticelli-box-devices odrive IFACE | ptu LINK\n");
  return 2;
}

int run_odrive(const char* interface) {
  boticelli::fakes::OdriveCanEmulator emu;
  if (!emu.open_can(interface)) {
    std::fprintf(stderr, "boticelli-box-devices: cannot open %s: %s\n", interface,
                 std::strerror(errno));
    return 1;
  }
  std::printf("odrive: two axes (nodes 0, 1) on %s\n", interface);
  std::fflush(stdout);
  while (g_stop == 0) {
    emu.service(now_us());
    sleep_1ms();
  }
  return 0;
}

int run_ptu(const char* link) {
  boticelli::fakes::Ptu46Emulator emu;
  if (!emu.open()) {
    std::fprintf(stderr, "boticelli-box-devices: no pty for the PTU: %s\n", std::strerror(errno));
    return 1;
  }
  ::unlink(link);
  if (::symlink(emu.slave_path(), link) != 0) {
    std::fprintf(stderr, "boticelli-box-devices: cannot link %s: %s\n", link, std::strerror(errno));
    return 1;
  }
  std::printf("ptu: PTU-D46 on %s (%s)\n", emu.slave_path(), link);
  std::fflush(stdout);
  while (g_stop == 0) {
    emu.service(now_us());
    sleep_1ms();
  }
  ::unlink(link);
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  if (argc != 3) return usage();
  struct sigaction action {};
  action.sa_handler = on_signal;
  sigemptyset(&action.sa_mask);
  sigaction(SIGTERM, &action, nullptr);
  sigaction(SIGINT, &action, nullptr);
  const std::string mode = argv[1];
  if (mode == "odrive") return run_odrive(argv[2]);
  if (mode == "ptu") return run_ptu(argv[2]);
  return usage();
}
