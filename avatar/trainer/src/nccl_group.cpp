#include "nccl_group.h"

#include <ATen/cuda/CUDAContext.h>
#include <c10/cuda/CUDAGuard.h>
#include <nccl.h>

#include <cstring>
#include <string>

#include "tega/core/error.h"

namespace tega::trainer {
namespace {

void check(ncclResult_t result, const char* call, ncclComm_t communicator = nullptr) {
  if (result == ncclSuccess) return;
  std::string message =
      std::string("data-parallel training: NCCL's ") + call + " failed: " + ncclGetErrorString(result);
  if (const char* detail = ncclGetLastError(communicator); detail && *detail)
    message += std::string(" (") + detail + ")";
  throw Error(message);
}

ncclDataType_t nccl_type(at::ScalarType type) {
  switch (type) {
    case at::kFloat: return ncclFloat32;
    case at::kDouble: return ncclFloat64;
    case at::kHalf: return ncclFloat16;
    case at::kBFloat16: return ncclBfloat16;
    case at::kInt: return ncclInt32;
    case at::kLong: return ncclInt64;
    default: throw Error(std::string("data-parallel training: NCCL cannot reduce tensors of ") + c10::toString(type));
  }
}

}  // namespace

std::vector<uint8_t> NcclGroup::new_token() {
  ncclUniqueId id;
  check(ncclGetUniqueId(&id), "ncclGetUniqueId");
  std::vector<uint8_t> token(sizeof(id));
  std::memcpy(token.data(), &id, sizeof(id));
  return token;
}

NcclGroup::NcclGroup(const std::vector<uint8_t>& token, int rank, int world, const at::Device& device)
    : device_(at::kCUDA, device.has_index() ? device.index() : c10::cuda::current_device()),
      // High priority: its few blocks are scheduled ahead of the backward kernels it runs beside.
      communication_(c10::cuda::getStreamFromPool(/*isHighPriority=*/true, device_.index())) {
  ncclUniqueId id;
  if (token.size() != sizeof(id))
    throw Error("data-parallel training: the NCCL token read from the rendezvous has " + std::to_string(token.size()) +
                " bytes, not " + std::to_string(sizeof(id)) + " (processes of different builds?)");
  std::memcpy(&id, token.data(), sizeof(id));
  const c10::cuda::CUDAGuard guard(device_);
  check(ncclCommInitRank(&communicator_, world, id, rank), "ncclCommInitRank");
}

NcclGroup::~NcclGroup() {
  if (communicator_) ncclCommDestroy(communicator_);
}

void NcclGroup::start_all_reduce(const std::vector<at::Tensor>& tensors, bool mean) {
  // Checked before the group call opens: a throw inside it would leave it open.
  for (const at::Tensor& tensor : tensors) {
    if (tensor.device() != device_)
      throw Error("data-parallel training: a tensor on " + tensor.device().str() + " given to the NCCL group of " +
                  device_.str());
    nccl_type(tensor.scalar_type());
  }
  const c10::cuda::CUDAGuard guard(device_);
  std::vector<at::Tensor> reduced;
  for (const at::Tensor& tensor : tensors) reduced.push_back(tensor.contiguous());  // itself where contiguous
  queued_.record(c10::cuda::getCurrentCUDAStream(device_.index()));
  queued_.block(communication_);
  {
    const c10::cuda::CUDAStreamGuard on_communication(communication_);
    check(ncclGroupStart(), "ncclGroupStart", communicator_);
    for (const at::Tensor& r : reduced)
      check(ncclAllReduce(r.data_ptr(), r.data_ptr(), static_cast<size_t>(r.numel()), nccl_type(r.scalar_type()),
                          mean ? ncclAvg : ncclSum, communicator_, communication_.stream()),
            "ncclAllReduce", communicator_);
    check(ncclGroupEnd(), "ncclGroupEnd", communicator_);
    for (size_t i = 0; i < tensors.size(); ++i) {
      if (!reduced[i].is_same(tensors[i])) tensors[i].copy_(reduced[i]);
      // Their memory is not reused by the caller's stream before this stream is done with it.
      reduced[i].record_stream(communication_);
      tensors[i].record_stream(communication_);
    }
  }
}

void NcclGroup::join() {
  reduced_.record(communication_);
  reduced_.block(c10::cuda::getCurrentCUDAStream(device_.index()));
}

}  // namespace tega::trainer
