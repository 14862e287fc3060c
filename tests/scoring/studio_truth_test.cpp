// The face region MVS is scored over holds what at least two cameras see:
// a plate behind a skin with a hole (a mouth) counts only where the hole
// shows it.
#include "tega/scoring/studio_truth.h"

#include <gtest/gtest.h>

#include <fstream>
#include <set>

#include "tega/core/rig.h"
#include "test_support.h"

namespace tega::scoring {
namespace {

namespace fs = std::filesystem;

// Squares of `cell` metres over [x0, x1] x [y0, y1] at depth z, facing +z,
// except those whose centre `skip` accepts.
void add_plate(Mesh& mesh, double x0, double x1, double y0, double y1, double z, double cell,
               const std::function<bool(double, double)>& skip) {
  std::vector<Eigen::Vector3f> corners;
  std::vector<Eigen::Vector3i> triangles;
  for (double x = x0; x < x1 - 1e-9; x += cell)
    for (double y = y0; y < y1 - 1e-9; y += cell) {
      if (skip(x + cell / 2, y + cell / 2)) continue;
      const int base = int(mesh.positions.rows() + corners.size());
      for (const auto& [dx, dy] : {std::pair{0.0, 0.0}, {cell, 0.0}, {cell, cell}, {0.0, cell}})
        corners.emplace_back(float(x + dx), float(y + dy), float(z));
      triangles.emplace_back(base, base + 1, base + 2);
      triangles.emplace_back(base, base + 2, base + 3);
    }
  const Eigen::Index v0 = mesh.positions.rows(), f0 = mesh.faces.rows();
  mesh.positions.conservativeResize(v0 + Eigen::Index(corners.size()), 3);
  mesh.faces.conservativeResize(f0 + Eigen::Index(triangles.size()), 3);
  for (size_t i = 0; i < corners.size(); ++i) mesh.positions.row(v0 + Eigen::Index(i)) = corners[i].transpose();
  for (size_t i = 0; i < triangles.size(); ++i) mesh.faces.row(f0 + Eigen::Index(i)) = triangles[i].transpose();
}

bool in_mouth(double x, double y) { return std::abs(x) < 0.01 && y > -0.04 && y < -0.03; }

// Cameras half a metre in front of the face, looking back along -z.
Rig front_rig(const std::vector<double>& xs) {
  Rig rig;
  for (double x : xs) {
    Camera c;
    c.name = "cam" + std::to_string(rig.cameras.size());
    c.width = 640;
    c.height = 480;
    c.K << 1000, 0, 319.5, 0, 1000, 239.5, 0, 0, 1;
    c.world_to_camera.R = Eigen::Vector3d(1, -1, -1).asDiagonal();
    c.world_to_camera.t = -c.world_to_camera.R * Eigen::Vector3d(x, 0, 0.5);
    rig.cameras.push_back(c);
  }
  return rig;
}

// A capture with ground truth whose head is a skin plate at z = 2 cm with
// a mouth hole and a "teeth" plate 2 cm behind it; returns the teeth's
// first face.
int write_capture(const fs::path& capture, const Rig& rig) {
  Mesh head;
  head.positions.resize(0, 3);
  head.faces.resize(0, 3);
  add_plate(head, -0.05, 0.05, -0.05, 0.05, 0.02, 0.01, in_mouth);
  const int teeth = head.num_faces();
  add_plate(head, -0.03, 0.03, -0.045, -0.015, 0.0, 0.0025, [](double, double) { return false; });
  const fs::path head_dir = capture / "ground_truth" / "head";
  fs::create_directories(head_dir);
  write_obj(head, head_dir / "template.obj");
  write_obj(head, head_dir / "fine_topology.obj");
  std::ofstream(head_dir / "head.json") << R"({"eye_left": [0.03, 0, 0], "eye_right": [-0.03, 0, 0], "interocular_m": 0.06})";
  fs::create_directories(capture / "ground_truth" / "expressions" / "fine");
  write_vertices_bin(head.positions, capture / "ground_truth" / "expressions" / "fine" / "000000.bin");
  write_rig_json(rig, capture / "rig.json");
  return teeth;
}

Eigen::Vector2d centroid_xy(const Mesh& mesh, int f) {
  Eigen::Vector2d c = Eigen::Vector2d::Zero();
  for (int k = 0; k < 3; ++k) c += mesh.positions.row(mesh.faces(f, k)).head<2>().cast<double>().transpose() / 3.0;
  return c;
}

TEST(StudioTruth, TheFaceRegionHoldsWhatTwoCamerasSee) {
  const test::TempDir dir;
  const int teeth = write_capture(dir.path(), front_rig({-0.05, 0.0, 0.05}));
  const StudioTruth truth = load_studio_truth(dir.path(), "expressions", 0);

  int skin = 0, teeth_seen = 0;
  for (int f : truth.face_region) {
    if (f < teeth) {
      ++skin;
      continue;
    }
    ++teeth_seen;
    // Within the hole, give or take the few millimetres the side cameras
    // look past its edges.
    const Eigen::Vector2d c = centroid_xy(truth.fine, f);
    EXPECT_LT(std::abs(c.x()), 0.0125) << "face " << f;
    EXPECT_GT(c.y(), -0.0425) << "face " << f;
    EXPECT_LT(c.y(), -0.0275) << "face " << f;
  }
  EXPECT_EQ(skin, teeth) << "every skin face faces the cameras unhidden";
  // The hole is 2 x 1 cm: 32 cells of 2.5 mm, two faces each, the side
  // cameras' shift lost at its edges.
  EXPECT_GE(teeth_seen, 2 * 20);
  EXPECT_LE(teeth_seen, 2 * 32);
  // Tracked meshes are scored on the template's vertices of what is seen
  // (here the template is its own fine topology): the skin and the teeth
  // within the hole, not the teeth behind the skin.
  std::set<int> seen_vertices;
  for (int f : truth.face_region)
    for (int k = 0; k < 3; ++k) seen_vertices.insert(truth.fine.faces(f, k));
  EXPECT_EQ(std::set<int>(truth.face_vertices.begin(), truth.face_vertices.end()), seen_vertices);
  const int first_tooth_vertex = truth.fine.faces(teeth, 0);
  int teeth_vertices = 0;
  for (int v : truth.face_vertices) {
    if (v < first_tooth_vertex) continue;
    ++teeth_vertices;
    // The seen teeth faces' corners: within a 2.5 mm cell of their centroids' bounds above.
    const double x = truth.fine.positions(v, 0), y = truth.fine.positions(v, 1);
    EXPECT_LT(std::abs(x), 0.0151) << "vertex " << v;
    EXPECT_GT(y, -0.0451) << "vertex " << v;
    EXPECT_LT(y, -0.0249) << "vertex " << v;
  }
  EXPECT_GT(teeth_vertices, 0);
}

TEST(StudioTruth, OneCameraSeesNoFaceStereoCouldRecover) {
  const test::TempDir dir;
  write_capture(dir.path(), front_rig({0.0}));
  EXPECT_TRUE(load_studio_truth(dir.path(), "expressions", 0).face_region.empty());
}

}  // namespace
}  // namespace tega::scoring
