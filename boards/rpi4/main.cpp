// boticelli for the Raspberry Pi 4 reference robot: hands the board to the firmware.
#include "firmware/firmware_main.h"

int main(int argc, char** argv) {
  static constexpr boticelli::firmware::BoardInfo kBoard{"rpi4", "Raspberry Pi 4 reference robot", false};
  return boticelli::firmware::firmware_main(argc, argv, kBoard);
}
