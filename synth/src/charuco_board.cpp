#include <cmath>
#include <numbers>

#include "tega/synth/charuco_board.h"
#include "tega/synth/random.h"

namespace tega::synth {

std::vector<Eigen::Vector3d> charuco_corners(const CharucoBoardSpec& b) {
  std::vector<Eigen::Vector3d> out;
  for (int y = 0; y < b.squares_y - 1; ++y)
    for (int x = 0; x < b.squares_x - 1; ++x) out.emplace_back((x + 1) * b.square_m, (y + 1) * b.square_m, 0.0);
  return out;
}

std::vector<RigidTransform> charuco_board_poses(const CharucoBoardSpec& b, int frames, uint64_t seed) {
  constexpr double kDeg = std::numbers::pi / 180.0;
  const uint64_t s = hash_of(seed, 0xb0a7d);
  const auto signed_uniform = [&](int frame, int channel) { return 2.0 * uniform(s, frame, channel) - 1.0; };
  // Printed side towards +z (the cameras): board x -> world x, board y -> world -y.
  const Eigen::Matrix3d facing_cameras = Eigen::Vector3d(1, -1, -1).asDiagonal();
  const Eigen::Vector3d board_centre(b.squares_x * b.square_m / 2, b.squares_y * b.square_m / 2, 0);
  std::vector<RigidTransform> out;
  for (int f = 0; f < frames; ++f) {
    // As docs/calibration.md asks of a studio's take: tilted up to 45 degrees, and
    // wandering far enough to reach into the image corners of the frontal cameras.
    const Eigen::Matrix3d tilt = (Eigen::AngleAxisd(45 * kDeg * signed_uniform(f, 0), Eigen::Vector3d::UnitY()) *
                                  Eigen::AngleAxisd(35 * kDeg * signed_uniform(f, 1), Eigen::Vector3d::UnitX()) *
                                  Eigen::AngleAxisd(30 * kDeg * signed_uniform(f, 2), Eigen::Vector3d::UnitZ()))
                                     .toRotationMatrix();
    const Eigen::Vector3d position(0.2 * signed_uniform(f, 3), 0.13 * signed_uniform(f, 4),
                                   0.05 + 0.15 * signed_uniform(f, 5));
    RigidTransform pose;
    pose.R = tilt * facing_cameras;
    pose.t = position - pose.R * board_centre;
    out.push_back(pose);
  }
  return out;
}

Mesh charuco_board_mesh(const CharucoBoardSpec& b, int cells_x, int cells_y, bool back) {
  const double m = b.margin_squares * b.square_m;
  const double width = b.squares_x * b.square_m + 2 * m, height = b.squares_y * b.square_m + 2 * m;
  Mesh mesh;
  mesh.positions.resize((cells_x + 1) * (cells_y + 1), 3);
  mesh.uvs.resize((cells_x + 1) * (cells_y + 1), 2);
  for (int j = 0; j <= cells_y; ++j) {
    for (int i = 0; i <= cells_x; ++i) {
      const int v = j * (cells_x + 1) + i;
      const double fx = double(i) / cells_x, fy = double(j) / cells_y;
      mesh.positions.row(v) = Eigen::RowVector3f(float(-m + fx * width), float(-m + fy * height), 0.0f);
      mesh.uvs.row(v) = Eigen::RowVector2f(float(fx), float(1.0 - fy));  // v = 0 at the texture's bottom
    }
  }
  mesh.faces.resize(2 * cells_x * cells_y, 3);
  int f = 0;
  for (int j = 0; j < cells_y; ++j) {
    for (int i = 0; i < cells_x; ++i) {
      const int tl = j * (cells_x + 1) + i, tr = tl + 1, bl = tl + cells_x + 1, br = bl + 1;
      // Seen from the front, board x runs right and y down: TL, BL, BR is counter-clockwise.
      if (!back) {
        mesh.faces.row(f++) << tl, bl, br;
        mesh.faces.row(f++) << tl, br, tr;
      } else {
        mesh.faces.row(f++) << tl, br, bl;
        mesh.faces.row(f++) << tl, tr, br;
      }
    }
  }
  mesh.uv_faces = mesh.faces;
  return mesh;
}

}  // namespace tega::synth
