// StateSaver: saves the mission state from a writer thread, so fsync never stalls the executive's
// frames.
#pragma once

#include <condition_variable>
#include <cstdint>
#include <mutex>
#include <thread>

#include "firmware/mission_state.h"
#include "firmware/persistence.h"

namespace boticelli::firmware {

// The executive's thread only copies the state into a hand-over buffer (try_lock, no I/O,
// no allocation); the writer thread (normal scheduling, started at init) encodes and saves
// it atomically through the StateStore. When states come faster than the disk takes them,
// the newest one waits and older, not yet started ones are dropped (each file is a
// complete state, so only the latest matters).
class StateSaver {
 public:
  explicit StateSaver(StateStore& store) : store_(store) {}
  ~StateSaver();
  StateSaver(const StateSaver&) = delete;
  StateSaver& operator=(const StateSaver&) = delete;

  // Starts the writer thread (allocates: call at init). Without it submit() saves in the
  // caller's thread (the sim board, where the clock stands still while code runs anyway).
  void start();
  // Hands a copy of `state` to the writer; false (nothing changed) when the writer is just
  // taking the previous one: call again in a later slice.
  bool submit(const MissionState& state);
  // Waits until every submitted state is on disk or has failed (shutdown, tests).
  void flush();
  std::uint64_t saved() const;
  std::uint64_t failures() const;
  // The last failure's reason, copied into `out`.
  void last_error(char* out, std::size_t size) const;

 private:
  void run();

  StateStore& store_;
  mutable std::mutex mutex_;
  std::condition_variable wake_;
  std::condition_variable idle_;
  MissionState pending_;  // guarded by mutex_
  bool has_pending_ = false;
  bool busy_ = false;
  bool stop_ = false;
  std::uint64_t saved_ = 0;
  std::uint64_t failures_ = 0;
  char error_[256] = "";
  MissionState writing_;  // the writer thread's own copy
  std::thread thread_;
};

}  // namespace boticelli::firmware
