// Helpers for suites that run the firmware binary: its path, running it with a timeout, files.
#pragma once

#include <string>
#include <vector>

namespace boticelli::bench {

// The whole file ("" when it cannot be read).
std::string read_file(const std::string& path);
// The directory of this executable (the firmware is built next to it: build/<preset>/bin).
std::string own_directory();
// Monotonic wall time [s].
double wall_s();
// Runs the firmware with stdin from /dev/null, stdout (the stdio console and the MISSION
// line) into `out_path`, stderr into `err_path`. SIGTERM after `timeout_s` (the firmware
// then aborts and still prints its MISSION line), SIGKILL 10 s later. Returns the exit
// status (-1 when it could not be started or was killed by a signal) and the child's CPU
// time (user + system) [s]: on a shared host the wall time mostly measures the neighbours.
int run_firmware(const std::vector<std::string>& args, const std::string& out_path,
                 const std::string& err_path, double timeout_s, bool& timed_out, double& cpu_s);

}  // namespace boticelli::bench
