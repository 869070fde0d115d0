// Whole missions in the test process: firmware_main on a sim board with its stdio console captured.
#pragma once

#include <string>
#include <vector>

#include "firmware/app/firmware_main.h"
#include "sim_board.h"

namespace boticelli::test {

// The whole file ("" when it cannot be read).
std::string slurp(const std::string& path);

// Runs firmware_main(argv) on `board` with stdout (telemetry, the MISSION line) into
// `out_path` and stdin from /dev/null, or from `console_in` (a pipe's read end the test
// types into) when it is ≥ 0; the process's own stdio is restored afterwards. Returns the
// firmware's exit code.
int run_captured(boards::sim::SimBoard& board, std::vector<const char*> argv,
                 const std::string& out_path, const firmware::MainHooks* hooks = nullptr,
                 int console_in = -1);

}  // namespace boticelli::test
