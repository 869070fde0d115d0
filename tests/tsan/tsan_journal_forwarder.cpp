// ThreadSanitizer check of the journal forwarder: the executive's thread pushes log lines while
// the forwarder's thread writes them to a pipe another thread reads; every line pushed and not
// dropped must arrive once, in order. A plain program, exit code 0 on success; any race
// report halts it.
#include <unistd.h>

#include <cstdio>
#include <cstdlib>
#include <string>
#include <thread>

#include "firmware/common/journal_forwarder.h"

namespace fw = boticelli::firmware;

int main() {
  int fds[2];
  if (::pipe(fds) != 0) return 2;
  std::string got;
  std::thread reader([&] {
    char buf[4096];
    ssize_t n = 0;
    while ((n = ::read(fds[0], buf, sizeof buf)) > 0) got.append(buf, static_cast<std::size_t>(n));
  });
  static fw::JournalForwarder journal;
  if (!journal.start(fds[1])) return 2;
  std::string expected;
  char line[64];
  for (int i = 0; i < 20000; ++i) {
    std::snprintf(line, sizeof line, "line %d", i);
    if (journal.push(i % 2 == 0 ? fw::LogLevel::kWarn : fw::LogLevel::kInfo, line)) {
      expected += (i % 2 == 0 ? "<4>" : "<6>") + std::string(line) + "\n";
    }
    if (i % 64 == 0) std::this_thread::yield();
  }
  journal.stop();
  ::close(fds[1]);
  reader.join();
  ::close(fds[0]);
  if (got != expected) {
    std::fprintf(stderr, "tsan_journal_forwarder: %zu bytes arrived, %zu expected\n", got.size(),
                 expected.size());
    return 1;
  }
  std::printf("tsan_journal_forwarder: %llu lines written, %llu dropped\n",
              static_cast<unsigned long long>(journal.written()),
              static_cast<unsigned long long>(journal.dropped()));
  return 0;
}
