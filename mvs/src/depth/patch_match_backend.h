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

// Holds every view's estimate where the sweeps run (on the GPU for the CUDA
// path), so that passes hand maps on without copies: a pass writes the next
// estimates while reading the current ones, and finish_pass() makes them current.
class PatchMatchBackend {
 public:
  virtual ~PatchMatchBackend() = default;
  // The next estimate of the task's reference view. Photometric runs start
  // from random hypotheses; geometric ones (params.geometric) from the view's
  // current estimate, and read the sources' current depth. Every sweep runs
  // `sweeps` times from `first_iteration` on (params.iteration counts on).
  virtual void run(const ViewTask& task, Parameters params, int first_iteration, int sweeps) = 0;
  virtual void finish_pass() = 0;
  virtual void set_estimate(int view, const DepthMap& map) = 0;  // the view's current estimate
  virtual DepthMap estimate(int view) const = 0;                 // empty where the view has none
};

std::unique_ptr<PatchMatchBackend> make_cpu_backend(const std::vector<StereoView>& views, ThreadPool& pool);
// Throws tega::Error in a build without CUDA.
std::unique_ptr<PatchMatchBackend> make_cuda_backend(const std::vector<StereoView>& views);

}  // namespace tega::mvs::detail
