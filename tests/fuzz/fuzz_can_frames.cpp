// libFuzzer target: CAN frames into the ODrive base driver (heartbeats, encoder estimates,
// error frames, anything else) over a socketpair, with time passing and setpoints between.
// Each 17-byte record is one step: a control byte and a struct can_frame's 16 bytes.
#include <linux/can.h>
#include <sys/socket.h>
#include <unistd.h>

#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <cstring>

#include "fake_clock.h"
#include "hal/linux/base_odrive_can.h"

namespace {

void drain(int fd) {
  can_frame frame{};
  while (::recv(fd, &frame, sizeof frame, MSG_DONTWAIT) > 0) {
  }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  int fds[2];
  if (::socketpair(AF_UNIX, SOCK_SEQPACKET | SOCK_CLOEXEC, 0, fds) != 0) std::abort();
  boticelli::fakes::FakeClock clock(1000000);
  boticelli::hal_linux::BaseOdriveCanConfig config;
  config.socket_fd = fds[0];  // the driver owns and closes it
  config.request_encoder = size % 2 == 1;
  boticelli::hal_linux::BaseOdriveCan base(config, clock);
  if (!base.init()) std::abort();
  constexpr std::size_t kRecord = 1 + sizeof(can_frame);
  for (std::size_t at = 0; at + kRecord <= size; at += kRecord) {
    const std::uint8_t control = data[at];
    can_frame frame{};
    std::memcpy(&frame, data + at + 1, sizeof frame);
    if ((control & 0x80U) == 0) {
      // A frame as SocketCAN hands it over (the driver checks the length itself).
      (void)::send(fds[1], &frame, sizeof frame, MSG_DONTWAIT);
    }
    clock.advance_us(static_cast<std::uint64_t>(control & 0x3FU) * 10000U);
    if ((control & 0x40U) != 0) {
      float v = 0.0F;
      float omega = 0.0F;
      std::memcpy(&v, frame.data, 4);
      std::memcpy(&omega, frame.data + 4, 4);
      base.set_velocity(v, omega);
    }
    base.update();
    drain(fds[1]);
    const boticelli::hal::Odometry o = base.odometry();
    if (!std::isfinite(o.x_m) || !std::isfinite(o.y_m) || !std::isfinite(o.yaw_rad) ||
        !std::isfinite(o.v_m_s) || !std::isfinite(o.omega_rad_s)) {
      std::abort();  // odometry must never go non-finite, whatever the bus says
    }
  }
  if ((size & 4U) != 0 && base.resume()) base.update();
  base.stop();
  ::close(fds[1]);
  return 0;
}
