// The CUDA entry points of a build without nvcc.
#ifndef TEGA_MVS_HAVE_CUDA

#include "fusion_cuda.h"
#include "patch_match_backend.h"
#include "tega/core/error.h"

namespace tega::mvs {

bool cuda_device_available() { return false; }

namespace detail {
std::unique_ptr<PatchMatchBackend> make_cuda_backend(const std::vector<StereoView>&) {
  throw Error("mvs: this build has no CUDA kernels (nvcc was not found at configure time); use --device cpu");
}
std::vector<FusedSample> fuse_pixels_cuda(const std::vector<FusionView>&, const FusionParameters&, int) {
  throw Error("mvs: this build has no CUDA kernels (nvcc was not found at configure time); use --device cpu");
}
}  // namespace detail

}  // namespace tega::mvs

#endif
