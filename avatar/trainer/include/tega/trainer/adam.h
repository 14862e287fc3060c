#pragma once
// Adam over named parameter tensors, with state that densification can
// reshape row by row (the Gaussians' parameters gain and lose rows) and that a
// checkpoint stores exactly, so a resumed run continues bit-for-bit on the CPU.
// (torch::optim::Adam keys its state by tensor identity and serialises it in
// its own archive format, which differs between libtorch 1.13 and 2.x.)

#include <ATen/ATen.h>

#include <cstdint>
#include <map>
#include <string>
#include <vector>

namespace tega::trainer {

class Adam {
 public:
  struct Group {
    std::string name;
    at::Tensor parameter;  // a leaf requiring grad
    double learning_rate = 1e-3;
    // Optional per-element factor on the step, broadcast against the
    // parameter (e.g. [1,3] to step u, v in uv units and d in metres).
    at::Tensor step_scale;
    at::Tensor first_moment, second_moment;  // same shape as parameter
  };

  static constexpr double kBeta1 = 0.9, kBeta2 = 0.999;  // the moments' decay a step, as 3DGS

  explicit Adam(double beta1 = kBeta1, double beta2 = kBeta2, double epsilon = 1e-15);

  void add(const std::string& name, const at::Tensor& parameter, double learning_rate,
           const at::Tensor& step_scale = at::Tensor());
  Group& group(const std::string& name);
  const std::vector<Group>& groups() const { return groups_; }
  int64_t steps() const { return steps_; }

  void zero_grad();
  // One step over every group that has a gradient.
  void step();

  // After densification: the parameter of `name` was replaced by `parameter`,
  // whose rows are `keep` rows of the old one (indices into it, in order)
  // followed by `appended` new rows, which start with zero moments.
  void replace_rows(const std::string& name, const at::Tensor& parameter, const at::Tensor& keep, int64_t appended);
  // Resets the moments of `rows` (e.g. after an opacity reset).
  void reset_rows(const std::string& name, const at::Tensor& rows);

  // Moments and step count as tensors named "<group>.adam_m", "<group>.adam_v", "adam.steps".
  std::map<std::string, at::Tensor> state() const;
  void load_state(const std::map<std::string, at::Tensor>& state);  // throws tega::Error on a mismatch

 private:
  double beta1_, beta2_, epsilon_;
  int64_t steps_ = 0;
  std::vector<Group> groups_;
};

}  // namespace tega::trainer
