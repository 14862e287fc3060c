// The gradients' all-reduce of training on several GPUs (NCCL), two GPUs driven by two threads of
// this process; skips where there are fewer than two GPUs or the build has no NCCL.
#include <ATen/ATen.h>
#include <gtest/gtest.h>

#include "tega/trainer/data_parallel.h"
#include "tega/trainer/gradient_average.h"
#include "test_support.h"
#include "two_processes.h"

namespace tega::trainer {
namespace {

TEST(DataParallelCuda, AveragesAndSumsOverTwoGpusInPlace) {
  if (!at::hasCUDA() || at::getNumGPUs() < 2) GTEST_SKIP() << "fewer than two GPUs";
  if (!DataParallel::available(at::kCUDA)) GTEST_SKIP() << "this build has no NCCL";
  test::TempDir dir;
  constexpr int kWorld = test::kTwoProcesses;
  at::Tensor gradient[kWorld], strided[kWorld], counts[kWorld];
  const void* storage[kWorld];
  double host[kWorld];
  const auto failures = test::as_two_processes([&](int rank) {
    const at::Device gpu(at::kCUDA, rank);
    DataParallel parallel({rank, kWorld, dir / "rendezvous"}, gpu);
    const auto on_gpu = at::TensorOptions().device(gpu);
    gradient[rank] = at::full({1000, 59}, rank + 1.0f, on_gpu);  // 1 and 2: mean 1.5
    storage[rank] = gradient[rank].data_ptr();
    strided[rank] = (at::arange(12, on_gpu.dtype(at::kFloat)) * (rank == 0 ? 1 : 3)).view({3, 4}).t();
    counts[rank] = at::full({6}, rank == 0 ? 2.0 : 5.0, on_gpu.dtype(at::kDouble));
    parallel.average({gradient[rank], strided[rank]});
    parallel.sum({counts[rank]});
    host[rank] = parallel.host_sum({rank + 1.0})[0];
    parallel.barrier();
  });
  for (int rank = 0; rank < kWorld; ++rank) {
    ASSERT_EQ(failures[rank], "") << "GPU " << rank;
    EXPECT_EQ(gradient[rank].data_ptr(), storage[rank]) << "reduced in place";
    EXPECT_TRUE(at::equal(gradient[rank].cpu(), at::full({1000, 59}, 1.5f)));
    EXPECT_FALSE(strided[rank].is_contiguous());
    EXPECT_TRUE(at::equal(strided[rank].cpu(), (at::arange(12, at::kFloat) * 2).view({3, 4}).t())) << strided[rank];
    EXPECT_TRUE(at::equal(counts[rank].cpu(), at::full({6}, 7.0, at::kDouble)));
    EXPECT_EQ(host[rank], 3.0);
  }
}

// The average started during backward (gradient_average.h): on GPUs it runs on NCCL's own stream
// beside backward's later kernels, and the step's stream sees it after finish().
TEST(DataParallelCuda, GradientAverageStartedDuringBackwardReachesTheStepsStream) {
  if (!at::hasCUDA() || at::getNumGPUs() < 2) GTEST_SKIP() << "fewer than two GPUs";
  if (!DataParallel::available(at::kCUDA)) GTEST_SKIP() << "this build has no NCCL";
  test::TempDir dir;
  constexpr int kWorld = test::kTwoProcesses;
  constexpr int64_t kEarly = 8 << 20;  // a Gaussians' tensor's worth: its all-reduce takes a while
  at::Tensor early[kWorld], late[kWorld];
  int started[kWorld] = {};
  const auto failures = test::as_two_processes([&](int rank) {
    const at::Device gpu(at::kCUDA, rank);
    DataParallel parallel({rank, kWorld, dir / "rendezvous"}, gpu);
    GradientAverage average(parallel);
    const auto on_gpu = at::TensorOptions().device(gpu);
    const at::Tensor e = at::ones({kEarly}, on_gpu).requires_grad_(), l = at::ones({64, 64}, on_gpu).requires_grad_();
    const double r = rank + 1;
    for (int step = 0; step < 3; ++step) {
      e.mutable_grad() = at::Tensor();
      l.mutable_grad() = at::Tensor();
      // `late`'s branch, made first, is reached last, after a few products' worth of backward.
      at::Tensor late_branch = l * r;
      for (int i = 0; i < 8; ++i) late_branch = late_branch.matmul(at::eye(64, on_gpu));
      const at::Tensor early_term = (e * (2 * r)).sum();
      const at::Tensor loss = late_branch.sum() + early_term;
      average.arm({{e}, {l}});
      loss.backward();
      average.finish();
      started[rank] = average.started_during_backward();
    }
    early[rank] = e.grad().cpu();  // on the step's stream
    late[rank] = l.grad().cpu();
  });
  for (int rank = 0; rank < kWorld; ++rank) {
    ASSERT_EQ(failures[rank], "") << "GPU " << rank;
    EXPECT_TRUE(at::equal(early[rank], at::full({kEarly}, 3.0f)));
    EXPECT_TRUE(at::equal(late[rank], at::full({64, 64}, 1.5f))) << late[rank];
    EXPECT_EQ(started[rank], 2);
  }
}

}  // namespace
}  // namespace tega::trainer
