#include <gtest/gtest.h>

#include <cmath>

#include "mcslam/eval/error_stats.hpp"

using namespace mcslam;

TEST(ErrorStats, EvenCountUsesNumpyConventions) {
  const ErrorStats s = computeErrorStats({4.0, 1.0, 3.0, 2.0});
  EXPECT_EQ(s.count, 4u);
  EXPECT_DOUBLE_EQ(s.mean, 2.5);
  EXPECT_DOUBLE_EQ(s.median, 2.5);           // mean of the two middle values
  EXPECT_DOUBLE_EQ(s.std, std::sqrt(1.25));  // population std (numpy's default), not sqrt(5/3)
  EXPECT_DOUBLE_EQ(s.rmse, std::sqrt(7.5));
  EXPECT_DOUBLE_EQ(s.sse, 30.0);
  EXPECT_DOUBLE_EQ(s.min, 1.0);
  EXPECT_DOUBLE_EQ(s.max, 4.0);
}

TEST(ErrorStats, OddCountMedianIsTheMiddleValue) {
  const ErrorStats s = computeErrorStats({5.0, 0.5, 2.0});
  EXPECT_DOUBLE_EQ(s.median, 2.0);
  EXPECT_DOUBLE_EQ(s.min, 0.5);
  EXPECT_DOUBLE_EQ(s.max, 5.0);
}

TEST(ErrorStats, EmptyGivesZeros) {
  const ErrorStats s = computeErrorStats({});
  EXPECT_EQ(s.count, 0u);
  EXPECT_EQ(s.rmse, 0.0);
}
