// Firmware entry: what every board's main() calls with its own Board.
#pragma once

#include "firmware/app/board.h"

namespace boticelli::firmware {

// Exit codes: 0 the target was found (or --help/--version), 1 a failure a restart may cure
// (board, device or state directory could not be set up, or a device fault outlasted its
// retry time, `[faults] retry_s`: the service unit restarts on it, with --resume), 2 a usage
// error, a bad
// configuration, a refused state directory (not a directory, another owner, writable by
// others: StateStore::refused) or a saved state that cannot be loaded (a restart cannot
// help: the service unit does not restart on it), 3 the mission ended without finding the
// target (result=not_found or aborted, e.g. stopped by a signal, the console or --max-cycles).
inline constexpr int kExitFound = 0;
inline constexpr int kExitFailure = 1;
inline constexpr int kExitUsage = 2;
inline constexpr int kExitNotFound = 3;

class Executive;

// Called around the cyclic loop: loop_started after every init (devices, files, tasks, the
// mission's start), after_frame after each minor frame, loop_ended after the last frame,
// before the orderly stop. Tests count heap allocations over a whole mission, press buttons
// at the right moment and read the executive's statistics with them.
struct MainHooks {
  void (*loop_started)(void* context) = nullptr;
  void (*after_frame)(void* context) = nullptr;
  void (*loop_ended)(void* context, const Executive& executive) = nullptr;
  void* context = nullptr;
};

// Parses the command line and runs the firmware on the board until a signal, the console's
// shutdown or --max-cycles; prints the MISSION line last and returns the exit code.
int firmware_main(int argc, const char* const* argv, Board& board,
                  const MainHooks* hooks = nullptr);

}  // namespace boticelli::firmware
