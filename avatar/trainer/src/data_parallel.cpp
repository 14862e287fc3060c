#include "tega/trainer/data_parallel.h"

#include <cmath>
#include <string>

#include "tega/core/error.h"

// libtorch's c10d with Gloo (Debian: libtorch-dev with libgloo-dev's headers; PyTorch's wheels).
#if __has_include(<torch/csrc/distributed/c10d/ProcessGroupGloo.hpp>) && __has_include(<gloo/rendezvous/store.h>)
#define TEGA_HAVE_C10D 1
#include <torch/csrc/distributed/c10d/FileStore.hpp>
#include <torch/csrc/distributed/c10d/PrefixStore.hpp>
#include <torch/csrc/distributed/c10d/ProcessGroupGloo.hpp>
#ifdef USE_C10D_NCCL
#include <torch/csrc/distributed/c10d/ProcessGroupNCCL.hpp>
#endif
#include <torch/version.h>
#endif

namespace tega::trainer {

#ifdef TEGA_HAVE_C10D
namespace {

// What Gloo's and NCCL's groups derive from: c10d::ProcessGroup in libtorch 1.x, c10d::Backend in 2.x.
#if TORCH_VERSION_MAJOR >= 2
using CollectiveGroup = c10d::Backend;
#else
using CollectiveGroup = c10d::ProcessGroup;
#endif

}  // namespace

struct DataParallel::Groups {
  c10::intrusive_ptr<c10d::Store> store;
  c10::intrusive_ptr<CollectiveGroup> gradients, host;
};

namespace {

c10::intrusive_ptr<CollectiveGroup> gloo_group(const c10::intrusive_ptr<c10d::Store>& store, int rank, int world) {
  auto options = c10d::ProcessGroupGloo::Options::create();
  options->devices.push_back(c10d::ProcessGroupGloo::createDeviceForHostname("127.0.0.1"));
  return c10::make_intrusive<c10d::ProcessGroupGloo>(store, rank, world, options);
}

}  // namespace

#else
struct DataParallel::Groups {};
#endif

DataParallel::DataParallel() = default;
DataParallel::~DataParallel() = default;

DataParallel::DataParallel(const ParallelRank& rank, const at::Device& device) : rank_(rank.rank), world_(rank.world) {
  if (world_ < 1 || rank_ < 0 || rank_ >= world_)
    throw Error("data-parallel training: process " + std::to_string(rank_) + " of " + std::to_string(world_) +
                " does not exist");
  if (world_ == 1) return;
  if (rank.rendezvous.empty()) throw Error("data-parallel training needs a rendezvous file");
#ifndef TEGA_HAVE_C10D
  throw Error("training on several processes needs libtorch's c10d with Gloo, which this build lacks (libgloo-dev)");
#else
  groups_ = std::make_unique<Groups>();
  groups_->store = c10::make_intrusive<c10d::FileStore>(rank.rendezvous.string(), world_);
  const auto host_store = c10::make_intrusive<c10d::PrefixStore>("host", groups_->store);
  const auto gradient_store = c10::make_intrusive<c10d::PrefixStore>("gradients", groups_->store);
  groups_->host = gloo_group(host_store, rank_, world_);
#ifdef USE_C10D_NCCL
  if (device.is_cuda()) {
    groups_->gradients = c10::make_intrusive<c10d::ProcessGroupNCCL>(gradient_store, rank_, world_);
    return;
  }
#endif
  (void)device;
  groups_->gradients = gloo_group(gradient_store, rank_, world_);
#endif
}

// Alone, or without c10d (then no group exists beyond one process), these are the identity.
void DataParallel::reduce(const std::vector<at::Tensor>& tensors, bool mean) {
  if (alone() || tensors.empty()) return;
#ifdef TEGA_HAVE_C10D
  std::vector<at::Tensor> flat_parts;
  for (const auto& t : tensors) flat_parts.push_back(t.reshape({-1}));
  std::vector<at::Tensor> flat{at::cat(flat_parts)};
  groups_->gradients->allreduce(flat)->wait();
  if (mean) flat[0].div_(world_);
  int64_t offset = 0;
  for (const auto& t : tensors) {
    t.copy_(flat[0].narrow(0, offset, t.numel()).view_as(t));
    offset += t.numel();
  }
#else
  (void)mean;
#endif
}

void DataParallel::average(const std::vector<at::Tensor>& tensors) { reduce(tensors, true); }
void DataParallel::sum(const std::vector<at::Tensor>& tensors) { reduce(tensors, false); }

std::vector<double> DataParallel::host_sum(const std::vector<double>& values) {
  if (alone()) return values;
#ifdef TEGA_HAVE_C10D
  std::vector<at::Tensor> packed{at::tensor(values, at::kDouble)};
  groups_->host->allreduce(packed)->wait();
  const at::Tensor& sums = packed[0];
  return {sums.data_ptr<double>(), sums.data_ptr<double>() + sums.numel()};
#else
  return values;
#endif
}

void DataParallel::barrier() {
  if (alone()) return;
  host_sum({0.0});  // Gloo's barrier is an all-reduce too; this one keeps to the host group
}

double learning_rate_factor(int views_per_step) { return std::sqrt(static_cast<double>(std::max(1, views_per_step))); }

}  // namespace tega::trainer
