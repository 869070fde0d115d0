// Benchmark registry and JSON-lines output for boticelli-bench (benchmarks report, tests assert).
#pragma once

#include <chrono>
#include <cstdint>
#include <cstdio>

namespace boticelli::bench {

// One JSON object per line: {"suite":"aln","case":"eval_plain","pieces":32,"ns_per_op":12.3}
class JsonLine {
 public:
  JsonLine(const char* suite, const char* name);
  JsonLine& num(const char* key, double value);
  JsonLine& integer(const char* key, std::int64_t value);
  JsonLine& text(const char* key, const char* value);
  JsonLine& flag(const char* key, bool value);
  // Prints the line (as JSON with --json, else as "suite case key=value ...").
  void emit();

 private:
  char buffer_[2048];
  std::size_t used_ = 0;
  bool overflow_ = false;
  void append(const char* fmt, ...) __attribute__((format(printf, 2, 3)));
};

// Suites register themselves: BOTICELLI_BENCH_SUITE(aln, "ALN evaluation and training") { ... }
using SuiteFn = int (*)();
struct Suite {
  const char* name;
  const char* description;
  SuiteFn run;
};
bool register_suite(const Suite& suite);
void set_json(bool json);
bool json();

// Monotonic wall time in ns, for timing loops.
inline std::int64_t now_ns() {
  return std::chrono::duration_cast<std::chrono::nanoseconds>(
             std::chrono::steady_clock::now().time_since_epoch())
      .count();
}

// Keeps the optimiser from discarding a result.
template <typename T>
inline void do_not_optimize(const T& value) {
  asm volatile("" : : "r,m"(value) : "memory");
}

}  // namespace boticelli::bench

#define BOTICELLI_BENCH_SUITE(id, description)                                 \
  static int bench_suite_##id();                                               \
  [[maybe_unused]] static const bool bench_registered_##id =                   \
      boticelli::bench::register_suite({#id, description, &bench_suite_##id}); \
  static int bench_suite_##id()
