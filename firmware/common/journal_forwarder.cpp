// JournalForwarder: a single-producer single-consumer queue of log lines and the thread that
// writes them to the journal's stream.
#include "firmware/common/journal_forwarder.h"

#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <chrono>
#include <cstdio>
#include <cstring>
#include <system_error>

namespace boticelli::firmware {

bool JournalForwarder::start(int fd) {
  if (thread_.joinable() || fd < 0) return false;
  fd_ = fd;
  stop_.store(false);
  try {
    thread_ = std::thread([this] { run(); });
  } catch (const std::system_error&) {
    return false;
  }
  return true;
}

void JournalForwarder::stop() {
  if (!thread_.joinable()) return;
  stop_.store(true);
  thread_.join();
  drain();  // anything pushed after the thread's last pass
}

bool JournalForwarder::push(LogLevel level, std::string_view text) {
  const std::uint64_t head = head_.load(std::memory_order_relaxed);
  if (head - tail_.load(std::memory_order_acquire) >= kSlots) {
    dropped_.fetch_add(1, std::memory_order_relaxed);
    return false;
  }
  Slot& slot = slots_[head % kSlots];
  const std::size_t n = std::min(text.size(), kTextBytes);
  std::memcpy(slot.text.data(), text.data(), n);
  slot.size = static_cast<std::uint8_t>(n);
  slot.level = level;
  head_.store(head + 1, std::memory_order_release);
  return true;
}

void JournalForwarder::drain() {
  std::uint64_t tail = tail_.load(std::memory_order_relaxed);
  const std::uint64_t head = head_.load(std::memory_order_acquire);
  for (; tail != head; ++tail) {
    const Slot& slot = slots_[tail % kSlots];
    char line[kTextBytes + 8];
    const int prefix = std::snprintf(line, sizeof line, "<%d>", log_priority(slot.level));
    std::size_t size = static_cast<std::size_t>(prefix);
    // One line per entry: a newline inside the text would start a line at the default level.
    for (std::size_t i = 0; i < slot.size; ++i) {
      line[size++] = slot.text[i] == '\n' ? ' ' : slot.text[i];
    }
    line[size++] = '\n';
    std::size_t off = 0;
    while (off < size) {
      const ssize_t w = ::write(fd_, line + off, size - off);
      if (w < 0 && errno == EINTR) continue;
      if (w <= 0) break;  // the journal gone: the line is lost, the robot goes on
      off += static_cast<std::size_t>(w);
    }
    written_.fetch_add(1, std::memory_order_relaxed);
    tail_.store(tail + 1, std::memory_order_release);
  }
}

void JournalForwarder::run() {
  while (!stop_.load()) {
    drain();
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
  }
  drain();
}

}  // namespace boticelli::firmware
