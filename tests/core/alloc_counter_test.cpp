#include <gtest/gtest.h>

#include <Eigen/Core>
#include <cstdlib>
#include <thread>
#include <vector>

#include "alloc_testing.hpp"
#include "mcslam/core/alloc_counter.hpp"

using namespace mcslam;

TEST(AllocCounter, HooksAreLinkedIntoTests) {
  SKIP_UNLESS_COUNTING_ALLOCATIONS();
  EXPECT_TRUE(alloc::available());
}

TEST(AllocCounter, CountsNewMallocAndEigen) {
  SKIP_UNLESS_COUNTING_ALLOCATIONS();
  alloc::ThreadScope scope;
  auto* v = new std::vector<int>(100);
  EXPECT_EQ(scope.count(), 2u);  // the vector object and its buffer
  delete v;
  void* volatile p = std::malloc(64);  // volatile: the compiler may not elide the pair
  EXPECT_EQ(scope.count(), 3u);
  std::free(p);
  Eigen::MatrixXd m(30, 30);  // Eigen allocates with malloc directly
  m.setZero();
  EXPECT_EQ(scope.count(), 4u);
}

TEST(AllocCounter, CountsPerThread) {
  SKIP_UNLESS_COUNTING_ALLOCATIONS();
  alloc::ThreadScope scope;
  std::thread t([] {
    std::vector<int> v(10);
    v[0] = 1;
  });
  t.join();
  // The other thread's allocations are not ours (std::thread's own state may be).
  const uint64_t ours = scope.count();
  alloc::ThreadScope quiet;
  int x = 0;
  for (int i = 0; i < 1000; ++i) x += i;
  EXPECT_EQ(quiet.count(), 0u);
  EXPECT_GT(x, 0);
  EXPECT_LE(ours, 3u);
}
