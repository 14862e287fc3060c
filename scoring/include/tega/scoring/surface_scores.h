#pragma once
// A reconstructed surface scored against ground truth, in the usual MVS terms:
// accuracy = distance from the reconstruction to the truth; completeness =
// share of the truth (within a region of interest) that lies within a
// tolerance of the reconstruction. Distances are exact point-to-triangle
// distances, the surfaces sampled uniformly by area.

#include <vector>

#include "tega/core/mesh.h"

namespace tega::scoring {

struct SurfaceScores {
  double accuracy_median_m = 0, accuracy_mean_m = 0, accuracy_p90_m = 0;
  std::vector<double> tolerances_m;      // as asked
  std::vector<double> completeness;      // per tolerance: share of the truth region within it, [0, 1]
  int reconstruction_samples = 0, truth_samples = 0;
};

struct EvaluationOptions {
  std::vector<double> tolerances_m = {0.001, 0.002, 0.003};
  double sample_spacing_m = 0.0005;  // mean distance between surface samples
  // Accuracy counts only reconstruction samples within this distance of the
  // truth region's faces (so a reconstructed neck or backdrop beyond the
  // region does not count); 0: every sample.
  double accuracy_region_margin_m = 0.01;
};

// `truth_region_faces`: faces of `truth` in the region of interest (empty: all).
// Accuracy is NaN when no reconstruction sample counts. Sampling uses fixed
// seeds: the same meshes give the same scores. Throws tega::Error on an
// invalid mesh, a region face out of range or a truth without faces.
SurfaceScores evaluate_surface(const Mesh& reconstruction, const Mesh& truth, const std::vector<int>& truth_region_faces,
                               const EvaluationOptions& options);

// Distance from each point to the nearest triangle of `mesh` (exact).
std::vector<double> distances_to_mesh(const Vertices& points, const Mesh& mesh);

}  // namespace tega::scoring
