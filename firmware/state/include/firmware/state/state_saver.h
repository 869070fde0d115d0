// StateSaver: saves the mission state from a writer thread, so fsync never stalls the executive's
// frames.
#pragma once

#include <array>
#include <atomic>
#include <condition_variable>
#include <cstdint>
#include <mutex>
#include <string_view>
#include <thread>

#include "firmware/state/mission_state.h"
#include "firmware/common/parameters.h"
#include "firmware/state/persistence.h"

namespace boticelli::firmware {

// The executive's thread only copies the state into a hand-over buffer (try_lock, no I/O,
// no allocation); the writer thread (normal scheduling, started at init) encodes and saves
// it atomically through the StateStore. When states come faster than the disk takes them,
// the newest one waits and older, not yet started ones are dropped (each file is a
// complete state, so only the latest matters). A save that fails is tried again by the writer
// thread every retry interval (1 s by default) until it succeeds or a newer state replaces
// it, so a full or briefly unwritable disk loses nothing once it recovers, even when the
// mission submits nothing more (a finished or held one). The console's saved parameters take
// the same road (submit_parameters), so `param save` never waits for the disk either.
class StateSaver {
 public:
  explicit StateSaver(StateStore& store) : store_(store) {}
  ~StateSaver();
  StateSaver(const StateSaver&) = delete;
  StateSaver& operator=(const StateSaver&) = delete;

  // Starts the writer thread (allocates: call at init). Without it submit() saves in the
  // caller's thread (the sim board, where the clock stands still while code runs anyway) and
  // a failed save is retried only by the next submit.
  void start();
  // How long the writer thread waits before trying a failed save again (before start()).
  void set_retry_interval_ms(std::uint32_t ms) { retry_interval_ms_ = ms; }
  // Failed saves that the writer thread tried again (each also counts in failures() or
  // saved()).
  std::uint64_t retries() const;
  // Hands a copy of `state` to the writer; false (nothing changed) when the writer is just
  // taking the previous one: call again in a later slice.
  bool submit(const MissionState& state);
  // Waits until every submitted state is on disk or has failed (shutdown, tests).
  void flush();
  std::uint64_t saved() const;
  std::uint64_t failures() const;
  // The last failure's reason, copied into `out`.
  void last_error(char* out, std::size_t size) const;
  // The same without waiting (the executive's thread): false, nothing copied, while the
  // writer holds the lock; try again in a later frame.
  bool try_last_error(char* out, std::size_t size) const;
  // True while the newest save attempt failed (storage unhealthy); a later success clears it.
  bool failing() const;

  enum class Submitted : std::uint8_t {
    kQueued,  // handed to the writer thread; parameter_saves() or parameter_failures() counts it
    kSaved,   // written at once (no writer thread)
    kFailed,  // written at once and failed: parameter_error() says why
    kBusy,    // the writer is taking the previous text: try again later
    kTooLong  // longer than ParameterTable::kMaxFileBytes
  };
  // Hands a copy of the parameter file's text to the writer (try_lock, no I/O, no
  // allocation), or writes it at once when the thread is not started.
  Submitted submit_parameters(std::string_view text);
  std::uint64_t parameter_saves() const { return parameter_saves_.load(); }
  std::uint64_t parameter_failures() const { return parameter_failures_.load(); }
  // The last failed parameter save's reason into `out`; false (nothing copied) when the
  // writer holds the lock just now (try again later). Never blocks.
  bool parameter_error(char* out, std::size_t size) const;
  const char* parameters_path() const { return store_.parameters_path(); }

 private:
  void run();
  void save_parameters_now(std::string_view text);  // counts the result

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
  bool failing_ = false;    // guarded by mutex_
  bool retry_due_ = false;  // writing_ failed and nothing newer came yet; guarded by mutex_
  std::uint64_t retries_ = 0;
  std::uint32_t retry_interval_ms_ = 1000;
  char error_[256] = "";
  MissionState writing_;  // the writer thread's own copy
  std::array<char, ParameterTable::kMaxFileBytes> parameters_pending_{};  // guarded by mutex_
  std::size_t parameters_pending_bytes_ = 0;
  bool has_parameters_ = false;
  std::array<char, ParameterTable::kMaxFileBytes> parameters_writing_{};  // the writer's copy
  std::atomic<std::uint64_t> parameter_saves_{0};
  std::atomic<std::uint64_t> parameter_failures_{0};
  char parameter_error_[256] = "";  // guarded by mutex_
  std::thread thread_;
};

}  // namespace boticelli::firmware
