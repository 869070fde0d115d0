// Helpers for suites that run the firmware binary (see bench_process.h).
#include "bench_process.h"

#include <fcntl.h>
#include <signal.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <cstdio>
#include <cstring>
#include <limits>

#include "bench.h"

namespace boticelli::bench {

// The whole file ("" when it cannot be read).
std::string read_file(const std::string& path) {
  std::string text;
  if (std::FILE* f = std::fopen(path.c_str(), "rb"); f != nullptr) {
    char buffer[65536];
    std::size_t n = 0;
    while ((n = std::fread(buffer, 1, sizeof buffer, f)) > 0) text.append(buffer, n);
    std::fclose(f);
  }
  return text;
}

// The directory of this executable (the firmware is built next to it: build/<preset>/bin).
std::string own_directory() {
  char path[4096];
  const ssize_t n = ::readlink("/proc/self/exe", path, sizeof path - 1);
  if (n <= 0) return ".";
  path[n] = '\0';
  char* slash = std::strrchr(path, '/');
  if (slash == nullptr) return ".";
  *slash = '\0';
  return path;
}

double wall_s() {
  return static_cast<double>(now_ns()) * 1e-9;
}

// Runs the firmware with stdin from /dev/null, stdout (the stdio console and the MISSION
// line) into `out_path`, stderr into `err_path`. SIGTERM after `timeout_s` (the firmware
// then aborts and still prints its MISSION line), SIGKILL 10 s later. Returns the exit
// status (-1 when it could not be started or was killed by a signal) and the child's CPU
// time (user + system) [s]: on a shared host the wall time mostly measures the neighbours.
int run_firmware(const std::vector<std::string>& args, const std::string& out_path,
                 const std::string& err_path, double timeout_s, bool& timed_out, double& cpu_s) {
  timed_out = false;
  cpu_s = std::numeric_limits<double>::quiet_NaN();
  std::vector<char*> argv;
  argv.reserve(args.size() + 1);
  for (const std::string& a : args) argv.push_back(const_cast<char*>(a.c_str()));
  argv.push_back(nullptr);
  const pid_t pid = ::fork();
  if (pid < 0) return -1;
  if (pid == 0) {
    const int in = ::open("/dev/null", O_RDONLY);
    const int out = ::open(out_path.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
    const int err = ::open(err_path.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
    if (in < 0 || out < 0 || err < 0) ::_exit(126);
    ::dup2(in, STDIN_FILENO);
    ::dup2(out, STDOUT_FILENO);
    ::dup2(err, STDERR_FILENO);
    ::execv(argv[0], argv.data());
    ::_exit(127);
  }
  const double start = wall_s();
  bool termed = false;
  for (;;) {
    int status = 0;
    rusage usage{};
    const pid_t r = ::wait4(pid, &status, WNOHANG, &usage);
    if (r == pid) {
      cpu_s = static_cast<double>(usage.ru_utime.tv_sec + usage.ru_stime.tv_sec) +
              static_cast<double>(usage.ru_utime.tv_usec + usage.ru_stime.tv_usec) * 1e-6;
      if (WIFEXITED(status)) return WEXITSTATUS(status);
      return -1;
    }
    if (r < 0 && errno != EINTR) return -1;
    const double elapsed = wall_s() - start;
    if (!termed && elapsed > timeout_s) {
      timed_out = true;
      termed = true;
      ::kill(pid, SIGTERM);
    } else if (termed && elapsed > timeout_s + 10.0) {
      ::kill(pid, SIGKILL);
    }
    ::usleep(20000);
  }
}

}  // namespace boticelli::bench
