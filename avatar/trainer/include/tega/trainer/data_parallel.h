#pragma once
// One process of a training run shared by several, one per GPU (docs/training.md#on-several-gpus).
// Every process holds the whole model and renders its own view each step; the gradients are
// averaged over the processes before each one's identical optimiser step, so the replicas stay
// equal, as does every decision taken from them (densification, roll-backs, stopping).
//
// The processes meet through a rendezvous file (c10d's file store). The gradients go through a
// collective group (NCCL for CUDA tensors where the build found it, Gloo on the CPU); the few numbers
// every process must agree on go through the store itself, which never waits for a GPU stream.

#include <ATen/ATen.h>

#include <memory>
#include <vector>

#include "tega/trainer/parallel_rank.h"

namespace tega::trainer {

class DataParallel {
 public:
  DataParallel();  // alone: every operation is the identity
  // Joins the group; returns once all `world` processes have. Throws tega::Error when `rank` does
  // not fit `world` or the rendezvous file cannot be used.
  DataParallel(const ParallelRank& rank, const at::Device& device);
  ~DataParallel();
  DataParallel(const DataParallel&) = delete;
  DataParallel& operator=(const DataParallel&) = delete;

  // Whether this build can train on several processes on `device`.
  static bool available(const at::Device& device);

  bool alone() const { return world_ == 1; }
  bool leads() const { return rank_ == 0; }  // the process that writes checkpoints, metrics and logs
  int rank() const { return rank_; }
  int world() const { return world_; }

  // In place: each tensor becomes its mean (average) or sum over the processes. One call: one
  // collective over the tensors flattened together, so every process must pass the same shapes.
  void average(const std::vector<at::Tensor>& tensors);
  void sum(const std::vector<at::Tensor>& tensors);
  // average(), except that on GPUs the current stream sees the result only after join_averages():
  // what backward starts for the gradients it has finished (gradient_average.h), its later
  // kernels running beside the all-reduce. On the CPU it is average() (Gloo waits).
  void start_average(const std::vector<at::Tensor>& tensors);
  // The current stream waits for every average started.
  void join_averages();
  // On the host: the processes' sums of `values`.
  std::vector<double> host_sum(const std::vector<double>& values);
  void barrier();

 private:
  struct Groups;
  void reduce(const std::vector<at::Tensor>& tensors, bool mean, bool wait);

  int rank_ = 0, world_ = 1;
  std::unique_ptr<Groups> groups_;
};

// Learning rates for `views_per_step` views a step (one per process) instead of one: scaled by
// its square root, as Grendel (Zhao et al. 2024) does for 3DGS trained on larger batches.
double learning_rate_factor(int views_per_step);
// Adam's decay `beta` a step for `views_per_step` views a step: beta^views_per_step, so that the
// moments forget at the same rate per view seen as with one view a step (Grendel's momentum rule,
// beside its √batch learning rates).
double moment_decay(double beta, int views_per_step);

}  // namespace tega::trainer
