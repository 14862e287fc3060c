#include "tega/trainer/data_parallel.h"

#include <chrono>
#include <cmath>
#include <cstring>
#include <string>

#include "tega/core/error.h"

// libtorch's c10d: its stores always (the rendezvous and the host numbers), Gloo for gradients on
// the CPU where its headers are (Debian: libgloo-dev). Gradients on GPUs go through NCCL's own API
// (nccl_group.h) where CMake found NCCL beside a CUDA libtorch (Debian's has no CUDA).
#if __has_include(<torch/csrc/distributed/c10d/FileStore.hpp>)
#define TEGA_HAVE_C10D 1
#include <torch/csrc/distributed/c10d/FileStore.hpp>
#include <torch/csrc/distributed/c10d/PrefixStore.hpp>
#include <torch/version.h>
#if defined(USE_C10D_GLOO) && __has_include(<gloo/rendezvous/store.h>) && \
    __has_include(<torch/csrc/distributed/c10d/ProcessGroupGloo.hpp>)
#define TEGA_HAVE_GLOO 1
#include <torch/csrc/distributed/c10d/ProcessGroupGloo.hpp>
#endif
#ifdef TEGA_HAVE_NCCL
#define TEGA_NCCL_GRADIENTS 1
#include "nccl_group.h"
#endif
#endif

namespace tega::trainer {

#ifdef TEGA_HAVE_C10D
namespace {

#ifdef TEGA_HAVE_GLOO
// What Gloo's group derives from: c10d::ProcessGroup in libtorch 1.x, c10d::Backend in 2.x.
#if TORCH_VERSION_MAJOR >= 2
using CollectiveGroup = c10d::Backend;
#else
using CollectiveGroup = c10d::ProcessGroup;
#endif
#endif

// A process waits this long for the others (the first process's checkpoints and held-out renders
// at 4M Gaussians take minutes).
constexpr auto kPatience = std::chrono::minutes(30);

}  // namespace

struct DataParallel::Groups {
  c10::intrusive_ptr<c10d::Store> store;
#ifdef TEGA_HAVE_GLOO
  c10::intrusive_ptr<CollectiveGroup> cpu_gradients;
#endif
#ifdef TEGA_NCCL_GRADIENTS
  std::unique_ptr<NcclGroup> gpu_gradients;
#endif
  int64_t host_round = 0;
};

bool DataParallel::available(const at::Device& device) {
#ifdef TEGA_NCCL_GRADIENTS
  if (device.is_cuda()) return true;
#endif
#ifdef TEGA_HAVE_GLOO
  return true;
#else
  (void)device;
  return false;
#endif
}
#else
struct DataParallel::Groups {};
bool DataParallel::available(const at::Device&) { return false; }
#endif

DataParallel::DataParallel() = default;
DataParallel::~DataParallel() = default;

DataParallel::DataParallel(const ParallelRank& rank, const at::Device& device) : rank_(rank.rank), world_(rank.world) {
  if (world_ < 1 || rank_ < 0 || rank_ >= world_)
    throw Error("data-parallel training: process " + std::to_string(rank_) + " of " + std::to_string(world_) +
                " does not exist");
  if (world_ == 1) return;
  if (rank.rendezvous.empty()) throw Error("data-parallel training needs a rendezvous file");
  if (!available(device))
    throw Error(std::string("training on several processes needs libtorch's c10d with ") +
                (device.is_cuda() ? "NCCL, which this build lacks (CMake looks beside a CUDA libtorch, then in the system)"
                                  : "Gloo's headers, which this build lacks (libgloo-dev)"));
#ifdef TEGA_HAVE_C10D
  groups_ = std::make_unique<Groups>();
  groups_->store = c10::make_intrusive<c10d::FileStore>(rank.rendezvous.string(), world_);
  groups_->store->setTimeout(kPatience);
  const auto gradient_store = c10::make_intrusive<c10d::PrefixStore>("gradients", groups_->store);
#ifdef TEGA_NCCL_GRADIENTS
  if (device.is_cuda()) {
    // The first process makes the group's token; the others wait for it in the rendezvous.
    if (rank_ == 0) gradient_store->set("nccl-token", NcclGroup::new_token());
    groups_->gpu_gradients = std::make_unique<NcclGroup>(gradient_store->get("nccl-token"), rank_, world_, device);
    return;
  }
#endif
#ifdef TEGA_HAVE_GLOO
  auto options = c10d::ProcessGroupGloo::Options::create();
  options->devices.push_back(c10d::ProcessGroupGloo::createDeviceForHostname("127.0.0.1"));
  options->timeout = kPatience;
  groups_->cpu_gradients = c10::make_intrusive<c10d::ProcessGroupGloo>(gradient_store, rank_, world_, options);
#endif
#endif
}

// Alone, these are the identity (and without c10d no group exists beyond one process).
void DataParallel::reduce(const std::vector<at::Tensor>& tensors, bool mean, bool wait) {
  if (alone() || tensors.empty()) return;
#ifdef TEGA_NCCL_GRADIENTS
  if (groups_->gpu_gradients) {
    groups_->gpu_gradients->start_all_reduce(tensors, mean);
    if (wait) groups_->gpu_gradients->join();
    return;
  }
#endif
  (void)wait;
#ifdef TEGA_HAVE_GLOO
  std::vector<at::Tensor> flat_parts;
  for (const auto& t : tensors) flat_parts.push_back(t.reshape({-1}));
  std::vector<at::Tensor> flat{at::cat(flat_parts)};
  groups_->cpu_gradients->allreduce(flat)->wait();
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

void DataParallel::average(const std::vector<at::Tensor>& tensors) { reduce(tensors, true, true); }
void DataParallel::sum(const std::vector<at::Tensor>& tensors) { reduce(tensors, false, true); }
void DataParallel::start_average(const std::vector<at::Tensor>& tensors) { reduce(tensors, true, false); }

void DataParallel::join_averages() {
#ifdef TEGA_NCCL_GRADIENTS
  if (!alone() && groups_->gpu_gradients) groups_->gpu_gradients->join();
#endif
}

// Through the rendezvous store, not a collective group: host numbers then never wait for a GPU
// stream, and need neither Gloo nor NCCL. Each round, each process sets its key and reads all.
std::vector<double> DataParallel::host_sum(const std::vector<double>& values) {
  if (alone()) return values;
#ifdef TEGA_HAVE_C10D
  const int64_t round = groups_->host_round++;
  const auto key = [&](int64_t r, int process) { return "host/" + std::to_string(r) + "/" + std::to_string(process); };
  std::vector<uint8_t> bytes(values.size() * sizeof(double));
  std::memcpy(bytes.data(), values.data(), bytes.size());
  groups_->store->set(key(round, rank_), bytes);
  std::vector<double> sums(values.size(), 0.0);
  for (int process = 0; process < world_; ++process) {
    const std::vector<uint8_t> theirs = groups_->store->get(key(round, process));  // waits for it
    if (theirs.size() != bytes.size()) throw Error("data-parallel training: the processes disagree on what they sum");
    for (size_t i = 0; i < values.size(); ++i) {
      double value;
      std::memcpy(&value, theirs.data() + i * sizeof(double), sizeof(double));
      sums[i] += value;
    }
  }
  // Every process has read round - 2's keys before it set those of round - 1, which this one has
  // read: its own key of round - 2 is no longer wanted.
  if (round >= 2) groups_->store->deleteKey(key(round - 2, rank_));
  return sums;
#else
  return values;
#endif
}

void DataParallel::barrier() { host_sum({0.0}); }

double learning_rate_factor(int views_per_step) { return std::sqrt(static_cast<double>(std::max(1, views_per_step))); }

double moment_decay(double beta, int views_per_step) {
  return std::pow(beta, static_cast<double>(std::max(1, views_per_step)));
}

}  // namespace tega::trainer
