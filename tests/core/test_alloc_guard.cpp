// Tests of the allocation guard: it must catch allocations and stay quiet on allocation-free code.
#include <array>
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
