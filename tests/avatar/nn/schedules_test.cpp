#include "tega/nn/schedules.h"

#include <gtest/gtest.h>

#include <cmath>

namespace tega::nn {
namespace {

constexpr int64_t kTotal = 60000;

TEST(Schedules, VggWeightStartsAtHalfAndGrowsExponentially) {
  EXPECT_EQ(vgg_weight(0, kTotal), 0.0);
  EXPECT_EQ(vgg_weight(29999, kTotal), 0.0);
  EXPECT_DOUBLE_EQ(vgg_weight(30000, kTotal), 0.01);
  EXPECT_DOUBLE_EQ(vgg_weight(59999, kTotal), 0.1);
  // Exponential: the geometric mean of the ends at the middle of the ramp.
  EXPECT_NEAR(vgg_weight(45000, kTotal), 0.01 * std::pow(10.0, 15000.0 / 29999.0), 1e-12);
  EXPECT_NEAR(vgg_weight(45000, kTotal), std::sqrt(0.01 * 0.1), 1e-5);
  for (int64_t it = 30000; it + 1000 < kTotal; it += 1000) EXPECT_LT(vgg_weight(it, kTotal), vgg_weight(it + 1000, kTotal));
}

TEST(Schedules, SmoothnessWeightDecaysToATenthByHalfway) {
  EXPECT_DOUBLE_EQ(smoothness_weight(0, kTotal), 1.0);
  EXPECT_NEAR(smoothness_weight(15000, kTotal), std::sqrt(0.1), 1e-12);
  EXPECT_DOUBLE_EQ(smoothness_weight(30000, kTotal), 0.1);
  EXPECT_DOUBLE_EQ(smoothness_weight(45000, kTotal), 0.1);
  EXPECT_DOUBLE_EQ(smoothness_weight(59999, kTotal), 0.1);
  EXPECT_THROW(smoothness_weight(-1, kTotal), std::invalid_argument);
}

}  // namespace
}  // namespace tega::nn
