// Benchmark suite "core": cost of the fixed-capacity containers (baseline for the others).
#include <cstdint>

#include "algo/core/fixed_vector.h"
#include "bench.h"

BOTICELLI_BENCH_SUITE(core, "fixed-capacity vector push/iterate cost") {
  constexpr int kRounds = 2000;
  static boticelli::core::FixedVector<std::int32_t, 4096> values;
  std::int64_t sum = 0;
  const std::int64_t t0 = boticelli::bench::now_ns();
  for (int r = 0; r < kRounds; ++r) {
    values.clear();
    for (std::int32_t i = 0; i < 4096; ++i) {
      (void)values.push_back(i ^ r);
    }
    for (const std::int32_t v : values) {
      sum += v;
    }
  }
  const std::int64_t t1 = boticelli::bench::now_ns();
  boticelli::bench::do_not_optimize(sum);
  boticelli::bench::JsonLine("core", "fixed_vector_push_iterate")
      .num("ns_per_element", static_cast<double>(t1 - t0) / (kRounds * 4096.0))
      .emit();
  return 0;
}
