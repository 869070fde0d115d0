// boticelli-bench: runs one benchmark suite (or all) and prints one result per line.
#include <cstdio>
#include <cstring>

#include "bench.h"

namespace boticelli::bench {
namespace {
constexpr int kMaxSuites = 32;
Suite g_suites[kMaxSuites];
int g_suite_count = 0;
}  // namespace

bool register_suite(const Suite& suite) {
  if (g_suite_count >= kMaxSuites) {
    std::fprintf(stderr, "boticelli-bench: too many suites, '%s' dropped\n", suite.name);
    return false;
  }
  g_suites[g_suite_count++] = suite;
  return true;
}

}  // namespace boticelli::bench

namespace {
void usage(FILE* out) {
  std::fprintf(out, "usage: boticelli-bench SUITE|all [--json]\nsuites:\n");
  for (int i = 0; i < boticelli::bench::g_suite_count; ++i) {
    std::fprintf(out, "  %-14s %s\n", boticelli::bench::g_suites[i].name,
                 boticelli::bench::g_suites[i].description);
  }
}
}  // namespace

int main(int argc, char** argv) {
  const char* suite = nullptr;
  for (int i = 1; i < argc; ++i) {
    if (std::strcmp(argv[i], "--json") == 0) {
      boticelli::bench::set_json(true);
    } else if (std::strcmp(argv[i], "--help") == 0 || std::strcmp(argv[i], "-h") == 0) {
      usage(stdout);
      return 0;
    } else if (argv[i][0] == '-' || suite != nullptr) {
      std::fprintf(stderr, "boticelli-bench: unexpected argument '%s'\n", argv[i]);
      usage(stderr);
      return 2;
    } else {
      suite = argv[i];
    }
  }
  if (suite == nullptr) {
    usage(stderr);
    return 2;
  }
  int status = 0;
  bool found = false;
  for (int i = 0; i < boticelli::bench::g_suite_count; ++i) {
    const auto& s = boticelli::bench::g_suites[i];
    if (std::strcmp(suite, "all") == 0 || std::strcmp(suite, s.name) == 0) {
      found = true;
      if (s.run() != 0) {
        status = 1;
      }
    }
  }
  if (!found) {
    std::fprintf(stderr, "boticelli-bench: no suite '%s'\n", suite);
    usage(stderr);
    return 2;
  }
  return status;
}
