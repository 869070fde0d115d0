// Helpers for suites that run the firmware binary: its path, running it with a timeout, files.
#pragma once

#include <string>
#include <vector>

namespace boticelli::bench {

// The whole file ("" when it cannot be read).
std::string read_file(const std::string& path);
// Removes a directory with everything in it (a run's outputs: its files, its state and
// snapshot directories).
void remove_tree(const std::string& dir);
// The directory of this executable (the firmware is built next to it: build/<preset>/bin).
std::string own_directory();
// Monotonic wall time [s].
double wall_s();
// Typed into the firmware's stdio console while it runs, in order: `text` once a telemetry
// line (`TLM t_s=...`) of at least `at_s` that contains `when` comes out.
struct ConsoleInput {
  double at_s = 0.0;
  std::string when;
  std::string text;
  std::string seen;  // out: the telemetry line it was typed after ("" when it was not typed)
};

// Runs the firmware (args[0]: a path, or a program found on PATH such as an emulator that
// runs it) with stdin from /dev/null (a pipe when `input` is given), stdout (the
// stdio console and the MISSION line) into `out_path`, stderr into `err_path`. SIGTERM after
// `timeout_s` (the firmware then aborts and still prints its MISSION line), SIGKILL 10 s
// later. Returns the exit status (-1 when it could not be started or was killed by a
// signal) and the child's CPU time (user + system) [s]: on a shared host the wall time
// mostly measures the neighbours.
int run_firmware(const std::vector<std::string>& args, const std::string& out_path,
                 const std::string& err_path, double timeout_s, bool& timed_out, double& cpu_s,
                 std::vector<ConsoleInput>* input = nullptr);

}  // namespace boticelli::bench
