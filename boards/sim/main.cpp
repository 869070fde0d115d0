// boticelli for the host simulation board: hands the board to the firmware.
#include "firmware/firmware_main.h"

int main(int argc, char** argv) {
  static constexpr boticelli::firmware::BoardInfo kBoard{"sim", "host simulation board", true};
  return boticelli::firmware::firmware_main(argc, argv, kBoard);
}
