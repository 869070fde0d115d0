// libFuzzer target: the mission state file's body parser. The input is the body; its CRC line
// is appended here, so every input passes the checksum and reaches decode_body. An accepted
// state must encode and decode back to itself.
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>

#include "firmware/state/mission_state.h"
#include "firmware/state/persistence.h"

namespace fw = boticelli::firmware;

namespace {
fw::MissionState g_state;
fw::MissionState g_again;
char g_file[fw::kMaxStateFileBytes + 16];
char g_encoded[fw::kMaxStateFileBytes];
}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size + 15 > sizeof g_file) return 0;
  std::memcpy(g_file, data, size);
  std::snprintf(g_file + size, 16, "crc32 %08x\n", fw::crc32(data, size));
  const char* error = "";
  if (!fw::decode_state({g_file, size + 15}, g_state, &error)) {
    if (error == nullptr || error[0] == '\0') std::abort();
    if (g_state.cycle != 0 || g_state.obstacles.size() != 0) std::abort();  // nothing half-loaded
    return 0;
  }
  const std::size_t n = fw::encode_state(g_state, g_encoded, sizeof g_encoded);
  if (n == 0) std::abort();
  if (!fw::decode_state({g_encoded, n}, g_again, &error)) {
    std::fprintf(stderr, "fuzz_state_file: re-encoded state rejected: %s\n", error);
    std::abort();
  }
  if (!(g_again == g_state)) std::abort();
  return 0;
}
