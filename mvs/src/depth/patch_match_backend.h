#pragma once
// Where the sweeps of one view run: the CPU path or the CUDA kernels. Both
// take the same per-pixel math (patch_match_math.h) and the same parameters,
// so the passes over views (patch_match.cpp) are written once.

#include <memory>
#include <vector>

#include "patch_match_math.h"
#include "tega/mvs/patch_match.h"

namespace tega::mvs::detail {

// The reference and source geometry of a task; pixel pointers are the caller's.
ReferenceView reference_geometry(const Camera& camera);
SourceView source_geometry(const Camera& reference, const Camera& source);

class PatchMatchBackend {
 public:
  virtual ~PatchMatchBackend() = default;
  // One view's estimate. Photometric passes start from random hypotheses;
  // geometric ones (params.geometric) start from previous[task.reference] and
  // read the sources' depth in `previous` (indexed by view). Every sweep runs
  // `sweeps` times from `first_iteration` on (params.iteration counts on).
  virtual DepthMap run(const ViewTask& task, Parameters params, const std::vector<DepthMap>& previous,
                       int first_iteration, int sweeps) = 0;
};

std::unique_ptr<PatchMatchBackend> make_cpu_backend(const std::vector<StereoView>& views, ThreadPool& pool);
// Throws tega::Error in a build without CUDA.
std::unique_ptr<PatchMatchBackend> make_cuda_backend(const std::vector<StereoView>& views);

}  // namespace tega::mvs::detail
