// Helpers for suites that run the firmware binary (see bench_process.h).
#include "bench_process.h"

#include <dirent.h>
#include <fcntl.h>
#include <signal.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <cstdlib>
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

void remove_tree(const std::string& dir) {
  if (DIR* d = ::opendir(dir.c_str()); d != nullptr) {
    while (const dirent* e = ::readdir(d)) {
      const std::string n = e->d_name;
      if (n == "." || n == "..") continue;
      const std::string p = std::string(dir).append("/").append(n);
      if (::unlink(p.c_str()) != 0) remove_tree(p);
    }
    ::closedir(d);
  }
  ::rmdir(dir.c_str());
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

namespace {

// Feeds `input` from the firmware's output as it grows: reads `out_path` from `*scanned` on,
// whole lines only.
void feed_console(const std::string& out_path, std::size_t* scanned, int fd,
                  std::vector<ConsoleInput>& input, std::size_t* next) {
  if (*next >= input.size()) return;
  std::FILE* f = std::fopen(out_path.c_str(), "rb");
  if (f == nullptr) return;
  std::string text;
  if (std::fseek(f, static_cast<long>(*scanned), SEEK_SET) == 0) {
    char buffer[65536];
    std::size_t n = 0;
    while ((n = std::fread(buffer, 1, sizeof buffer, f)) > 0) text.append(buffer, n);
  }
  std::fclose(f);
  std::size_t begin = 0;
  for (std::size_t end = text.find('\n'); end != std::string::npos && *next < input.size();
       begin = end + 1, end = text.find('\n', begin)) {
    const std::string line = text.substr(begin, end - begin);
    const std::size_t at = line.find("TLM t_s=");
    if (at == std::string::npos) continue;
    ConsoleInput& in = input[*next];
    if (std::atof(line.c_str() + at + 8) < in.at_s || line.find(in.when) == std::string::npos) {
      continue;
    }
    if (::write(fd, in.text.data(), in.text.size()) != static_cast<ssize_t>(in.text.size())) {
      continue;  // the firmware is gone: nothing more to type
    }
    in.seen = line.substr(at);
    while (!in.seen.empty() && (in.seen.back() == '\r' || in.seen.back() == '\n')) {
      in.seen.pop_back();
    }
    ++*next;
  }
  *scanned += begin;
}

}  // namespace

// Runs the firmware (args[0]: a path, or a program found on PATH such as an emulator that
// runs it) with stdin from /dev/null (a pipe when `input` is given), stdout (the
// stdio console and the MISSION line) into `out_path`, stderr into `err_path`. SIGTERM after
// `timeout_s` (the firmware then aborts and still prints its MISSION line), SIGKILL 10 s
// later. Returns the exit status (-1 when it could not be started or was killed by a
// signal) and the child's CPU time (user + system) [s]: on a shared host the wall time
// mostly measures the neighbours.
int run_firmware(const std::vector<std::string>& args, const std::string& out_path,
                 const std::string& err_path, double timeout_s, bool& timed_out, double& cpu_s,
                 std::vector<ConsoleInput>* input) {
  timed_out = false;
  cpu_s = std::numeric_limits<double>::quiet_NaN();
  std::vector<char*> argv;
  argv.reserve(args.size() + 1);
  for (const std::string& a : args) argv.push_back(const_cast<char*>(a.c_str()));
  argv.push_back(nullptr);
  int pipe_fds[2] = {-1, -1};
  if (input != nullptr) {
    if (::pipe2(pipe_fds, O_CLOEXEC) != 0) return -1;
    ::signal(SIGPIPE, SIG_IGN);  // a firmware that ended early: write() fails instead
  }
  const pid_t pid = ::fork();
  if (pid < 0) {
    if (input != nullptr) {
      ::close(pipe_fds[0]);
      ::close(pipe_fds[1]);
    }
    return -1;
  }
  if (pid == 0) {
    const int in = input != nullptr ? pipe_fds[0] : ::open("/dev/null", O_RDONLY);
    const int out = ::open(out_path.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
    const int err = ::open(err_path.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
    if (in < 0 || out < 0 || err < 0) ::_exit(126);
    ::dup2(in, STDIN_FILENO);
    ::dup2(out, STDOUT_FILENO);
    ::dup2(err, STDERR_FILENO);
    ::execvp(argv[0], argv.data());  // a path runs as given; a bare name (an emulator) from PATH
    ::_exit(127);
  }
  if (input != nullptr) ::close(pipe_fds[0]);
  std::size_t scanned = 0;
  std::size_t next = 0;
  const double start = wall_s();
  bool termed = false;
  for (;;) {
    int status = 0;
    rusage usage{};
    const pid_t r = ::wait4(pid, &status, WNOHANG, &usage);
    if (r == pid) {
      if (input != nullptr) ::close(pipe_fds[1]);
      cpu_s = static_cast<double>(usage.ru_utime.tv_sec + usage.ru_stime.tv_sec) +
              static_cast<double>(usage.ru_utime.tv_usec + usage.ru_stime.tv_usec) * 1e-6;
      if (WIFEXITED(status)) return WEXITSTATUS(status);
      return -1;
    }
    if (input != nullptr) feed_console(out_path, &scanned, pipe_fds[1], *input, &next);
    if (r < 0 && errno != EINTR) {
      if (input != nullptr) ::close(pipe_fds[1]);
      return -1;
    }
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
