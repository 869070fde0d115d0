// DurationHistogram: counts of durations in buckets about 3% wide, for the worst case and the
// percentiles of any number of runs in a fixed 4 KB (no samples kept, no heap).
#pragma once

#include <array>
#include <bit>
#include <cstddef>
#include <cstdint>

namespace boticelli::firmware {

// Durations [ns]: exact below 64 ns, then 32 buckets per power of two (a bucket is at most
// 1/32 of its lower edge wide), up to kMaxNs; longer ones land in the last bucket (the worst
// case is kept exactly beside the buckets). add() is O(1) and never allocates.
class DurationHistogram {
 public:
  static constexpr unsigned kSubBits = 5;
  static constexpr std::uint64_t kSub = std::uint64_t{1} << kSubBits;
  static constexpr unsigned kMaxBit = 34;  // 2^34 ns ≈ 17 s
  static constexpr std::uint64_t kMaxNs = (std::uint64_t{1} << kMaxBit) - 1;
  static constexpr std::size_t kBuckets = (kMaxBit - kSubBits + 1U) * kSub;

  // The bucket of `ns` (clamped to kMaxNs).
  static constexpr std::size_t bucket(std::uint64_t ns) {
    if (ns > kMaxNs) ns = kMaxNs;
    if (ns < 2 * kSub) return static_cast<std::size_t>(ns);
    const unsigned shift = static_cast<unsigned>(std::bit_width(ns)) - 1U - kSubBits;
    return static_cast<std::size_t>(shift * kSub + (ns >> shift));
  }
  // The longest duration bucket `i` holds [ns].
  static constexpr std::uint64_t bucket_upper_ns(std::size_t i) {
    if (i < 2 * kSub) return i;
    const std::uint64_t shift = i / kSub - 1U;
    const std::uint64_t mantissa = i - shift * kSub;
    return ((mantissa + 1U) << shift) - 1U;
  }

  void add(std::uint64_t ns) {
    ++counts_[bucket(ns)];
    ++count_;
    total_ns_ += ns;
    if (ns > max_ns_) max_ns_ = ns;
  }
  void clear() {
    counts_.fill(0);
    count_ = 0;
    total_ns_ = 0;
    max_ns_ = 0;
  }

  [[nodiscard]] std::uint64_t count() const { return count_; }
  [[nodiscard]] std::uint64_t max_ns() const { return max_ns_; }
  [[nodiscard]] std::uint64_t average_ns() const { return count_ == 0 ? 0 : total_ns_ / count_; }
  // The p-quantile (0 < per_mille ≤ 1000, e.g. 990 for p99) as the upper edge of its bucket,
  // never above the worst case: at most about 3% above the true value, never below it. 0
  // when empty.
  [[nodiscard]] std::uint64_t percentile_ns(std::uint32_t per_mille) const {
    if (count_ == 0) return 0;
    // The smallest rank r with r ≥ count·p (at least the first).
    std::uint64_t rank = (count_ * per_mille + 999U) / 1000U;
    if (rank == 0) rank = 1;
    std::uint64_t seen = 0;
    for (std::size_t i = 0; i < kBuckets; ++i) {
      seen += counts_[i];
      if (seen >= rank) {
        const std::uint64_t upper = bucket_upper_ns(i);
        return upper < max_ns_ ? upper : max_ns_;
      }
    }
    return max_ns_;
  }

 private:
  std::array<std::uint32_t, kBuckets> counts_{};
  std::uint64_t count_ = 0;
  std::uint64_t total_ns_ = 0;
  std::uint64_t max_ns_ = 0;
};

static_assert(DurationHistogram::bucket(DurationHistogram::kMaxNs) ==
                  DurationHistogram::kBuckets - 1,
              "the longest duration fills the last bucket");
static_assert(DurationHistogram::bucket_upper_ns(DurationHistogram::kBuckets - 1) ==
                  DurationHistogram::kMaxNs,
              "the buckets end at kMaxNs");

}  // namespace boticelli::firmware
