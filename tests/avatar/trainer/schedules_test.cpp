#include "tega/trainer/schedules.h"

#include <gtest/gtest.h>

#include <cmath>

namespace {

using namespace tega::trainer;
constexpr int64_t kTotal = 60000;

TEST(Schedules, VggWeightStartsAtHalfAndGrowsExponentially) {
  const LossOptions paper;
  EXPECT_EQ(schedules::vgg_weight(paper, 0, kTotal), 0.0);
  EXPECT_EQ(schedules::vgg_weight(paper, 29999, kTotal), 0.0);
  EXPECT_DOUBLE_EQ(schedules::vgg_weight(paper, 30000, kTotal), 0.01);
  EXPECT_DOUBLE_EQ(schedules::vgg_weight(paper, 59999, kTotal), 0.1);
  // Exponential: the geometric mean of the ends at the middle of the ramp.
  EXPECT_NEAR(schedules::vgg_weight(paper, 45000, kTotal), std::sqrt(0.01 * 0.1), 1e-5);
  for (int64_t it = 30000; it + 1000 < kTotal; it += 1000) {
    EXPECT_LT(schedules::vgg_weight(paper, it, kTotal), schedules::vgg_weight(paper, it + 1000, kTotal));
  }
}

TEST(Schedules, VggStartIsAnOption) {
  LossOptions late;
  late.vgg_start = 0.8;
  EXPECT_EQ(schedules::vgg_weight(late, 47999, kTotal), 0.0);
  EXPECT_DOUBLE_EQ(schedules::vgg_weight(late, 48000, kTotal), 0.01);
}

TEST(Schedules, SmoothnessWeightDecaysToATenthByHalfway) {
  const LossOptions paper;
  EXPECT_DOUBLE_EQ(schedules::smoothness_weight(paper, 0, kTotal), 1.0);
  EXPECT_NEAR(schedules::smoothness_weight(paper, 15000, kTotal), std::sqrt(0.1), 1e-12);
  EXPECT_DOUBLE_EQ(schedules::smoothness_weight(paper, 30000, kTotal), 0.1);
  EXPECT_DOUBLE_EQ(schedules::smoothness_weight(paper, 59999, kTotal), 0.1);
}

TEST(Schedules, SmoothnessWeightIsZeroThroughoutWhenTheTermIsOff) {
  LossOptions off;
  off.smoothness_initial = 0;
  off.smoothness_final = 0;
  for (const int64_t iteration : {0, 15000, 30000, 59999}) {
    EXPECT_EQ(schedules::smoothness_weight(off, iteration, kTotal), 0.0) << iteration;
  }
}

TEST(Schedules, ScaleWithTheIterationCount) {
  const LossOptions paper;
  EXPECT_DOUBLE_EQ(schedules::vgg_weight(paper, 300, 600), 0.01);
  EXPECT_DOUBLE_EQ(schedules::smoothness_weight(paper, 300, 600), 0.1);
  EXPECT_EQ(at_fraction(TrainOptions{}.warmup, 60000), 10000);
  EXPECT_EQ(period(DensifyOptions{}.interval, 60000), 100);
  EXPECT_EQ(period(DensifyOptions{}.interval, 600), 1);
}

}  // namespace
