// StateSaver: the writer thread and the hand-over (see state_saver.h).
#include "firmware/state_saver.h"

#include <pthread.h>
#include <sched.h>

#include <cstdio>
#include <cstring>

namespace boticelli::firmware {

StateSaver::~StateSaver() {
  if (!thread_.joinable()) return;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    stop_ = true;
  }
  wake_.notify_one();
  thread_.join();
}

void StateSaver::start() {
  if (thread_.joinable()) return;
  thread_ = std::thread([this] { run(); });
  // The writer must never compete with the executive: normal scheduling even when the
  // process runs under SCHED_FIFO (threads inherit the creator's policy).
  sched_param normal{};
  normal.sched_priority = 0;
  pthread_setschedparam(thread_.native_handle(), SCHED_OTHER, &normal);
}

bool StateSaver::submit(const MissionState& state) {
  if (!thread_.joinable()) {
    // Not started: save right here (simulation, tests).
    char error[256] = "";
    const bool ok = store_.save(state, error, sizeof error);
    std::lock_guard<std::mutex> lock(mutex_);
    if (ok) {
      ++saved_;
    } else {
      ++failures_;
      std::snprintf(error_, sizeof error_, "%s", error);
    }
    return true;
  }
  std::unique_lock<std::mutex> lock(mutex_, std::try_to_lock);
  if (!lock.owns_lock()) return false;
  pending_ = state;
  has_pending_ = true;
  lock.unlock();
  wake_.notify_one();
  return true;
}

void StateSaver::flush() {
  std::unique_lock<std::mutex> lock(mutex_);
  idle_.wait(lock, [this] { return !has_pending_ && !busy_; });
}

std::uint64_t StateSaver::saved() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return saved_;
}

std::uint64_t StateSaver::failures() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return failures_;
}

void StateSaver::last_error(char* out, std::size_t size) const {
  std::lock_guard<std::mutex> lock(mutex_);
  std::snprintf(out, size, "%s", error_);
}

void StateSaver::run() {
  std::unique_lock<std::mutex> lock(mutex_);
  for (;;) {
    wake_.wait(lock, [this] { return stop_ || has_pending_; });
    if (!has_pending_ && stop_) break;
    writing_ = pending_;
    has_pending_ = false;
    busy_ = true;
    lock.unlock();
    char error[256] = "";
    const bool ok = store_.save(writing_, error, sizeof error);
    lock.lock();
    busy_ = false;
    if (ok) {
      ++saved_;
    } else {
      ++failures_;
      std::snprintf(error_, sizeof error_, "%s", error);
    }
    if (!has_pending_) idle_.notify_all();
  }
  idle_.notify_all();
}

}  // namespace boticelli::firmware
