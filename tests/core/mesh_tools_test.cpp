#include "tega/core/mesh_tools.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>
#include <set>

#include "tega/core/error.h"

namespace tega {
namespace {

// An n x n grid of quads on z = 0, each split into two triangles.
Mesh grid(int n) {
  Mesh mesh;
  mesh.positions.resize((n + 1) * (n + 1), 3);
  for (int y = 0; y <= n; ++y) {
    for (int x = 0; x <= n; ++x) mesh.positions.row(y * (n + 1) + x) << float(x) / n, float(y) / n, 0.0f;
  }
  mesh.faces.resize(2 * n * n, 3);
  for (int y = 0; y < n; ++y) {
    for (int x = 0; x < n; ++x) {
      const int a = y * (n + 1) + x, b = a + 1, c = a + n + 2, d = a + n + 1;
      mesh.faces.row(2 * (y * n + x)) << a, b, c;
      mesh.faces.row(2 * (y * n + x) + 1) << a, c, d;
    }
  }
  return mesh;
}

// A closed unit sphere: two poles and `rings` x `segments` vertices between them.
Mesh sphere(int rings, int segments) {
  Mesh mesh;
  const int v = rings * segments + 2, north = v - 2, south = v - 1;
  mesh.positions.resize(v, 3);
  for (int r = 0; r < rings; ++r) {
    const double theta = M_PI * (r + 1) / (rings + 1);
    for (int s = 0; s < segments; ++s) {
      const double phi = 2 * M_PI * s / segments;
      mesh.positions.row(r * segments + s) << float(std::sin(theta) * std::cos(phi)),
          float(std::sin(theta) * std::sin(phi)), float(std::cos(theta));
    }
  }
  mesh.positions.row(north) << 0, 0, 1;
  mesh.positions.row(south) << 0, 0, -1;
  std::vector<int32_t> faces;
  for (int s = 0; s < segments; ++s) {
    const int t = (s + 1) % segments;
    faces.insert(faces.end(), {north, s, t});
    for (int r = 0; r + 1 < rings; ++r) {
      const int a = r * segments + s, b = r * segments + t, c = b + segments, d = a + segments;
      faces.insert(faces.end(), {a, d, c, a, c, b});
    }
    faces.insert(faces.end(), {south, (rings - 1) * segments + t, (rings - 1) * segments + s});
  }
  mesh.faces = Eigen::Map<const Triangles>(faces.data(), static_cast<Eigen::Index>(faces.size() / 3), 3);
  return mesh;
}

TEST(MeshTools, OneRingsAreCounterClockwise) {
  // A hexagon fanned around vertex 0, counter-clockwise seen from +z.
  Mesh mesh;
  mesh.positions.resize(7, 3);
  mesh.positions.row(0) << 0, 0, 0;
  for (int i = 0; i < 6; ++i) mesh.positions.row(i + 1) << float(std::cos(i * M_PI / 3)), float(std::sin(i * M_PI / 3)), 0;
  mesh.faces.resize(6, 3);
  for (int i = 0; i < 6; ++i) mesh.faces.row(i) << 0, i + 1, (i + 1) % 6 + 1;

  const VertexAdjacency adjacency = vertex_one_rings(mesh);
  ASSERT_EQ(adjacency.offsets.size(), 8u);
  const auto centre = adjacency.of(0);
  ASSERT_EQ(centre.size(), 6u);
  for (size_t k = 0; k < 6; ++k) EXPECT_EQ(centre[(k + 1) % 6], centre[k] % 6 + 1) << "not counter-clockwise";
  const auto rim = adjacency.of(1);
  EXPECT_EQ(std::set<int32_t>(rim.begin(), rim.end()), (std::set<int32_t>{0, 2, 6}));
  EXPECT_EQ(adjacency.neighbours.size(), 6u + 6u * 3u);
}

TEST(MeshTools, LaplacianSmoothingFlattensNoiseAndKeepsTheBoundary) {
  Mesh mesh = grid(20);
  std::mt19937 random(7);
  std::uniform_real_distribution<float> noise(-0.05f, 0.05f);
  for (Eigen::Index v = 0; v < mesh.positions.rows(); ++v) mesh.positions(v, 2) = noise(random);

  const Vertices smoothed = smooth_laplacian(mesh, 10);
  ASSERT_EQ(smoothed.rows(), mesh.positions.rows());
  float rough = 0, smooth = 0;
  for (int y = 0; y <= 20; ++y) {
    for (int x = 0; x <= 20; ++x) {
      const int v = y * 21 + x;
      if (x == 0 || y == 0 || x == 20 || y == 20) {
        EXPECT_EQ(smoothed.row(v), mesh.positions.row(v)) << "boundary vertex " << v << " moved";
      } else {
        rough += std::abs(mesh.positions(v, 2));
        smooth += std::abs(smoothed(v, 2));
      }
    }
  }
  EXPECT_LT(smooth, 0.3f * rough);
}

TEST(MeshTools, DecimationReachesTheTargetAndStaysOnTheSurface) {
  const Mesh mesh = sphere(40, 80);
  const Mesh coarse = decimate(mesh, 500);
  EXPECT_LE(coarse.num_faces(), 500);
  EXPECT_GE(coarse.num_faces(), 480);
  EXPECT_FALSE(coarse.has_uvs());
  // Still closed and of genus 0: F = 2V - 4.
  EXPECT_EQ(coarse.num_faces(), 2 * coarse.num_vertices() - 4);
  for (Eigen::Index v = 0; v < coarse.positions.rows(); ++v) {
    EXPECT_NEAR(coarse.positions.row(v).norm(), 1.0f, 2e-3f) << "vertex " << v;
  }
  coarse.validate("decimated");
}

TEST(MeshTools, SmallComponentsGoWithTheirVerticesAndTheRestKeepsUvsAndPolygons) {
  // A 2 x 2 grid (8 triangles), then a lone triangle, then a quad of two triangles.
  Mesh mesh = grid(2);
  const int grid_vertices = mesh.num_vertices();
  mesh.positions.conservativeResize(grid_vertices + 7, 3);
  for (int i = 0; i < 7; ++i) mesh.positions.row(grid_vertices + i) << 5.0f + i, 0, 0;
  mesh.faces.conservativeResize(11, 3);
  const int g = grid_vertices;
  mesh.faces.row(8) << g, g + 1, g + 2;
  mesh.faces.row(9) << g + 3, g + 4, g + 5;
  mesh.faces.row(10) << g + 3, g + 5, g + 6;
  mesh.uvs = mesh.positions.leftCols<2>();
  mesh.uv_faces = mesh.faces;
  mesh.triangle_polygon = {0, 0, 1, 1, 2, 2, 3, 3, 4, 5, 5};

  const Mesh two_or_more = remove_small_components(mesh, 2);
  EXPECT_EQ(two_or_more.num_faces(), 10);
  EXPECT_EQ(two_or_more.num_vertices(), grid_vertices + 4);
  EXPECT_EQ(two_or_more.triangle_polygon, (std::vector<int32_t>{0, 0, 1, 1, 2, 2, 3, 3, 5, 5}));
  // The quad's vertices move down by the three of the lone triangle.
  EXPECT_EQ(two_or_more.faces.row(8), Eigen::RowVector3i(g, g + 1, g + 2));
  EXPECT_EQ(two_or_more.positions.row(g), mesh.positions.row(g + 3));
  EXPECT_EQ(two_or_more.uvs.row(g), mesh.uvs.row(g + 3));
  two_or_more.validate("kept");

  const Mesh largest = keep_largest_component(mesh);
  EXPECT_EQ(largest.faces, mesh.faces.topRows(8));
  EXPECT_EQ(largest.positions, mesh.positions.topRows(grid_vertices));
  EXPECT_EQ(largest.uv_faces, mesh.uv_faces.topRows(8));
}

TEST(MeshTools, EmptyMeshStaysEmpty) {
  const Mesh empty;
  EXPECT_EQ(decimate(empty, 10).num_vertices(), 0);
  EXPECT_EQ(keep_largest_component(empty).num_faces(), 0);
  EXPECT_TRUE(vertex_one_rings(empty).neighbours.empty());
}

TEST(MeshTools, NonManifoldInputNamesTheSourceAndTriangle) {
  // Three triangles on one edge.
  Mesh mesh;
  mesh.positions.resize(5, 3);
  mesh.positions << 0, 0, 0, 1, 0, 0, 0, 1, 0, 0, -1, 0, 0, 0, 1;
  mesh.faces.resize(3, 3);
  mesh.faces << 0, 1, 2, 1, 0, 3, 0, 1, 4;
  try {
    vertex_one_rings(mesh, "scan.ply");
    FAIL() << "no error";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("scan.ply: triangle 2 (0 1 4)"), std::string::npos) << e.what();
  }
}

TEST(MeshTools, ATriangleOnAFullEdgeIsItsOwnComponent) {
  // Three triangles on one edge, as trimmed Poisson surfaces have: the first
  // two hold the edge, the third is detached.
  Mesh mesh;
  mesh.positions.resize(5, 3);
  mesh.positions << 0, 0, 0, 1, 0, 0, 0, 1, 0, 0, -1, 0, 0, 0, 1;
  mesh.faces.resize(3, 3);
  mesh.faces << 0, 1, 2, 1, 0, 3, 0, 1, 4;
  const Mesh kept = remove_small_components(mesh, 2, "scan.ply");
  ASSERT_EQ(kept.num_faces(), 2);
  EXPECT_EQ(kept.num_vertices(), 4);
  EXPECT_EQ(keep_largest_component(mesh).num_faces(), 2);
}

}  // namespace
}  // namespace tega
