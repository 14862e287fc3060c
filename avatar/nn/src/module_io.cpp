#include "tega/nn/module_io.h"

#include <ATen/ATen.h>
#include <ATen/core/grad_mode.h>

#include "tega/core/error.h"

namespace tega::nn {
namespace {

template <class Visit>
void for_each_tensor(const torch::nn::Module& module, Visit visit) {
  for (const auto& item : module.named_parameters(/*recurse=*/true)) visit(item.key(), item.value());
  for (const auto& item : module.named_buffers(/*recurse=*/true)) visit(item.key(), item.value());
}

}  // namespace

TensorMap module_tensors(const torch::nn::Module& module, const std::string& prefix) {
  TensorMap out;
  for_each_tensor(module, [&](const std::string& name, const at::Tensor& t) { out[prefix + name] = t.detach(); });
  return out;
}

void load_module_tensors(torch::nn::Module& module, const TensorMap& tensors, const std::filesystem::path& source,
                         const std::string& prefix) {
  at::NoGradGuard no_grad;
  for_each_tensor(module, [&](const std::string& name, const at::Tensor& target) {
    const auto it = tensors.find(prefix + name);
    if (it == tensors.end()) throw Error(source, "missing tensor '" + prefix + name + "'");
    if (it->second.sizes() != target.sizes())
      throw Error(source, "tensor '" + prefix + name + "' has shape " + c10::str(it->second.sizes()) +
                              ", the network expects " + c10::str(target.sizes()));
    target.copy_(it->second);  // in place: the tensor handle is shared with the module
  });
}

}  // namespace tega::nn
