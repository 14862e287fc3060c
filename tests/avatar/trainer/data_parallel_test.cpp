#include "tega/trainer/data_parallel.h"

#include <gtest/gtest.h>

#include "tega/core/error.h"
#include "test_support.h"
#include "two_processes.h"

namespace tega::trainer {
namespace {

// Two processes' worth of the group, as two threads of this one (Gloo over the loopback).
TEST(DataParallel, AveragesAndSumsOverTheProcessesAndAgreesOnHostNumbers) {
  if (!DataParallel::available(at::kCPU)) GTEST_SKIP() << "this build's libtorch has no c10d with Gloo";
  test::TempDir dir;
  constexpr int kWorld = test::kTwoProcesses;
  at::Tensor gradient[kWorld], other[kWorld], counts[kWorld];
  std::vector<double> host[kWorld], rounds[kWorld];
  const auto failures = test::as_two_processes([&](int rank) {
    DataParallel parallel({rank, kWorld, dir / "rendezvous"}, at::kCPU);
    gradient[rank] = at::full({3, 4}, rank + 1.0f);  // 1 and 2: mean 1.5
    other[rank] = at::arange(5, at::kFloat) * (rank == 0 ? 1 : 3);  // mean 2 i
    counts[rank] = at::full({6}, rank == 0 ? 2.0f : 5.0f);
    parallel.average({gradient[rank], other[rank]});
    parallel.sum({counts[rank]});
    host[rank] = parallel.host_sum({rank == 0 ? 0.25 : 0.5, 1.0});
    // Many rounds, as a run has (one a step): each its own sums, old keys dropped as they go.
    for (int round = 0; round < 50; ++round)
      rounds[rank].push_back(parallel.host_sum({double(round * (rank + 1))})[0]);
    parallel.barrier();
  });
  for (int rank = 0; rank < kWorld; ++rank) {
    ASSERT_EQ(failures[rank], "") << "process " << rank;
    for (int round = 0; round < 50; ++round) EXPECT_EQ(rounds[rank][round], 3.0 * round);
    EXPECT_TRUE(at::equal(gradient[rank], at::full({3, 4}, 1.5f))) << gradient[rank];
    EXPECT_TRUE(at::allclose(other[rank], at::arange(5, at::kFloat) * 2)) << other[rank];
    EXPECT_TRUE(at::equal(counts[rank], at::full({6}, 7.0f))) << counts[rank];
    EXPECT_EQ(host[rank], (std::vector<double>{0.75, 2.0}));
  }
}

TEST(DataParallel, AloneEverythingIsTheIdentity) {
  DataParallel alone;
  at::Tensor t = at::arange(4, at::kFloat);
  alone.average({t});
  alone.sum({t});
  EXPECT_TRUE(at::equal(t, at::arange(4, at::kFloat)));
  EXPECT_EQ(alone.host_sum({3.0}), std::vector<double>{3.0});
  EXPECT_TRUE(alone.leads());
  EXPECT_THROW(DataParallel({2, 2, "x"}, at::kCPU), Error);  // rank 2 of 0..1
}

TEST(DataParallel, LearningRatesGrowWithTheSquareRootOfTheViewsAStep) {
  EXPECT_DOUBLE_EQ(learning_rate_factor(1), 1.0);
  EXPECT_DOUBLE_EQ(learning_rate_factor(4), 2.0);
  EXPECT_DOUBLE_EQ(learning_rate_factor(2), std::sqrt(2.0));
}

TEST(DataParallel, MomentDecaysKeepTheirRatePerView) {
  EXPECT_DOUBLE_EQ(moment_decay(0.9, 1), 0.9);
  EXPECT_NEAR(moment_decay(0.9, 2), 0.81, 1e-15);
  EXPECT_NEAR(moment_decay(0.999, 4), 0.999 * 0.999 * 0.999 * 0.999, 1e-15);
  // What a moment keeps of a view after 40 views, one a step or four a step: the same.
  EXPECT_NEAR(std::pow(moment_decay(0.9, 4), 10), std::pow(0.9, 40), 1e-15);
}

}  // namespace
}  // namespace tega::trainer
