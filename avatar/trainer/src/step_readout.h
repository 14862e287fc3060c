#pragma once
// A training step's loss, MSE, all-finite flag and largest deformation, read
// by the host without draining the GPU. On CUDA they are copied into pinned
// memory behind the step's work and read one step later, when the copy has
// long completed (the next step's rasterizer waits for the GPU once anyway);
// reading them at once made every step wait for the GPU to finish before the
// next step could be queued. On the CPU they are plain values.

#include <ATen/core/Tensor.h>
#include <c10/core/Event.h>

#include <optional>

#include "tega/trainer/view_loader.h"

namespace tega::trainer {

// The Gaussian that the field moved furthest in a step.
struct LargestDeformation {
  double metres = 0;  // 0 while the field is off
  int64_t gaussian = -1, triangle = -1;
  double u = 0, v = 0;  // canonical
};

struct StepValues {
  double loss = 0, mse = 0;
  bool finite = true;     // the loss and every gradient
  LargestDeformation largest_deformation;
  int64_t iteration = 0;  // 1-based
  View view;
};

class StepReadout {
 public:
  // Queues the copy of one step's 0-d loss, mse, finite flag and largest
  // deformation (PosedGaussians::largest_deformation; undefined: none). At
  // most one step is queued: pop() it first.
  void push(const at::Tensor& loss, const at::Tensor& mse, const at::Tensor& finite,
            const at::Tensor& largest_deformation, int64_t iteration, const View& view);
  // The queued step's values (waiting for their copy if it is still running),
  // or nothing.
  std::optional<StepValues> pop();

 private:
  struct Pending {
    at::Tensor host;  // [8] double: loss, mse, finite, then the largest deformation's 5
    std::optional<c10::Event> copied;
    int64_t iteration;
    View view;
  };
  std::optional<Pending> pending_;
};

}  // namespace tega::trainer
