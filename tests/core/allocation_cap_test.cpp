// core/allocation_cap.h: one allocation above the cap throws at once, smaller ones and other threads
// are untouched, scopes nest and restore what was in force before them.
#include "core/allocation_cap.h"

#include <gtest/gtest.h>

#include <new>
#include <string>
#include <thread>
#include <vector>

namespace ts {
namespace {

TEST(AllocationCap, AnAllocationAboveTheCapThrowsBadAllocAndOneBelowSucceeds) {
  const AllocationCap cap(1 << 20);
  EXPECT_THROW(std::string(std::size_t{3} << 30, ' '), std::bad_alloc);  // 3 GiB: refused, not reserved
  EXPECT_THROW(std::vector<char>(2 << 20), std::bad_alloc);
  EXPECT_NO_THROW(std::vector<char>(1 << 19));
}

TEST(AllocationCap, ScopesNestAndRestoreTheOuterCap) {
  {
    const AllocationCap outer(1 << 20);
    {
      const AllocationCap inner(1 << 10);
      EXPECT_THROW(std::vector<char>(1 << 12), std::bad_alloc);
    }
    EXPECT_NO_THROW(std::vector<char>(1 << 12));
    EXPECT_THROW(std::vector<char>(1 << 21), std::bad_alloc);
  }
  EXPECT_NO_THROW(std::vector<char>(1 << 21));  // no cap once every scope has ended
}

TEST(AllocationCap, OtherThreadsAreNotCapped) {
  const AllocationCap cap(1 << 10);
  bool other_allocated = false;
  std::thread other([&] {
    std::vector<char> big(1 << 20);
    other_allocated = big.size() == (1u << 20);
  });
  other.join();
  EXPECT_TRUE(other_allocated);
}

}  // namespace
}  // namespace ts
