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

struct StepValues {
  double loss = 0, mse = 0;
  bool finite = true;     // the loss and every gradient
  double largest_deformation = 0;  // metres; 0 while the field is off
  int64_t iteration = 0;  // 1-based
  View view;
};

class StepReadout {
 public:
  // Queues the copy of one step's 0-d loss, mse, finite flag and largest
  // deformation (undefined: 0). At most one step is queued: pop() it first.
  void push(const at::Tensor& loss, const at::Tensor& mse, const at::Tensor& finite,
            const at::Tensor& largest_deformation, int64_t iteration, const View& view);
  // The queued step's values (waiting for their copy if it is still running),
  // or nothing.
  std::optional<StepValues> pop();

 private:
  struct Pending {
    at::Tensor host;  // [4] double: loss, mse, finite, largest deformation
    std::optional<c10::Event> copied;
    int64_t iteration;
    View view;
  };
  std::optional<Pending> pending_;
};

}  // namespace tega::trainer
