#include "tega/scoring/surface_scores.h"

#include <gtest/gtest.h>

#include <random>

#include "sphere_scene.h"
#include "tega/core/error.h"

namespace tega::scoring {
namespace {

using mvs::test::kRadius;

// Faces of `mesh` whose centroid has z > 0.
std::vector<int> upper_faces(const Mesh& mesh) {
  std::vector<int> faces;
  for (int f = 0; f < mesh.num_faces(); ++f)
    if (mesh.positions(mesh.faces(f, 0), 2) + mesh.positions(mesh.faces(f, 1), 2) +
            mesh.positions(mesh.faces(f, 2), 2) >
        0)
      faces.push_back(f);
  return faces;
}

Mesh keep_faces(const Mesh& mesh, const std::vector<int>& faces) {
  Mesh out = mesh;
  out.faces.resize(Eigen::Index(faces.size()), 3);
  for (size_t i = 0; i < faces.size(); ++i) out.faces.row(Eigen::Index(i)) = mesh.faces.row(faces[i]);
  return out;
}

TEST(Evaluation, ConcentricSpheresOneMillimetreApart) {
  const Mesh truth = mvs::test::sphere_mesh(kRadius, 6);
  const Mesh reconstruction = mvs::test::sphere_mesh(kRadius + 0.001, 6);
  EvaluationOptions options;
  options.tolerances_m = {0.0005, 0.002};
  options.sample_spacing_m = 0.001;
  const SurfaceScores scores = evaluate_surface(reconstruction, truth, {}, options);
  EXPECT_NEAR(scores.accuracy_median_m, 0.001, 0.00002);
  EXPECT_NEAR(scores.accuracy_mean_m, 0.001, 0.00002);
  EXPECT_NEAR(scores.accuracy_p90_m, 0.001, 0.00002);
  EXPECT_EQ(scores.tolerances_m, options.tolerances_m);
  ASSERT_EQ(scores.completeness.size(), 2u);
  EXPECT_EQ(scores.completeness[0], 0.0);
  EXPECT_EQ(scores.completeness[1], 1.0);
  // One sample per spacing² of area.
  const double area = 4 * std::numbers::pi * kRadius * kRadius / (0.001 * 0.001);
  EXPECT_NEAR(scores.truth_samples, area, 0.02 * area);
  EXPECT_NEAR(scores.reconstruction_samples, area, 0.03 * area);

  // Fixed seeds: the same meshes score the same.
  const SurfaceScores again = evaluate_surface(reconstruction, truth, {}, options);
  EXPECT_EQ(again.accuracy_median_m, scores.accuracy_median_m);
  EXPECT_EQ(again.truth_samples, scores.truth_samples);
}

TEST(Evaluation, RegionLimitsCompletenessAndAccuracy) {
  const Mesh truth = mvs::test::sphere_mesh(kRadius, 5);
  const Mesh sphere = mvs::test::sphere_mesh(kRadius + 0.001, 5);
  const Mesh upper_half = keep_faces(sphere, upper_faces(sphere));
  EvaluationOptions options;
  options.tolerances_m = {0.002};
  options.sample_spacing_m = 0.002;

  // Half the truth is reconstructed; completeness over the upper half is full.
  EXPECT_NEAR(evaluate_surface(upper_half, truth, {}, options).completeness[0], 0.5, 0.03);
  const SurfaceScores upper = evaluate_surface(upper_half, truth, upper_faces(truth), options);
  EXPECT_EQ(upper.completeness[0], 1.0);

  // A reconstruction beyond the region (its lower half, but for a band
  // within the margin of the equator) does not count towards accuracy.
  options.accuracy_region_margin_m = 0.002;
  const SurfaceScores whole = evaluate_surface(sphere, truth, upper_faces(truth), options);
  const SurfaceScores half = evaluate_surface(upper_half, truth, upper_faces(truth), options);
  EXPECT_LT(whole.reconstruction_samples, 0.6 * evaluate_surface(sphere, truth, {}, options).reconstruction_samples);
  EXPECT_NEAR(whole.reconstruction_samples, half.reconstruction_samples, 0.1 * half.reconstruction_samples);
  options.accuracy_region_margin_m = 0;
  EXPECT_NEAR(evaluate_surface(sphere, truth, upper_faces(truth), options).reconstruction_samples,
              2 * half.reconstruction_samples, 0.06 * half.reconstruction_samples);
}

TEST(Evaluation, DistancesToMeshMatchBruteForce) {
  const Mesh mesh = mvs::test::sphere_mesh(kRadius, 3);
  std::mt19937 random(7);
  std::uniform_real_distribution<float> coordinate(-0.2f, 0.2f);
  Vertices points(500, 3);
  for (int i = 0; i < points.rows(); ++i)
    for (int k = 0; k < 3; ++k) points(i, k) = coordinate(random);
  const std::vector<double> fast = distances_to_mesh(points, mesh);
  ASSERT_EQ(fast.size(), 500u);
  // Brute force: the minimum over every triangle of the distance to the
  // nearest point of its plane, when that lies inside, or of its edges.
  const auto segment = [](const Eigen::Vector3d& p, const Eigen::Vector3d& a, const Eigen::Vector3d& b) {
    const double t = std::clamp((p - a).dot(b - a) / (b - a).squaredNorm(), 0.0, 1.0);
    return (a + t * (b - a) - p).norm();
  };
  for (int i = 0; i < points.rows(); ++i) {
    const Eigen::Vector3d p = points.row(i).cast<double>();
    double best = std::numeric_limits<double>::infinity();
    for (int f = 0; f < mesh.num_faces(); ++f) {
      const Eigen::Vector3d a = mesh.positions.row(mesh.faces(f, 0)).cast<double>();
      const Eigen::Vector3d b = mesh.positions.row(mesh.faces(f, 1)).cast<double>();
      const Eigen::Vector3d c = mesh.positions.row(mesh.faces(f, 2)).cast<double>();
      const Eigen::Vector3d n = (b - a).cross(c - a).normalized();
      const Eigen::Vector3d q = p - n * n.dot(p - a);
      const bool inside =
          (b - a).cross(q - a).dot(n) >= 0 && (c - b).cross(q - b).dot(n) >= 0 && (a - c).cross(q - c).dot(n) >= 0;
      best = std::min(best, inside ? (p - q).norm() : std::min({segment(p, a, b), segment(p, b, c), segment(p, c, a)}));
    }
    EXPECT_NEAR(fast[size_t(i)], best, 1e-12) << "point " << i;
  }
}

TEST(Evaluation, BadInputIsAnError) {
  const Mesh truth = mvs::test::sphere_mesh(kRadius, 1);
  EXPECT_THROW(evaluate_surface(truth, truth, {truth.num_faces()}, EvaluationOptions{}), Error);
  EXPECT_THROW(evaluate_surface(truth, Mesh{}, {}, EvaluationOptions{}), Error);
  EvaluationOptions no_spacing;
  no_spacing.sample_spacing_m = 0;
  EXPECT_THROW(evaluate_surface(truth, truth, {}, no_spacing), Error);
  // An empty reconstruction is a score, not an error.
  const SurfaceScores empty = evaluate_surface(Mesh{}, truth, {}, EvaluationOptions{});
  EXPECT_EQ(empty.completeness, (std::vector<double>{0, 0, 0}));
  EXPECT_TRUE(std::isnan(empty.accuracy_median_m));
}

}  // namespace
}  // namespace tega::scoring
