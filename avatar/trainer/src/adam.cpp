#include "tega/trainer/adam.h"

#include <ATen/core/grad_mode.h>

#include <cmath>

#include "adam_update.h"
#include "tega/core/error.h"

namespace tega::trainer {

Adam::Adam(double beta1, double beta2, double epsilon) : beta1_(beta1), beta2_(beta2), epsilon_(epsilon) {}

void Adam::add(const std::string& name, const at::Tensor& parameter, double learning_rate,
               const at::Tensor& step_scale) {
  groups_.push_back(
      {name, parameter, learning_rate, step_scale, at::zeros_like(parameter), at::zeros_like(parameter)});
}

Adam::Group& Adam::group(const std::string& name) {
  for (auto& g : groups_)
    if (g.name == name) return g;
  throw Error("optimizer has no parameter group '" + name + "'");
}

void Adam::zero_grad() {
  for (auto& g : groups_) {
    if (g.parameter.grad().defined()) g.parameter.mutable_grad() = at::Tensor();
  }
}

void Adam::step() {
  ++steps_;
  const double correction1 = 1.0 - std::pow(beta1_, static_cast<double>(steps_));
  const double correction2 = 1.0 - std::pow(beta2_, static_cast<double>(steps_));
  at::NoGradGuard no_grad;
  for (auto& g : groups_) {
    const at::Tensor& grad = g.parameter.grad();
    if (!grad.defined() || g.learning_rate == 0.0) continue;
    adam_update::step(g.parameter, grad.contiguous(), g.first_moment, g.second_moment, g.step_scale,
                      {beta1_, 1.0 - beta1_, beta2_, 1.0 - beta2_, epsilon_, g.learning_rate / correction1,
                       1.0 / correction2});
  }
}

void Adam::replace_rows(const std::string& name, const at::Tensor& parameter, const at::Tensor& keep,
                        int64_t appended) {
  Group& g = group(name);
  const auto grow = [&](const at::Tensor& moment) {
    at::Tensor kept = moment.index_select(0, keep);
    auto shape = kept.sizes().vec();
    shape[0] = appended;
    return at::cat({kept, at::zeros(shape, kept.options())});
  };
  g.first_moment = grow(g.first_moment);
  g.second_moment = grow(g.second_moment);
  g.parameter = parameter;
}

void Adam::reset_rows(const std::string& name, const at::Tensor& rows) {
  Group& g = group(name);
  g.first_moment.index_fill_(0, rows, 0.0);
  g.second_moment.index_fill_(0, rows, 0.0);
}

std::map<std::string, at::Tensor> Adam::state() const {
  std::map<std::string, at::Tensor> s;
  for (const auto& g : groups_) {
    s[g.name + ".adam_m"] = g.first_moment;
    s[g.name + ".adam_v"] = g.second_moment;
  }
  s["adam.steps"] = at::tensor({steps_}, at::kLong);
  return s;
}

void Adam::load_state(const std::map<std::string, at::Tensor>& state) {
  const auto get = [&](const std::string& key, const at::Tensor& like) {
    auto it = state.find(key);
    if (it == state.end()) throw Error("checkpoint has no optimizer state '" + key + "'");
    if (it->second.sizes() != like.sizes()) throw Error("checkpoint optimizer state '" + key + "' has the wrong shape");
    return it->second.to(like.options());
  };
  for (auto& g : groups_) {
    g.first_moment = get(g.name + ".adam_m", g.parameter);
    g.second_moment = get(g.name + ".adam_v", g.parameter);
  }
  auto steps = state.find("adam.steps");
  if (steps == state.end()) throw Error("checkpoint has no optimizer step count");
  steps_ = steps->second.item<int64_t>();
}

}  // namespace tega::trainer
