// AllocationGuard: counts heap allocations in a scope, to prove a cyclic path allocates nothing.
#pragma once

#include <cstddef>

#include "CppUTest/TestHarness.h"

namespace boticelli::test {

// While a guard lives, every operator new / new[] (through CppUTest's allocators, which
// Debian's static CppUTest routes the global operator new to), every over-aligned new
// (replaced in alloc_guard.cpp) and every malloc, calloc, realloc, posix_memalign,
// aligned_alloc and memalign made by the test binary's code (linked with --wrap) is counted.
// Not seen: allocations made inside shared libraries (libc's own, e.g. by fopen, strdup or
// getaddrinfo; libstdc++'s, e.g. of exceptions; libpng's) and mmap or sbrk called directly
// (docs/testing.md). Guards do not nest. Use CHECK_NO_ALLOCATION for the common case.
class AllocationGuard {
 public:
  AllocationGuard();
  ~AllocationGuard();
  AllocationGuard(const AllocationGuard&) = delete;
  AllocationGuard& operator=(const AllocationGuard&) = delete;

  // Allocation calls seen since construction (one `new` may count twice: once as
  // operator new, once as the malloc beneath it; any allocation makes this non-zero).
  [[nodiscard]] std::size_t allocations() const;
  // Stops counting early (the destructor does it otherwise).
  void stop();

 private:
  bool active_ = true;
};

}  // namespace boticelli::test

// Runs `statement` and fails the test if it allocated on the heap.
#define CHECK_NO_ALLOCATION(statement)                                                    \
  do {                                                                                    \
    std::size_t boticelli_allocs_ = 0;                                                    \
    {                                                                                     \
      boticelli::test::AllocationGuard boticelli_guard_;                                  \
      statement;                                                                          \
      boticelli_allocs_ = boticelli_guard_.allocations();                                 \
    }                                                                                     \
    UNSIGNED_LONGS_EQUAL_TEXT(0U, boticelli_allocs_, "heap allocations in: " #statement); \
  } while (false)
