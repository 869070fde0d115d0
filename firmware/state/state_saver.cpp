// StateSaver: the writer thread and the hand-over (see state_saver.h).
#include "firmware/state/state_saver.h"

#include <pthread.h>
#include <sched.h>

#include <chrono>
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
    failing_ = !ok;
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
  idle_.wait(lock, [this] { return !has_pending_ && !has_parameters_ && !busy_; });
}

void StateSaver::save_parameters_now(std::string_view text) {
  char error[256] = "";
  const bool ok = store_.save_parameters(text, error, sizeof error);
  if (!ok) {
    std::lock_guard<std::mutex> lock(mutex_);
    std::snprintf(parameter_error_, sizeof parameter_error_, "%s", error);
  }
  // Counted after the reason is stored, so a reader that sees the count finds the reason.
  (ok ? parameter_saves_ : parameter_failures_).fetch_add(1);
}

StateSaver::Submitted StateSaver::submit_parameters(std::string_view text) {
  if (text.size() > parameters_pending_.size()) return Submitted::kTooLong;
  if (!thread_.joinable()) {
    const std::uint64_t failures = parameter_failures_.load();
    save_parameters_now(text);
    return parameter_failures_.load() == failures ? Submitted::kSaved : Submitted::kFailed;
  }
  std::unique_lock<std::mutex> lock(mutex_, std::try_to_lock);
  if (!lock.owns_lock()) return Submitted::kBusy;
  std::memcpy(parameters_pending_.data(), text.data(), text.size());
  parameters_pending_bytes_ = text.size();
  has_parameters_ = true;
  lock.unlock();
  wake_.notify_one();
  return Submitted::kQueued;
}

bool StateSaver::parameter_error(char* out, std::size_t size) const {
  std::unique_lock<std::mutex> lock(mutex_, std::try_to_lock);
  if (!lock.owns_lock()) return false;
  std::snprintf(out, size, "%s", parameter_error_);
  return true;
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

bool StateSaver::try_last_error(char* out, std::size_t size) const {
  std::unique_lock<std::mutex> lock(mutex_, std::try_to_lock);
  if (!lock.owns_lock()) return false;
  std::snprintf(out, size, "%s", error_);
  return true;
}

bool StateSaver::failing() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return failing_;
}

std::uint64_t StateSaver::retries() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return retries_;
}

void StateSaver::run() {
  std::unique_lock<std::mutex> lock(mutex_);
  const auto work = [this] { return stop_ || has_pending_ || has_parameters_; };
  for (;;) {
    // After a failed save, wait for new work at most one retry interval, then write the same
    // state again (a newer state, when one comes, replaces it).
    bool retry = false;
    if (retry_due_) {
      retry = !wake_.wait_for(lock, std::chrono::milliseconds(retry_interval_ms_), work);
    } else {
      wake_.wait(lock, work);
    }
    if (!retry && !has_pending_ && !has_parameters_ && stop_) break;
    if (has_parameters_) {
      const std::size_t bytes = parameters_pending_bytes_;
      std::memcpy(parameters_writing_.data(), parameters_pending_.data(), bytes);
      has_parameters_ = false;
      busy_ = true;
      lock.unlock();
      save_parameters_now({parameters_writing_.data(), bytes});
      lock.lock();
      busy_ = false;
      if (!has_pending_ && !has_parameters_) idle_.notify_all();
      continue;
    }
    if (has_pending_) {
      writing_ = pending_;
      has_pending_ = false;
    } else {
      ++retries_;  // retry: writing_ still holds the state that failed
    }
    busy_ = true;
    lock.unlock();
    char error[256] = "";
    const bool ok = store_.save(writing_, error, sizeof error);
    lock.lock();
    busy_ = false;
    failing_ = !ok;
    retry_due_ = !ok;
    if (ok) {
      ++saved_;
    } else {
      ++failures_;
      std::snprintf(error_, sizeof error_, "%s", error);
    }
    if (!has_pending_ && !has_parameters_) idle_.notify_all();
  }
  idle_.notify_all();
}

}  // namespace boticelli::firmware
