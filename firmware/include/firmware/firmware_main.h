// Firmware entry: what every board's main() calls with its own Board.
#pragma once

#include "firmware/board.h"

namespace boticelli::firmware {

// Parses the command line and runs the firmware on the board. Returns the process exit
// code: 0 for success, 2 for a usage error.
int firmware_main(int argc, const char* const* argv, Board& board);

}  // namespace boticelli::firmware
