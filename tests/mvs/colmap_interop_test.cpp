// COLMAP 3.8 itself reads what tega writes: its stereo_fusion fuses tega's
// depth and normal maps of an analytic sphere into points on that sphere, and
// its poisson_mesher meshes tega's fused.ply. Skipped without `colmap`.
#include <gtest/gtest.h>

#include <cstdlib>
#include <fstream>
#include <sstream>

#include "sphere_scene.h"
#include "tega/mvs/colmap_workspace.h"
#include "test_support.h"

namespace tega::mvs {
namespace {

namespace fs = std::filesystem;
using test::kRadius;
// COLMAP's MVS takes depth-map pixel (col, row) on the ray through image
// coordinate (col, row) in its own convention, which puts pixel centres at +0.5:
// half a pixel up and left of the centre (colmap_workspace.h).
constexpr double kColmapDepthPixelOffset = -0.5;

std::optional<fs::path> colmap_executable() {
  const char* path = std::getenv("PATH");
  std::istringstream directories(path ? path : "");
  for (std::string directory; std::getline(directories, directory, ':');)
    if (!directory.empty() && fs::exists(fs::path(directory) / "colmap")) return fs::path(directory) / "colmap";
  return std::nullopt;
}

#define TEGA_REQUIRE_COLMAP(var)                           \
  const std::optional<fs::path> var = colmap_executable(); \
  if (!var) GTEST_SKIP() << "colmap (COLMAP 3.8) is not on PATH"

// Runs colmap headless; fails the test with its output when it fails.
void run_colmap(const fs::path& colmap, const std::string& arguments, const fs::path& log) {
  const std::string command =
      "QT_QPA_PLATFORM=offscreen '" + colmap.string() + "' " + arguments + " > '" + log.string() + "' 2>&1";
  const int status = std::system(command.c_str());
  std::ifstream in(log);
  const std::string output((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  ASSERT_EQ(status, 0) << command << "\n" << output;
}

double distance_to_sphere(const Eigen::Vector3f& point) { return std::abs(point.cast<double>().norm() - kRadius); }

TEST(ColmapInterop, StereoFusionFusesTegasDepthMaps) {
  TEGA_REQUIRE_COLMAP(colmap);
  tega::test::TempDir dir;
  const fs::path ws = dir / "ws";
  DenseWorkspace workspace;
  workspace.rig = test::cap_rig(8, 25, 0.5, 200, 200, 350);
  for (const Camera& camera : workspace.rig.cameras) {
    workspace.images[camera.name] = test::sphere_image(camera, kRadius);
    workspace.depth_maps[camera.name] = test::sphere_depth_map(camera, kRadius, kColmapDepthPixelOffset);
  }
  write_dense_workspace(workspace, ws);

  run_colmap(*colmap,
             "stereo_fusion --workspace_path '" + ws.string() +
                 "' --workspace_format COLMAP --input_type geometric --output_path '" +
                 (ws / "fused_by_colmap.ply").string() + "'",
             dir / "fusion.log");
  const OrientedPointCloud fused = read_point_cloud_ply(ws / "fused_by_colmap.ply");
  // Each view sees the sphere in ~16000 pixels; a fused point takes at least
  // COLMAP's min_num_pixels (5), most many more.
  EXPECT_GT(fused.size(), 3000);
  int off_surface = 0, inward = 0, miscoloured = 0;
  double worst = 0;
  ASSERT_EQ(fused.colors.rows(), fused.size());
  for (int i = 0; i < fused.size(); ++i) {
    const Eigen::Vector3f p = fused.points.row(i).transpose();
    off_surface += distance_to_sphere(p) > 0.001;
    worst = std::max(worst, distance_to_sphere(p));
    inward += fused.normals.row(i).dot(p.normalized().transpose()) < 0.9f;
    // The images colour the sphere by position (sphere_image): COLMAP read them, in RGB order.
    const Eigen::Vector3f expected = Eigen::Vector3f::Constant(127.5f) + 127 * p / float(kRadius);
    miscoloured += (fused.colors.row(i).cast<float>().transpose() - expected).cwiseAbs().maxCoeff() > 20;
  }
  EXPECT_EQ(off_surface, 0) << "farthest " << worst << " m";
  EXPECT_EQ(inward, 0);
  // At the silhouette the pixel's centre may miss the sphere that its depth
  // (half a pixel off) hits, and COLMAP takes that pixel's background colour.
  EXPECT_LT(miscoloured, fused.size() / 200);
}

TEST(ColmapInterop, PoissonMesherMeshesTegasFusedCloud) {
  TEGA_REQUIRE_COLMAP(colmap);
  tega::test::TempDir dir;
  write_point_cloud_ply(test::sphere_cloud(20000, kRadius), dir / "fused.ply");
  // Depth 7 (~2 mm cells) keeps the run short; COLMAP's default trim (10)
  // would cut every vertex at that depth, whose densities are about 6.
  run_colmap(
      *colmap,
      "poisson_mesher --PoissonMeshing.depth 7 --PoissonMeshing.trim 0 --PoissonMeshing.num_threads 1 --input_path '" +
          (dir / "fused.ply").string() + "' --output_path '" + (dir / "meshed-poisson.ply").string() + "'",
      dir / "poisson.log");
  const Mesh mesh = read_ply(dir / "meshed-poisson.ply");
  ASSERT_GT(mesh.num_faces(), 5000);
  double worst = 0;
  for (int v = 0; v < mesh.num_vertices(); ++v) worst = std::max(worst, distance_to_sphere(mesh.positions.row(v)));
  EXPECT_LT(worst, 0.001);
}

}  // namespace
}  // namespace tega::mvs
