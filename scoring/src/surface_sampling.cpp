#include "surface_sampling.h"

#include <Eigen/Geometry>
#include <cmath>
#include <numeric>
#include <random>

namespace tega::scoring {
namespace {

// Uniform in [0, 1) from 53 random bits: unlike std::uniform_real_distribution,
// the same on every standard library.
double uniform(std::mt19937_64& random) { return double(random() >> 11) * 0x1.0p-53; }

}  // namespace

Vertices sample_surface(const Mesh& mesh, const std::vector<int>& faces, double spacing_m, uint64_t seed) {
  std::vector<int> chosen = faces;
  if (chosen.empty()) {
    chosen.resize(size_t(mesh.num_faces()));
    std::iota(chosen.begin(), chosen.end(), 0);
  }
  std::mt19937_64 random(seed);
  const double per_square_metre = 1.0 / (spacing_m * spacing_m);
  std::vector<Eigen::Vector3d> samples;
  for (const int f : chosen) {
    const Eigen::Vector3d a = mesh.positions.row(mesh.faces(f, 0)).transpose().cast<double>();
    const Eigen::Vector3d b = mesh.positions.row(mesh.faces(f, 1)).transpose().cast<double>();
    const Eigen::Vector3d c = mesh.positions.row(mesh.faces(f, 2)).transpose().cast<double>();
    const double expected = 0.5 * (b - a).cross(c - a).norm() * per_square_metre;
    const int count = int(std::floor(expected + uniform(random)));
    for (int i = 0; i < count; ++i) {
      // Folding the unit square onto the triangle keeps the density uniform.
      double u = uniform(random), v = uniform(random);
      if (u + v > 1) u = 1 - u, v = 1 - v;
      samples.push_back(a + u * (b - a) + v * (c - a));
    }
  }
  Vertices out(Eigen::Index(samples.size()), 3);
  for (size_t i = 0; i < samples.size(); ++i) out.row(Eigen::Index(i)) = samples[i].transpose().cast<float>();
  return out;
}

}  // namespace tega::scoring
