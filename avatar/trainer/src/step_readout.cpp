#include "step_readout.h"

#include <ATen/ATen.h>
#include <c10/core/impl/VirtualGuardImpl.h>
#include <c10/util/Exception.h>

#include <chrono>
#include <thread>

namespace tega::trainer {

void StepReadout::push(const at::Tensor& loss, const at::Tensor& mse, const at::Tensor& finite,
                       const at::Tensor& largest_deformation, int64_t iteration, const View& view) {
  TORCH_CHECK(!pending_, "StepReadout: a step is already queued");
  const at::TensorOptions doubles = loss.options().dtype(at::kDouble);
  const at::Tensor deformation = largest_deformation.defined()
                                     ? largest_deformation.detach().to(at::kDouble)
                                     : at::tensor({0.0, -1.0, -1.0, 0.0, 0.0}, doubles);
  TORCH_CHECK(deformation.numel() == 5, "StepReadout: the largest deformation has 5 values");
  const at::Tensor values = at::cat({at::stack({loss.detach().to(at::kDouble), mse.detach().to(at::kDouble),
                                                finite.to(at::kDouble)}),
                                     deformation});
  Pending p{{}, std::nullopt, iteration, view};
  if (values.is_cpu()) {
    p.host = values;
  } else {
    p.host = at::empty({values.numel()}, at::TensorOptions().dtype(at::kDouble).pinned_memory(true));
    p.host.copy_(values, /*non_blocking=*/true);
    const c10::impl::VirtualGuardImpl guard(values.device().type());
    p.copied.emplace(values.device().type());
    p.copied->record(guard.getStream(values.device()));
  }
  pending_ = std::move(p);
}

std::optional<StepValues> StepReadout::pop() {
  if (!pending_) return std::nullopt;
  // c10::Event has no blocking wait in every supported libtorch; the copy is
  // normally done by now, so a poll costs nothing.
  if (pending_->copied) {
    while (!pending_->copied->query()) std::this_thread::sleep_for(std::chrono::microseconds(20));
  }
  const double* v = pending_->host.data_ptr<double>();
  const LargestDeformation largest{v[3], static_cast<int64_t>(v[4]), static_cast<int64_t>(v[5]), v[6], v[7]};
  StepValues out{v[0], v[1], v[2] != 0.0, largest, pending_->iteration, pending_->view};
  pending_.reset();
  return out;
}

}  // namespace tega::trainer
