// libFuzzer target: the command line. The input is split at NUL bytes into argv[1..].
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <initializer_list>

#include "firmware/app/options.h"

namespace {
char g_bytes[4096 + 1];
const char* g_argv[64];
}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size > sizeof g_bytes - 1) return 0;
  std::memcpy(g_bytes, data, size);
  g_bytes[size] = '\0';
  int argc = 0;
  g_argv[argc++] = "boticelli";
  for (std::size_t at = 0; at <= size && argc < 63;) {
    g_argv[argc++] = g_bytes + at;
    at += std::strlen(g_bytes + at) + 1;
  }
  g_argv[argc] = nullptr;
  for (const bool simulated : {true, false}) {
    boticelli::firmware::Options options;
    const auto r = boticelli::firmware::parse_options(argc, g_argv, simulated, options);
    if (!r.ok && (r.error == nullptr || r.error[0] == '\0')) std::abort();
  }
  return 0;
}
