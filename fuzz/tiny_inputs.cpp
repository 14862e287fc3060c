#include "tiny_inputs.h"

#include <Eigen/Geometry>
#include <cmath>

namespace tega::fuzz {

Rig tiny_rig(int count, bool distorted) {
  Rig rig;
  for (int i = 0; i < count; ++i) {
    Camera camera;
    camera.name = "cam" + std::string(i < 10 ? "0" : "") + std::to_string(i);
    camera.width = 64;
    camera.height = 48;
    camera.K << 80, 0, 31.5, 0, 80.5, 23.5, 0, 0, 1;
    if (distorted) camera.distortion = {-0.05, 0.08, 0.0004, -0.0003, 0.001 * i};
    const double angle = 0.3 * i;
    camera.world_to_camera.R = Eigen::AngleAxisd(angle, Eigen::Vector3d::UnitY()).toRotationMatrix();
    camera.world_to_camera.t = {0, 0, 1};
    rig.cameras.push_back(camera);
  }
  return rig;
}

Mesh tiny_mesh() {
  Mesh mesh;
  mesh.positions.resize(5, 3);
  mesh.positions << 0, 0, 0, 1, 0, 0, 1, 1, 0, 0, 1, 0, 2, 0.5f, 0.1f;
  mesh.faces.resize(3, 3);
  mesh.faces << 0, 1, 2, 0, 2, 3, 1, 4, 2;
  mesh.uvs.resize(6, 2);
  mesh.uvs << 0, 0, 0.5f, 0, 0.5f, 1, 0, 1, 0.6f, 0, 0.6f, 1;
  mesh.uv_faces.resize(3, 3);
  mesh.uv_faces << 0, 1, 2, 0, 2, 3, 4, 5, 5;
  mesh.triangle_polygon = {0, 0, 1};
  return mesh;
}

}  // namespace tega::fuzz
