// Firmware entry: what every board's main() calls with its own description.
#pragma once

namespace boticelli::firmware {

struct BoardInfo {
  const char* name;         // folder in boards/, e.g. "sim"
  const char* description;  // one line for --version
  bool simulated;           // true for the sim board (accepts --world)
};

// Parses the command line and runs the firmware on the board. Returns the process exit
// code: 0 for success, 2 for a usage error.
int firmware_main(int argc, const char* const* argv, const BoardInfo& board);

}  // namespace boticelli::firmware
