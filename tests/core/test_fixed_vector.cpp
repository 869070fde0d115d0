// Tests of FixedVector: capacity, overflow policy, size-free base.
#include <numeric>

#include "algo/core/fixed_vector.h"
#include "CppUTest/TestHarness.h"

using boticelli::core::FixedVector;
using boticelli::core::FixedVectorBase;

namespace {
int sum(const FixedVectorBase<int>& values) {
  return std::accumulate(values.begin(), values.end(), 0);
}
}  // namespace

TEST_GROUP(FixedVector){};

TEST(FixedVector, RefusesAPushIntoAFullVectorAndKeepsItsContents) {
  FixedVector<int, 3> v;
  CHECK(v.push_back(1));
  CHECK(v.push_back(2));
  CHECK(v.push_back(3));
  CHECK(v.full());
  CHECK_FALSE(v.push_back(4));
  LONGS_EQUAL(3, static_cast<long>(v.size()));
  LONGS_EQUAL(6, sum(v));
}

TEST(FixedVector, IsUsedThroughItsSizeFreeBase) {
  FixedVector<int, 8> small;
  FixedVector<int, 64> large;
  for (int i = 1; i <= 4; ++i) {
    CHECK(small.push_back(i));
    CHECK(large.push_back(10 * i));
  }
  LONGS_EQUAL(10, sum(small));
  LONGS_EQUAL(100, sum(large));
}

TEST(FixedVector, ResizeIsClampedToCapacityAndClearsNewElements) {
  FixedVector<int, 4> v;
  CHECK(v.push_back(7));
  v.pop_back();
  LONGS_EQUAL(4, static_cast<long>(v.resize(10)));
  LONGS_EQUAL(0, v[0]);
  v.clear();
  CHECK(v.empty());
}

TEST(FixedVector, CopiesOnlyTheLiveElements) {
  FixedVector<int, 4> a;
  CHECK(a.push_back(5));
  CHECK(a.push_back(6));
  FixedVector<int, 4> b = a;
  LONGS_EQUAL(2, static_cast<long>(b.size()));
  LONGS_EQUAL(11, sum(b));
}

TEST(FixedVector, APushThinningIntoAFullVectorKeepsEveryOtherElementFromTheFirstThenAppends) {
  FixedVector<int, 5> v;
  for (int i = 0; i < 5; ++i) CHECK(v.push_back_thinning(i));
  LONGS_EQUAL(5, static_cast<long>(v.size()));  // not full before this push: nothing thinned
  CHECK(v.push_back_thinning(5));               // full: 0, 2, 4 kept, then 5
  LONGS_EQUAL(4, static_cast<long>(v.size()));
  LONGS_EQUAL(0, v[0]);
  LONGS_EQUAL(2, v[1]);
  LONGS_EQUAL(4, v[2]);
  LONGS_EQUAL(5, v[3]);
  CHECK(v.push_back_thinning(6));
  CHECK(v.push_back_thinning(7));  // full again: 0, 4, 6 kept, then 7
  LONGS_EQUAL(4, static_cast<long>(v.size()));
  LONGS_EQUAL(0, v[0]);
  LONGS_EQUAL(4, v[1]);
  LONGS_EQUAL(6, v[2]);
  LONGS_EQUAL(7, v[3]);
}
