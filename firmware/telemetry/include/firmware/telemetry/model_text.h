// ModelText: the occupancy model's text as the console streams it: two buffers, and a new text
// is shown only once no reader holds the one it would replace (no torn `model` reply).
#pragma once

#include <array>
#include <cstddef>
#include <span>
#include <string_view>

#include "firmware/state/mission_state.h"

namespace boticelli::firmware {

class ModelText {
 public:
  static constexpr std::size_t kMaxBytes = MissionState::kMaxModelBytes;

  // No text (a fresh mission).
  void clear() {
    front_ = 0;
    bytes_ = {0, 0};
    pending_ = false;
  }
  // Where the next text is written; never the buffer a reader holds.
  [[nodiscard]] std::span<char> back() { return buffers_[1 - front_]; }
  // The first `bytes` of back() are the new text: it is shown now, or when the reader that
  // holds the current text releases it (a later text written meanwhile replaces it).
  void publish(std::size_t bytes) {
    bytes_[1 - front_] = bytes;
    pending_ = true;
    if (!held_) swap();
  }
  // The text shown now (empty when there is none).
  [[nodiscard]] std::string_view current() const {
    return {buffers_[front_].data(), bytes_[front_]};
  }
  // current(), kept unchanged until release().
  [[nodiscard]] std::string_view hold() {
    held_ = true;
    return current();
  }
  void release() {
    held_ = false;
    if (pending_) swap();
  }

 private:
  void swap() {
    front_ = 1 - front_;
    pending_ = false;
  }

  std::array<std::array<char, kMaxBytes>, 2> buffers_{};
  std::array<std::size_t, 2> bytes_{0, 0};
  std::size_t front_ = 0;
  bool pending_ = false;  // back() holds a newer text than current()
  bool held_ = false;
};

}  // namespace boticelli::firmware
