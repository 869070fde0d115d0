// Tests of the allocation guard: it must catch allocations and stay quiet on allocation-free code.
#include <malloc.h>

#include <array>
#include <cstdint>
#include <cstdlib>
#include <numeric>
#include <vector>

#include <Eigen/Dense>

#include "algo/core/fixed_vector.h"
#include "alloc_guard.h"
#include "CppUTest/TestHarness.h"

TEST_GROUP(AllocationGuard){};

TEST(AllocationGuard, CatchesAGrowingStdVector) {
  std::vector<int> values;
  std::size_t seen = 0;
  {
    boticelli::test::AllocationGuard guard;
    for (int i = 0; i < 100; ++i) {
      values.push_back(i);
    }
    seen = guard.allocations();
  }
  CHECK(seen > 0);
  LONGS_EQUAL(100, static_cast<long>(values.size()));
}

TEST(AllocationGuard, CatchesADirectMalloc) {
  void* volatile p = nullptr;
  std::size_t seen = 0;
  {
    boticelli::test::AllocationGuard guard;
    p = std::malloc(64);
    seen = guard.allocations();
  }
  std::free(p);
  CHECK(seen > 0);
}

// CppUTest's `new` macro (leak detection with file and line) has no over-aligned form; the
// plain new-expressions below must reach the replaceable aligned operator new.
#undef new

namespace {
struct alignas(128) CacheLines {
  unsigned char bytes[256];
};
}  // namespace

TEST(AllocationGuard, CatchesOverAlignedNew) {
  static_assert(alignof(CacheLines) > __STDCPP_DEFAULT_NEW_ALIGNMENT__);
  CacheLines* volatile one = nullptr;
  CacheLines* volatile many = nullptr;
  std::size_t seen_one = 0;
  std::size_t seen_many = 0;
  {
    boticelli::test::AllocationGuard guard;
    one = new CacheLines{};
    seen_one = guard.allocations();
    many = new CacheLines[3];
    seen_many = guard.allocations() - seen_one;
  }
  CHECK(reinterpret_cast<std::uintptr_t>(one) % 128 == 0);
  CHECK(reinterpret_cast<std::uintptr_t>(many) % 128 == 0);
  delete one;
  delete[] many;
  CHECK(seen_one > 0);
  CHECK(seen_many > 0);
}

TEST(AllocationGuard, CatchesEachAlignedAllocationCall) {
  void* p = nullptr;
  void* volatile q = nullptr;
  void* volatile r = nullptr;
  std::size_t seen[3] = {};
  {
    boticelli::test::AllocationGuard guard;
    CHECK_EQUAL(0, posix_memalign(&p, 64, 100));
    seen[0] = guard.allocations();
    q = std::aligned_alloc(64, 128);
    seen[1] = guard.allocations() - seen[0];
    r = memalign(64, 100);
    seen[2] = guard.allocations() - seen[0] - seen[1];
  }
  std::free(p);
  std::free(q);
  std::free(r);
  CHECK(seen[0] > 0);
  CHECK(seen[1] > 0);
  CHECK(seen[2] > 0);
}

TEST(AllocationGuard, CatchesADynamicEigenMatrix) {
  std::size_t seen = 0;
  {
    boticelli::test::AllocationGuard guard;
    Eigen::MatrixXd m = Eigen::MatrixXd::Identity(8, 8);
    seen = guard.allocations();
    CHECK(m(0, 0) > 0.5);
  }
  CHECK(seen > 0);
}

TEST(AllocationGuard, PassesOnAllocationFreeCode) {
  boticelli::core::FixedVector<int, 128> values;
  std::array<double, 16> squares{};
  Eigen::Matrix4d a = Eigen::Matrix4d::Identity();
  CHECK_NO_ALLOCATION({
    for (int i = 0; i < 100; ++i) {
      CHECK(values.push_back(i));
    }
    for (std::size_t i = 0; i < squares.size(); ++i) {
      squares[i] = static_cast<double>(i * i);
    }
    a = a * 2.0 + Eigen::Matrix4d::Ones();
  });
  LONGS_EQUAL(4950, std::accumulate(values.begin(), values.end(), 0));
  DOUBLES_EQUAL(3.0, a(0, 0), 1e-12);
}

TEST(AllocationGuard, RestoresTheAllocatorsSoLaterAllocationsAreNotCounted) {
  { boticelli::test::AllocationGuard guard; }
  std::vector<int> values(10, 1);
  boticelli::test::AllocationGuard guard;
  UNSIGNED_LONGS_EQUAL(0U, guard.allocations());
  LONGS_EQUAL(10, std::accumulate(values.begin(), values.end(), 0));
}
