#include "tega/trainer/gradient_average.h"

#include <torch/csrc/autograd/function.h>
#include <torch/csrc/autograd/function_hook.h>
#include <torch/csrc/autograd/variable.h>

#include <functional>
#include <mutex>
#include <utility>

#include "tega/core/error.h"

namespace tega::trainer {
namespace {

// Runs after a gradient accumulator has added backward's gradient to its parameter's .grad.
class AfterAccumulation : public torch::autograd::FunctionPostHook {
 public:
  explicit AfterAccumulation(std::function<void()> accumulated) : accumulated_(std::move(accumulated)) {}
  torch::autograd::variable_list operator()(const torch::autograd::variable_list& outputs,
                                            const torch::autograd::variable_list&) override {
    accumulated_();
    return outputs;
  }

 private:
  std::function<void()> accumulated_;
};

struct Hooked {
  std::shared_ptr<torch::autograd::Node> accumulator;  // held: the hook lives as long as it does
  uintptr_t hook = 0;
};

}  // namespace

struct GradientAverage::State {
  std::mutex mutex;  // backward's hooks run on the autograd engine's device threads
  bool armed = false;
  std::vector<std::vector<at::Tensor>> buckets;
  std::vector<Hooked> hooked;
  std::vector<int> waiting;  // per bucket: the gradients backward has yet to accumulate
  size_t next = 0;           // the first bucket not started
  int started_during_backward = 0;

  void start(DataParallel& parallel, size_t bucket) {
    std::vector<at::Tensor> gradients;
    for (const at::Tensor& parameter : buckets[bucket])
      if (parameter.grad().defined()) gradients.push_back(parameter.grad());
    parallel.start_average(gradients);
  }

  void detach_hooks() {
    for (const Hooked& h : hooked) h.accumulator->del_post_hook(h.hook);
    hooked.clear();
  }

  bool same_parameters(const std::vector<std::vector<at::Tensor>>& given) const {
    if (given.size() != buckets.size()) return false;
    for (size_t b = 0; b < given.size(); ++b) {
      if (given[b].size() != buckets[b].size()) return false;
      for (size_t i = 0; i < given[b].size(); ++i)
        if (!given[b][i].is_same(buckets[b][i])) return false;
    }
    return true;
  }
};

GradientAverage::GradientAverage(DataParallel& parallel) : parallel_(parallel), state_(std::make_unique<State>()) {}

GradientAverage::~GradientAverage() { state_->detach_hooks(); }

void GradientAverage::arm(const std::vector<std::vector<at::Tensor>>& buckets) {
  State& s = *state_;
  if (parallel_.alone()) return;
  if (!s.same_parameters(buckets)) {
    s.detach_hooks();
    s.buckets = buckets;
    for (size_t b = 0; b < buckets.size(); ++b) {
      for (const at::Tensor& parameter : buckets[b]) {
        if (!parameter.is_leaf() || !parameter.requires_grad())
          throw Error("the gradients' average: a bucket holds a tensor that is not a trained parameter");
        Hooked h{torch::autograd::impl::grad_accumulator(parameter)};
        h.hook = h.accumulator->add_post_hook(std::make_unique<AfterAccumulation>([this, b] {
          State& state = *state_;
          const std::lock_guard<std::mutex> lock(state.mutex);
          if (!state.armed) return;  // a backward of some other loss
          --state.waiting[b];
          for (; state.next < state.buckets.size() && state.waiting[state.next] == 0;
               ++state.next, ++state.started_during_backward)
            state.start(parallel_, state.next);
        }));
        s.hooked.push_back(h);
      }
    }
  }
  const std::lock_guard<std::mutex> lock(s.mutex);
  s.waiting.clear();
  for (const auto& bucket : s.buckets) s.waiting.push_back(static_cast<int>(bucket.size()));
  s.next = 0;
  s.started_during_backward = 0;
  s.armed = true;
}

void GradientAverage::finish() {
  State& s = *state_;
  if (parallel_.alone()) return;
  const std::lock_guard<std::mutex> lock(s.mutex);
  if (!s.armed) throw Error("the gradients' average: finish() without arm()");
  s.armed = false;
  for (; s.next < s.buckets.size(); ++s.next) s.start(parallel_, s.next);
  parallel_.join_averages();
}

void GradientAverage::forget() {
  State& s = *state_;
  const std::lock_guard<std::mutex> lock(s.mutex);
  if (s.armed) throw Error("the gradients' average: forget() between arm() and finish()");
  s.detach_hooks();
  s.buckets.clear();
}

int GradientAverage::started_during_backward() const { return state_->started_during_backward; }

}  // namespace tega::trainer
