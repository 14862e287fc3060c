// The gradients' average started during backward (gradient_average.h), on two processes' worth of
// Gloo group as two threads of this one. Gloo's all-reduce waits, so a bucket's gradients read
// inside backward show whether its average had already run there.
#include "tega/trainer/gradient_average.h"

#include <gtest/gtest.h>

#include "test_support.h"
#include "two_processes.h"

namespace tega::trainer {
namespace {

at::Tensor parameter(int64_t size) { return at::ones({size}).requires_grad_(); }

TEST(GradientAverage, StartsEachBucketInBackwardOnceItAndTheBucketsBeforeItHaveTheirGradients) {
  if (!DataParallel::available(at::kCPU)) GTEST_SKIP() << "this build's libtorch has no c10d with Gloo";
  test::TempDir dir;
  struct Seen {
    at::Tensor early_when_late_reached, early, late, unused, densified, densified_when_late_reached, dropped;
    int started_first = -1, started_second = -1;
  } seen[test::kTwoProcesses];
  const auto failures = test::as_two_processes([&](int rank) {
    Seen& s = seen[rank];
    DataParallel parallel({rank, test::kTwoProcesses, dir / "rendezvous"}, at::kCPU);
    GradientAverage average(parallel);
    const double r = rank + 1;  // each process its own gradients: means 3 (early) and 1.5 (late)
    at::Tensor early = parameter(4), late = parameter(3), unused = parameter(2);

    // Backward runs the nodes made last first: `late`'s branch, made first, is reached last.
    const at::Tensor late_branch = late * r;
    late_branch.register_hook([&](const at::Tensor&) {
      if (early.grad().defined()) s.early_when_late_reached = early.grad().clone();
    });
    const at::Tensor early_term = (early * (2 * r)).sum();
    const at::Tensor loss = late_branch.sum() + early_term;
    average.arm({{early}, {late}, {unused}});
    loss.backward();
    average.finish();
    s.started_first = average.started_during_backward();
    s.early = early.grad();
    s.late = late.grad();
    s.unused = unused.grad();

    // Densification: `early` replaced by a larger tensor, which needs hooks of its own. The
    // old one, trained on here but in no bucket, is reached first.
    const at::Tensor densified = parameter(6), dropped = early;
    dropped.mutable_grad() = at::Tensor();
    late.mutable_grad() = at::Tensor();
    const at::Tensor late_again = late * r;
    late_again.register_hook([&](const at::Tensor&) {
      if (densified.grad().defined()) s.densified_when_late_reached = densified.grad().clone();
    });
    const at::Tensor densified_term = (densified * (2 * r)).sum();
    const at::Tensor dropped_term = (dropped * r).sum();
    const at::Tensor next_loss = late_again.sum() + densified_term + dropped_term;
    average.arm({{densified}, {late}});
    next_loss.backward();
    average.finish();
    s.started_second = average.started_during_backward();
    s.densified = densified.grad();
    s.dropped = dropped.grad();
  });
  for (int rank = 0; rank < test::kTwoProcesses; ++rank) {
    const Seen& s = seen[rank];
    ASSERT_EQ(failures[rank], "") << "process " << rank;
    ASSERT_TRUE(s.early_when_late_reached.defined()) << "backward reached `late` before `early`'s gradient";
    EXPECT_TRUE(at::equal(s.early_when_late_reached, at::full({4}, 3.0f))) << "not averaged during backward";
    EXPECT_TRUE(at::equal(s.early, at::full({4}, 3.0f))) << s.early;
    EXPECT_TRUE(at::equal(s.late, at::full({3}, 1.5f))) << s.late;
    EXPECT_FALSE(s.unused.defined());
    EXPECT_EQ(s.started_first, 2) << "the bucket without a gradient starts in finish()";

    ASSERT_TRUE(s.densified_when_late_reached.defined());
    EXPECT_TRUE(at::equal(s.densified_when_late_reached, at::full({6}, 3.0f))) << s.densified_when_late_reached;
    EXPECT_TRUE(at::equal(s.densified, at::full({6}, 3.0f))) << s.densified;
    EXPECT_TRUE(at::equal(s.dropped, at::full({4}, rank + 1.0f))) << "a tensor in no bucket is not averaged";
    EXPECT_EQ(s.started_second, 2);
  }
}

TEST(GradientAverage, ForgottenItFreesTheParametersItHookedAndHooksTheirSuccessorsAnew) {
  if (!DataParallel::available(at::kCPU)) GTEST_SKIP() << "this build's libtorch has no c10d with Gloo";
  test::TempDir dir;
  struct Seen {
    bool held_after_replacement = false, held_after_forget = true;
    at::Tensor successor;
    int started = -1;
  } seen[test::kTwoProcesses];
  const auto failures = test::as_two_processes([&](int rank) {
    Seen& s = seen[rank];
    DataParallel parallel({rank, test::kTwoProcesses, dir / "rendezvous"}, at::kCPU);
    GradientAverage average(parallel);
    const double r = rank + 1;
    at::Tensor replaced = parameter(4);
    const c10::weak_intrusive_ptr<c10::TensorImpl, c10::UndefinedTensorImpl> weak(replaced.getIntrusivePtr());
    average.arm({{replaced}});
    (replaced * r).sum().backward();
    average.finish();

    replaced = parameter(5);  // as densification replaces a parameter
    s.held_after_replacement = !weak.expired();
    average.forget();
    s.held_after_forget = !weak.expired();

    average.arm({{replaced}});
    (replaced * (2 * r)).sum().backward();
    average.finish();
    s.successor = replaced.grad();
    s.started = average.started_during_backward();
  });
  for (int rank = 0; rank < test::kTwoProcesses; ++rank) {
    const Seen& s = seen[rank];
    ASSERT_EQ(failures[rank], "") << "process " << rank;
    EXPECT_TRUE(s.held_after_replacement) << "the hooks no longer hold their parameter: forget() has nothing to do";
    EXPECT_FALSE(s.held_after_forget) << "the replaced parameter outlived forget()";
    EXPECT_TRUE(at::equal(s.successor, at::full({5}, 3.0f))) << s.successor;
    EXPECT_EQ(s.started, 1) << "the successor's bucket was not started by its own hook";
  }
}

TEST(GradientAverage, AloneItLeavesTheGradientsAsBackwardMadeThem) {
  DataParallel alone;
  GradientAverage average(alone);
  at::Tensor p = parameter(3);
  average.arm({{p}});
  (p * 5).sum().backward();
  average.finish();
  EXPECT_TRUE(at::equal(p.grad(), at::full({3}, 5.0f)));
}

}  // namespace
}  // namespace tega::trainer
