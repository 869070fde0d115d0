// boticelli for the host simulation board: hands the board to the firmware.
#include "firmware/app/firmware_main.h"
#include "sim_board.h"

namespace {
boticelli::boards::sim::SimBoard g_board;
}  // namespace

int main(int argc, char** argv) {
  return boticelli::firmware::firmware_main(argc, argv, g_board);
}
