#pragma once
// The gradients' average over the processes of a run on several GPUs, started while backward still
// runs, as PyTorch's DistributedDataParallel does. The parameters come in buckets; a bucket's
// all-reduce starts as soon as backward has accumulated the gradients of it and of every bucket
// before it. Backward reaches the Gaussians' own gradients right after the rasterizer's, so their
// all-reduce, nearly all of a step's traffic, runs beside the fields' backward rather than after it.
//
// Every process starts the buckets in the order given, which NCCL needs (the same collectives in
// the same order on every process): a bucket never starts before those listed ahead of it.

#include <ATen/ATen.h>

#include <memory>
#include <vector>

#include "tega/trainer/data_parallel.h"

namespace tega::trainer {

class GradientAverage {
 public:
  explicit GradientAverage(DataParallel& parallel);
  ~GradientAverage();
  GradientAverage(const GradientAverage&) = delete;
  GradientAverage& operator=(const GradientAverage&) = delete;

  // Before backward: the parameters in buckets, in the order every process starts them. Hooks on
  // the parameters' gradient accumulators are attached when the parameters are new (the first
  // step, densification, a roll-back) and kept otherwise.
  void arm(const std::vector<std::vector<at::Tensor>>& buckets);
  // After backward: starts the buckets backward did not (a parameter it gave no gradient is left
  // out of its bucket), then the current stream waits for every bucket's average.
  void finish();
  // Before parameters are replaced by new tensors (densification, a roll-back): drops the hooks
  // and the tensors they hold, so the old parameters and their gradients are freed now rather than
  // after the next step's forward (about 1.9 GB at 4M Gaussians). The next arm() attaches hooks anew.
  void forget();
  // How many buckets backward started itself in the last step (the rest started in finish()).
  int started_during_backward() const;

 private:
  struct State;
  DataParallel& parallel_;
  std::unique_ptr<State> state_;
};

}  // namespace tega::trainer
