// Whole missions in the test process (see mission_runner.h).
#include "mission_runner.h"

#include <unistd.h>

#include <cstdio>
#include <fstream>
#include <sstream>

namespace boticelli::test {

std::string slurp(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

int run_captured(boards::sim::SimBoard& board, std::vector<const char*> argv,
                 const std::string& out_path, const firmware::MainHooks* hooks, int console_in) {
  std::fflush(stdout);
  const int saved = dup(1);
  const int saved_in = dup(0);
  FILE* f = std::fopen(out_path.c_str(), "w");
  FILE* null_in = std::fopen("/dev/null", "r");
  dup2(fileno(f), 1);
  dup2(console_in >= 0 ? console_in : fileno(null_in), 0);
  const int code =
      firmware::firmware_main(static_cast<int>(argv.size()), argv.data(), board, hooks);
  std::fflush(stdout);
  dup2(saved, 1);
  dup2(saved_in, 0);
  close(saved);
  close(saved_in);
  std::fclose(f);
  std::fclose(null_in);
  return code;
}

}  // namespace boticelli::test
