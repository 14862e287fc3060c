#pragma once
// The gradients' all-reduce of a run trained on several GPUs (data_parallel.h), through NCCL's own
// C API. c10d's NCCL group would want them flattened into one buffer and copied back (about 1 GB
// each way a step at 4M Gaussians); one NCCL group call reduces each gradient in place, and
// averages in NCCL itself (ncclAvg). Every all-reduce runs on the group's own stream, after the
// work queued so far on the caller's: those started during backward run beside its later kernels.

#include <ATen/ATen.h>
#include <ATen/cuda/CUDAEvent.h>
#include <c10/cuda/CUDAStream.h>

#include <cstdint>
#include <vector>

struct ncclComm;

namespace tega::trainer {

class NcclGroup {
 public:
  // What every process of one group must be given: one process makes it, the others read it.
  static std::vector<uint8_t> new_token();

  // Joins the group on `device`; returns once all `world` processes have. Throws tega::Error.
  NcclGroup(const std::vector<uint8_t>& token, int rank, int world, const at::Device& device);
  ~NcclGroup();
  NcclGroup(const NcclGroup&) = delete;
  NcclGroup& operator=(const NcclGroup&) = delete;

  // In place, each tensor (on this process's GPU) becomes its sum or mean over the processes: one
  // NCCL group call, without a copy for contiguous tensors and without waiting on the host. It
  // follows the work queued on the current stream so far, and that stream sees the result after
  // join().
  void start_all_reduce(const std::vector<at::Tensor>& tensors, bool mean);
  // The current stream waits for every all-reduce started so far.
  void join();

 private:
  ncclComm* communicator_ = nullptr;
  at::Device device_;
  c10::cuda::CUDAStream communication_;
  // Recorded again at each call (a stream's wait takes the event as it is then): the work queued on
  // the caller's stream before an all-reduce, and every all-reduce started before a join.
  at::cuda::CUDAEvent queued_, reduced_;
};

}  // namespace tega::trainer
