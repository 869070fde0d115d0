// boticelli for the Raspberry Pi 4 reference robot: hands the board to the firmware.
#include "firmware/app/firmware_main.h"
#include "rpi4_board.h"

namespace {
boticelli::boards::rpi4::Rpi4Board g_board;
}  // namespace

int main(int argc, char** argv) {
  return boticelli::firmware::firmware_main(argc, argv, g_board);
}
