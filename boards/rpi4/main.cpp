// boticelli for the Raspberry Pi 4 reference robot: hands the board to the firmware.
#include <cstdio>

#include "firmware/firmware_main.h"

namespace {

// Devices are not wired yet (see README: the mission comes in a later stage); init()
// refuses so nothing can use the missing HAL bag.
class Rpi4Board final : public boticelli::firmware::Board {
 public:
  const boticelli::firmware::BoardInfo& info() const override { return kInfo; }
  const boticelli::firmware::BoardConfig& config() const override { return config_; }
  bool init(const boticelli::firmware::Options&, char* error, std::size_t size) override {
    std::snprintf(error, size, "the rpi4 board's devices are not wired yet");
    return false;
  }
  boticelli::hal::Hal& hal() override { __builtin_trap(); }

 private:
  static constexpr boticelli::firmware::BoardInfo kInfo{"rpi4", "Raspberry Pi 4 reference robot", false};
  boticelli::firmware::BoardConfig config_{};
};

Rpi4Board g_board;

}  // namespace

int main(int argc, char** argv) { return boticelli::firmware::firmware_main(argc, argv, g_board); }
