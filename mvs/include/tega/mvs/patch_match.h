#pragma once
// PatchMatch multi-view stereo: a depth and a normal per pixel of every view,
// by plane hypotheses scored with a bilateral-weighted NCC against the view's
// source views (docs/mvs.md#depth-estimation). Two implementations share the
// per-pixel math: a multi-threaded CPU path and CUDA kernels; with the same
// options and seed they give the same maps up to float rounding.

#include <cstdint>
#include <string>
#include <vector>

#include "tega/core/camera.h"
#include "tega/core/image.h"
#include "tega/mvs/depth_map.h"

namespace tega {
class ThreadPool;
class Progress;
}  // namespace tega

namespace tega::mvs {

struct PatchMatchOptions {
  int window_radius = 4;        // pixels; the window spans 2 * radius + 1
  int window_step = 2;          // sample every step-th pixel of the window
  float sigma_spatial = 4.0f;   // bilateral weight: pixels
  float sigma_color = 0.08f;    // bilateral weight: intensity in [0, 1]
  int source_views = 6;         // at most this many source views per view (the best by baseline and angle)
  int top_k = 3;                // a hypothesis' cost: the mean of its best top_k source costs
  int iterations = 5;           // photometric red-black sweeps
  int geometric_passes = 1;     // passes over every view with the geometric-consistency term
  int geometric_iterations = 2;
  float geometric_weight = 0.2f;        // per pixel of reprojection error
  float geometric_max_error_px = 3.0f;  // the reprojection error is clipped here
  float max_cost = 0.7f;        // estimates costing more are dropped
  int seed = 1;
  // Coarse to fine: the whole estimate (iterations and geometric passes) first
  // at half size per level, then at each finer level only refine_passes
  // geometric passes of refine_iterations, starting from the coarser planes.
  int pyramid_levels = 0;
  int refine_passes = 1;
  int refine_iterations = 2;

  template <class V>
  void visit(V& v) {
    v("window_radius", window_radius, "Matching window half-size in pixels (the window spans 2 * radius + 1).");
    v("window_step", window_step, "Sample every step-th pixel of the window.");
    v("sigma_spatial", sigma_spatial, "Bilateral window weight: spatial sigma in pixels.");
    v("sigma_color", sigma_color, "Bilateral window weight: intensity sigma (intensities in [0, 1]).");
    v("source_views", source_views, "Source views per reference view, chosen by baseline and viewing angle.");
    v("top_k", top_k, "A hypothesis costs the mean of its top_k best source views (robust to occlusion).");
    v("iterations", iterations, "Photometric PatchMatch iterations (each a red and a black sweep).");
    v("geometric_passes", geometric_passes, "Passes with the geometric-consistency term (0: photometric only).");
    v("geometric_iterations", geometric_iterations, "Iterations of each geometric pass.");
    v("geometric_weight", geometric_weight, "Weight of the reprojection error (per pixel) against 1 - NCC.");
    v("geometric_max_error_px", geometric_max_error_px, "The reprojection error is clipped at this many pixels.");
    v("max_cost", max_cost, "Estimates whose final cost exceeds this are dropped.");
    v("seed", seed, "Seed of the random hypotheses (the result is deterministic for a seed).");
    v("pyramid_levels", pyramid_levels,
      "Coarse to fine: estimate at 1/2^levels of the size first (window and sigma_spatial scaled along), then refine "
      "at each finer level (0: full size only).");
    v("refine_passes", refine_passes, "Geometric passes at each finer pyramid level.");
    v("refine_iterations", refine_iterations, "Iterations of each of those passes.");
  }
};

// One view: an undistorted (pinhole) camera and its grey image in [0, 1].
struct StereoView {
  Camera camera;                // zero distortion
  ImageF grey;                  // 1 channel, the camera's size
  std::vector<uint8_t> mask;    // width * height, 0 = not the subject (not estimated); empty = everything
  Image8 colour;                // optional RGB image, for coloured fused points
};

// What to estimate for one view.
struct ViewTask {
  int reference = 0;
  std::vector<int> sources;     // indices into the views
  float depth_min = 0, depth_max = 0;  // metres along the reference camera's z axis
};

enum class Device { cpu, cuda };
Device parse_device(const std::string& name);  // "cpu" | "cuda"; throws tega::Error otherwise
bool cuda_device_available();                  // a CUDA build with a usable GPU (its context is made here)

// Depth maps of every task's reference view, in task order. `pool` runs the
// CPU path (nullptr: a pool of its own); `progress`, when given, advances by
// one per view and pass (at every pyramid level). Throws tega::Error on bad input (sizes, indices) and
// when the device is not available.
std::vector<DepthMap> estimate_depth_maps(const std::vector<StereoView>& views, const std::vector<ViewTask>& tasks,
                                          const PatchMatchOptions& options, Device device, ThreadPool* pool = nullptr,
                                          Progress* progress = nullptr);

}  // namespace tega::mvs
