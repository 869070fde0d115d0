// Persistence: the mission state file — versioned text with a CRC32, strict loading, atomic saving.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <string_view>

#include "firmware/state/atomic_file.h"
#include "firmware/state/mission_state.h"

namespace boticelli::firmware {

// CRC-32 (IEEE 802.3, reflected, polynomial 0xEDB88320), as zlib's crc32().
std::uint32_t crc32(const void* data, std::size_t size, std::uint32_t crc = 0);

// Format (docs/console.md "State directory"):
//   BOTICELLI-STATE 1 / cycle N / seed N / pose X Y YAW / goal none|goal X Y /
//   obstacles N + N lines "X Y" / exploration N + N lines / model BYTES + the bytes + "\n" /
//   log N + N lines "CYCLE TEXT" / end / crc32 XXXXXXXX (over everything before that line).
inline constexpr std::uint32_t kStateFormatVersion = 2;  // 2: the goal has a height
inline constexpr std::size_t kMaxStateFileBytes =
    256 + 40 * (MissionState::kMaxObstaclePoints + MissionState::kMaxExplorationPoints) +
    MissionState::kMaxModelBytes + 32 + MissionState::kMaxLogEntries * 124 + 64;

// Writes the file's bytes into `out`; returns their count, 0 when `capacity` is too small.
std::size_t encode_state(const MissionState& state, char* out, std::size_t capacity);
// Parses a whole file. On failure `out` is cleared, `error` says what was wrong.
bool decode_state(std::string_view file, MissionState& out, const char** error);

// A state directory's permission bits (st_mode) are safe when neither its group nor others
// may write in it: no one but its owner can then put a file or a symlink where the state or
// its temporary file goes. (The systemd unit's StateDirectoryMode must pass.)
bool state_dir_mode_is_safe(unsigned mode);

enum class LoadResult : std::uint8_t { kLoaded, kMissing, kCorrupt, kIoError };

// The state directory. save() is atomic (write_file_atomically): it writes
// `mission.state.tmp`, fsyncs it, renames it over `mission.state` and fsyncs the directory,
// so after a crash at any point the file is either the previous state or the new one, never
// a mix. save_parameters() does the same for the console's saved parameters.
class StateStore {
 public:
  static constexpr const char* kFileName = "mission.state";
  static constexpr const char* kParametersFileName = "parameters.conf";

  StateStore() = default;
  StateStore(const StateStore&) = delete;
  StateStore& operator=(const StateStore&) = delete;

  // Uses `dir`, creating it (one level, mode 0750) when missing. False with a reason
  // otherwise; refused() then tells a directory that is there but must not be used (not a
  // directory, not owned by this process's user, or writable by its group or others: see
  // state_dir_mode_is_safe) from one that could not be created.
  bool open(const char* dir, char* error, std::size_t error_size);
  bool refused() const { return refused_; }
  bool save(const MissionState& state, char* error, std::size_t error_size);
  // Replaces `parameters.conf` with `text` (the console's `param save`), atomically.
  bool save_parameters(std::string_view text, char* error, std::size_t error_size);
  // kLoaded fills `out`; kMissing when there is no state file; kCorrupt (out cleared) when
  // the file is truncated, altered or from another version; the reason goes to `error`.
  LoadResult load(MissionState& out, char* error, std::size_t error_size);
  // A new mission (no --resume) keeps the saved one instead of overwriting it: renames
  // `mission.state` to `mission.state.1`, shifting older copies up to `.kKeptStates` (the
  // oldest is dropped), then fsyncs the directory. kMissing when there was nothing to keep;
  // kLoaded (kept, `kept` holds the new name) or kIoError with the reason in `error`.
  static constexpr int kKeptStates = 3;
  LoadResult keep_previous(char* kept, std::size_t kept_size, char* error, std::size_t error_size);
  const char* path() const { return path_.data(); }
  const char* parameters_path() const { return parameters_path_.data(); }
  bool is_open() const { return dir_[0] != '\0'; }
  std::uint64_t saves() const { return saves_; }
  void set_crash_hook(SaveCrashHook hook, void* context) {
    crash_hook_ = hook;
    crash_context_ = context;
  }
  static constexpr std::size_t kWriteChunkBytes = kAtomicWriteChunkBytes;

 private:
  std::array<char, 512> dir_{};
  std::array<char, 512> path_{};
  std::array<char, 512> parameters_path_{};
  std::array<char, kMaxStateFileBytes> buffer_{};
  std::uint64_t saves_ = 0;
  bool refused_ = false;
  SaveCrashHook crash_hook_ = nullptr;
  void* crash_context_ = nullptr;
};

}  // namespace boticelli::firmware
