#include "tega/scoring/surface_scores.h"

#include <spdlog/fmt/fmt.h>

#include <algorithm>
#include <limits>
#include <numeric>

#include "surface_sampling.h"
#include "tega/core/error.h"
#include "tega/core/thread_pool.h"
#include "tega/core/triangle_distance_tree.h"

namespace tega::scoring {
namespace {

constexpr uint64_t kReconstructionSeed = 1, kTruthSeed = 2;

std::vector<double> distances(const Vertices& points, const TriangleDistanceTree& tree) {
  std::vector<double> out(size_t(points.rows()));
  ThreadPool pool;
  pool.parallel_for(0, points.rows(), [&](int64_t i) {
    out[size_t(i)] = tree.distance(points.row(Eigen::Index(i)).transpose().cast<double>());
  });
  return out;
}

double quantile(std::vector<double> values, double q) {
  const size_t k = std::min(values.size() - 1, size_t(q * double(values.size())));
  std::nth_element(values.begin(), values.begin() + std::ptrdiff_t(k), values.end());
  return values[k];
}

}  // namespace

std::vector<double> distances_to_mesh(const Vertices& points, const Mesh& mesh) {
  mesh.validate("distances_to_mesh");
  return distances(points, TriangleDistanceTree(mesh));
}

SurfaceScores evaluate_surface(const Mesh& reconstruction, const Mesh& truth,
                               const std::vector<int>& truth_region_faces, const EvaluationOptions& options) {
  reconstruction.validate("the reconstruction");
  truth.validate("the ground truth");
  if (!(options.sample_spacing_m > 0))
    throw Error(fmt::format("evaluation: sample_spacing_m must be positive, got {}", options.sample_spacing_m));
  if (truth.num_faces() == 0) throw Error("evaluation: the ground-truth mesh has no faces");
  for (const int f : truth_region_faces)
    if (f < 0 || f >= truth.num_faces())
      throw Error(
          fmt::format("evaluation: region face {} is not a face of the ground truth ({} faces)", f, truth.num_faces()));

  SurfaceScores scores;
  scores.tolerances_m = options.tolerances_m;
  const TriangleDistanceTree truth_tree(truth), region_tree(truth, truth_region_faces);
  const TriangleDistanceTree reconstruction_tree(reconstruction);

  const Vertices truth_samples = sample_surface(truth, truth_region_faces, options.sample_spacing_m, kTruthSeed);
  scores.truth_samples = int(truth_samples.rows());
  const std::vector<double> to_reconstruction = distances(truth_samples, reconstruction_tree);
  for (const double tolerance : options.tolerances_m) {
    const auto within = std::count_if(to_reconstruction.begin(), to_reconstruction.end(),
                                      [tolerance](double d) { return d <= tolerance; });
    scores.completeness.push_back(to_reconstruction.empty() ? 0.0 : double(within) / double(to_reconstruction.size()));
  }

  const Vertices reconstruction_samples =
      sample_surface(reconstruction, {}, options.sample_spacing_m, kReconstructionSeed);
  std::vector<double> accuracy = distances(reconstruction_samples, truth_tree);
  if (options.accuracy_region_margin_m > 0) {
    const std::vector<double> to_region = distances(reconstruction_samples, region_tree);
    std::vector<double> kept;
    for (size_t i = 0; i < accuracy.size(); ++i)
      if (to_region[i] <= options.accuracy_region_margin_m) kept.push_back(accuracy[i]);
    accuracy = std::move(kept);
  }
  scores.reconstruction_samples = int(accuracy.size());
  if (accuracy.empty()) {
    scores.accuracy_median_m = scores.accuracy_mean_m = scores.accuracy_p90_m =
        std::numeric_limits<double>::quiet_NaN();
    return scores;
  }
  scores.accuracy_median_m = quantile(accuracy, 0.5);
  scores.accuracy_p90_m = quantile(accuracy, 0.9);
  scores.accuracy_mean_m = std::accumulate(accuracy.begin(), accuracy.end(), 0.0) / double(accuracy.size());
  return scores;
}

}  // namespace tega::scoring
