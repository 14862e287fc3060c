// The fused Adam update on a GPU against the CPU in double; skips where there
// is no GPU.
#include <ATen/ATen.h>
#include <gtest/gtest.h>

#include "tega/trainer/adam.h"
#include "../tensor_compare.h"

namespace {

using tega::trainer::Adam;

using tega::test::relative_error;

void expect_parity(int64_t rows) {
  at::manual_seed(11);
  const at::Tensor start = at::randn({rows, 3}, at::kDouble);
  const at::Tensor scale = at::tensor({0.25, 0.25, 1.0}, at::kDouble).view({1, 3});
  at::Tensor on_cpu = start.clone().requires_grad_(true);
  at::Tensor on_gpu = start.to(at::kCUDA, at::kFloat).requires_grad_(true);
  Adam cpu, gpu;
  cpu.add("p", on_cpu, 1e-2, scale);
  gpu.add("p", on_gpu, 1e-2, scale.to(at::kCUDA, at::kFloat));
  for (int step = 0; step < 5; ++step) {
    const at::Tensor weights = at::randn({rows, 3}, at::kDouble);
    on_cpu.mutable_grad() = at::Tensor();
    on_gpu.mutable_grad() = at::Tensor();
    (on_cpu * weights).sum().backward();
    (on_gpu * weights.to(at::kCUDA, at::kFloat)).sum().backward();
    cpu.step();
    gpu.step();
  }
  EXPECT_LT(relative_error(on_gpu.detach(), on_cpu.detach()), 1e-6);
  EXPECT_LT(relative_error(gpu.group("p").first_moment, cpu.group("p").first_moment), 1e-6);
  EXPECT_LT(relative_error(gpu.group("p").second_moment, cpu.group("p").second_moment), 1e-6);
}

// 100003 × 3 floats take the one-element kernel; 100000 × 3, a multiple of
// four, the four-element one, whose quads straddle rows of the column scale.
TEST(AdamCuda, MatchesTheCpuInDouble) {
  if (!at::hasCUDA()) GTEST_SKIP() << "no CUDA device";
  for (const int64_t rows : {100003, 100000}) {
    SCOPED_TRACE(rows);
    expect_parity(rows);
  }
}

}  // namespace
