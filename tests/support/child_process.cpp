// Forked children in tests (see child_process.h).
#include "child_process.h"

#include <sys/wait.h>

#include <csignal>
#include <ctime>

namespace boticelli::test {

int wait_for_child(pid_t child, int timeout_ms) {
  for (int waited_ms = 0; waited_ms < timeout_ms; waited_ms += 10) {
    int status = 0;
    if (waitpid(child, &status, WNOHANG) == child) return status;
    timespec ms10{0, 10000000L};
    nanosleep(&ms10, nullptr);
  }
  kill(child, SIGKILL);
  waitpid(child, nullptr, 0);
  return -1;
}

}  // namespace boticelli::test
