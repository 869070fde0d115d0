// WorldTruthFile: the simulated world's true state in a file of its own, which outlives the
// firmware as the physical world does (a killed firmware's robot stands where it stood).
#pragma once

#include <cstddef>
#include <cstdint>

#include "hal/sim/sim_world.h"

namespace boticelli::boards::sim {

// A fixed-size binary file mapped shared into memory: record() is plain stores into the
// mapping (no system call, no allocation), so the newest record survives a kill -9 of the
// process (the kernel keeps the page). Two slots, each with a sequence number and a checksum,
// are written in turn; load() takes the newest whole one. The header names the world the
// state belongs to (a hash of its geometry): a file of another world is not loaded.
class WorldTruthFile {
 public:
  WorldTruthFile() = default;
  ~WorldTruthFile() { close(); }
  WorldTruthFile(const WorldTruthFile&) = delete;
  WorldTruthFile& operator=(const WorldTruthFile&) = delete;

  enum class Load : std::uint8_t { kLoaded, kMissing, kOtherWorld, kDamaged };
  // Reads `path` without keeping it open; kLoaded fills `out`. `why` says what was wrong.
  static Load load(const char* path, std::uint64_t world_id, hal::sim::SimWorld::PhysicalState& out,
                   char* why, std::size_t why_size);
  // Creates or takes over `path` (a regular file, not a symlink) for `world_id`, emptied.
  bool open(const char* path, std::uint64_t world_id, char* error, std::size_t error_size);
  bool is_open() const { return map_ != nullptr; }
  void record(const hal::sim::SimWorld::PhysicalState& state);
  void close();
  std::uint64_t records() const { return sequence_; }

  // A world's identity: FNV-1a over its start pose and colliders.
  static std::uint64_t world_id(const hal::sim::World& world);

  struct Slot {
    std::uint64_t sequence;  // 0: never written
    double values[7];        // x, y, yaw, wheel counters left/right, wheel speeds left/right
    std::uint64_t checksum;  // FNV-1a over sequence and values
  };
  struct Layout {
    char magic[8];
    std::uint64_t world_id;
    Slot slots[2];
  };

 private:
  Layout* map_ = nullptr;
  std::uint64_t sequence_ = 0;
};

}  // namespace boticelli::boards::sim
