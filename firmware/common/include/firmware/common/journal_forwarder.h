// JournalForwarder: the console's log lines to the journal (stderr with sd-daemon priorities),
// written by a thread of its own so the cyclic path never blocks on the journal's pipe.
#pragma once

#include <array>
#include <atomic>
#include <cstddef>
#include <cstdint>
#include <string_view>
#include <thread>

#include "firmware/common/log.h"

namespace boticelli::firmware {

// One producer (the executive's thread: push() copies the line into a fixed slot, no lock,
// no system call, no allocation; a full queue drops the line and counts it), one consumer
// (the forwarder's thread, which wakes every 50 ms and writes each line to `fd` as
// "<N>text\n", N the level's sd-daemon priority: journald files it under that level).
class JournalForwarder {
 public:
  static constexpr std::size_t kSlots = 64;
  static constexpr std::size_t kTextBytes = LogRing::kTextBytes;

  JournalForwarder() = default;
  ~JournalForwarder() { stop(); }
  JournalForwarder(const JournalForwarder&) = delete;
  JournalForwarder& operator=(const JournalForwarder&) = delete;

  // Starts the thread writing to `fd` (not owned). False if it cannot start. At init.
  bool start(int fd);
  // Writes what is queued, then ends the thread.
  void stop();
  bool running() const { return thread_.joinable(); }
  // From the executive's thread only. False (dropped, counted) when the queue is full.
  bool push(LogLevel level, std::string_view text);
  std::uint64_t dropped() const { return dropped_.load(std::memory_order_relaxed); }
  std::uint64_t written() const { return written_.load(std::memory_order_relaxed); }
  // Writes what is queued now to the fd set here or by start() (the thread's work; tests
  // without the thread).
  void set_fd(int fd) { fd_ = fd; }
  void drain();

 private:
  struct Slot {
    LogLevel level = LogLevel::kInfo;
    std::uint8_t size = 0;
    std::array<char, kTextBytes> text{};
  };
  void run();

  std::array<Slot, kSlots> slots_{};
  std::atomic<std::uint64_t> head_{0};  // next slot the producer fills
  std::atomic<std::uint64_t> tail_{0};  // next slot the consumer writes
  std::atomic<std::uint64_t> dropped_{0};
  std::atomic<std::uint64_t> written_{0};
  std::atomic<bool> stop_{false};
  int fd_ = -1;
  std::thread thread_;
};

}  // namespace boticelli::firmware
