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
//   BOTICELLI-STATE 5 / sequence N / cycle N / seed N / result running|found|not_found|aborted
//   [REASON] / pose X Y YAW / pose_time_ms MS / wheels none|wheels L R / goal none|goal X Y H
//   / obstacles N + N lines "X Y" / exploration N + N lines / grid CELL_M N + N lines "TX TY HEX"
//   (a tile's 256 log-odds, two hex digits each, rows south to north) / model BYTES + the bytes
//   + "\n" / log N + N lines "CYCLE TEXT" / end / crc32 XXXXXXXX (over everything before it).
// Versions 1 (a goal without its height), 2 (no sequence, no result), 3 (no pose time) and 4
// (no wheels, no grid) are still read: their sequence is 0 (before 3), their mission running,
// their pose's time unknown, no wheel counters, no grid.
// 5: the wheel counters, the grid; 6: the stereo's learnt bias
inline constexpr std::uint32_t kStateFormatVersion = 6;
inline constexpr std::size_t kMaxStateFileBytes =
    256 + 40 * (MissionState::kMaxObstaclePoints + MissionState::kMaxExplorationPoints) +
    MissionState::kMaxModelBytes + 32 + MissionState::kMaxLogEntries * 124 + 64 + 224 + 32 +
    worldmap::kMaxTiles * (16 + 2 * worldmap::kTileCells * worldmap::kTileCells);

// Writes the file's bytes into `out`; returns their count, 0 when `capacity` is too small.
// `sequence` numbers the saves of a state directory (StateStore: the newest copy wins).
std::size_t encode_state(const MissionState& state, char* out, std::size_t capacity,
                         std::uint64_t sequence = 0);
// Parses a whole file. On failure `out` is cleared, `error` says what was wrong. `sequence`
// (when given) receives the file's sequence number (0 before version 3).
bool decode_state(std::string_view file, MissionState& out, const char** error,
                  std::uint64_t* sequence = nullptr);
// Checks the checksum and reads the version and sequence number only (no body parsing).
bool peek_state(std::string_view file, std::uint64_t& sequence, const char** error);

// A state directory's permission bits (st_mode) are safe when neither its group nor others
// may write in it: no one but its owner can then put a file or a symlink where the state or
// its temporary file goes. (The systemd unit's StateDirectoryMode must pass.)
bool state_dir_mode_is_safe(unsigned mode);

enum class LoadResult : std::uint8_t { kLoaded, kMissing, kCorrupt, kIoError };

// The state directory. The mission state is kept in two copies, `mission.state.a` and
// `mission.state.b`; save() writes the one that does not hold the newest valid state, with the
// next sequence number, atomically (write_file_atomically: temporary file, fsync, rename,
// directory fsync). load() takes the valid copy with the highest sequence number, so a copy
// that a bad card or a cut write damaged costs one save, not the mission: the other copy is
// loaded and load_warning() says which copy was passed over and why. A state file of the
// single-file layout (`mission.state`, written before there were two copies) is one more
// candidate (sequence 0 unless it says otherwise); it is removed once both copies have been
// written after it. save_parameters() writes the console's saved parameters atomically.
class StateStore {
 public:
  static constexpr const char* kCopyNames[2] = {"mission.state.a", "mission.state.b"};
  static constexpr const char* kSingleFileName = "mission.state";  // the layout before A/B
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
  // Writes the older (or missing, or damaged) copy; on failure both copies stay as they were.
  bool save(const MissionState& state, char* error, std::size_t error_size);
  // Replaces `parameters.conf` with `text` (the console's `param save`), atomically.
  bool save_parameters(std::string_view text, char* error, std::size_t error_size);
  // kLoaded fills `out` from the newest valid copy (loaded_path() names it; load_warning() is
  // non-empty when another copy was damaged); kMissing when there is no copy at all;
  // kCorrupt (out cleared) when every copy is truncated, altered or of an unknown version,
  // kIoError when none could be read; the reasons, per copy, go to `error`.
  LoadResult load(MissionState& out, char* error, std::size_t error_size);
  const char* loaded_path() const { return loaded_path_.data(); }
  const char* load_warning() const { return warning_.data(); }
  // A new mission (no --resume) keeps the saved one instead of overwriting it: renames the
  // newest valid copy to `mission.state.1`, shifting older kept missions up to
  // `.kKeptStates` (the oldest is dropped), removes the other copies, then fsyncs the
  // directory. kMissing when there was nothing to keep; kLoaded (kept, `kept` holds the new
  // name) or kIoError with the reason in `error`. A kept file loads again when renamed to
  // `mission.state` with no other copies beside it.
  static constexpr int kKeptStates = 3;
  LoadResult keep_previous(char* kept, std::size_t kept_size, char* error, std::size_t error_size);
  const char* parameters_path() const { return parameters_path_.data(); }
  const char* directory() const { return dir_.data(); }
  bool is_open() const { return dir_[0] != '\0'; }
  std::uint64_t saves() const { return saves_; }
  // The sequence number the next save will carry.
  std::uint64_t next_sequence() const { return next_sequence_; }
  void set_crash_hook(SaveCrashHook hook, void* context) {
    crash_hook_ = hook;
    crash_context_ = context;
  }
  static constexpr std::size_t kWriteChunkBytes = kAtomicWriteChunkBytes;

 private:
  static constexpr int kCandidates = 3;  // copy A, copy B, the single file
  struct Copy {
    bool exists = false;
    bool valid = false;     // checksum and header good
    bool io_error = false;  // could not be read
    std::uint64_t sequence = 0;
    std::array<char, 160> why{};  // why it is not valid
  };
  // Reads candidate `i` into buffer_: kLoaded with `size`, kMissing, kIoError or kCorrupt
  // (larger than any valid state), with the reason in `why`.
  LoadResult read_candidate(int i, std::size_t& size, char* why, std::size_t why_size);
  // Looks at every candidate's checksum and sequence (fills copies_, newest_, next_sequence_).
  void survey();
  // The valid candidate with the highest sequence number, not in `skip_mask` (bit i: candidate
  // i); -1 when there is none.
  int newest_valid(int skip_mask) const;
  bool sync_dir(char* error, std::size_t error_size);

  std::array<char, 512> dir_{};
  std::array<std::array<char, 512>, kCandidates> paths_{};
  std::array<char, 512> parameters_path_{};
  std::array<char, 512> loaded_path_{};
  std::array<char, 512> warning_{};
  std::array<char, kMaxStateFileBytes> buffer_{};
  std::array<Copy, kCandidates> copies_{};
  bool surveyed_ = false;
  int newest_ = -1;  // the copy (0 or 1) holding the newest valid state, -1 for neither
  std::uint64_t next_sequence_ = 1;
  int copies_written_ = 0;  // A/B saves since open(), for removing the single file
  std::uint64_t saves_ = 0;
  bool refused_ = false;
  SaveCrashHook crash_hook_ = nullptr;
  void* crash_context_ = nullptr;
};

}  // namespace boticelli::firmware
