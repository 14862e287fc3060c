#include "tega/core/silhouette.h"

#include <algorithm>
#include <cmath>
#include <vector>

namespace tega {

Image8 mesh_silhouette(const Camera& camera, const Vertices& world, const Triangles& faces, Facing facing) {
  Image8 mask(camera.width, camera.height, 1, 0);
  std::vector<Eigen::Vector2d> pixel(world.rows());
  std::vector<bool> in_front(world.rows());
  const bool distorted = camera.has_distortion();
  const Eigen::Vector3d centre = camera.center();
  for (Eigen::Index i = 0; i < world.rows(); ++i) {
    const Eigen::Vector3d c = camera.world_to_camera.apply(world.row(i).transpose().cast<double>());
    in_front[i] = c.z() > 0;
    if (!in_front[i]) continue;
    const Eigen::Vector2d normalised = c.head<2>() / c.z();
    const Eigen::Vector2d lens = distorted ? camera.distort(normalised) : normalised;
    pixel[i] = (camera.K * lens.homogeneous()).head<2>();
  }
  for (Eigen::Index f = 0; f < faces.rows(); ++f) {
    const int a = faces(f, 0), b = faces(f, 1), c = faces(f, 2);
    if (!in_front[a] || !in_front[b] || !in_front[c]) continue;
    if (facing == Facing::toward_camera) {
      const Eigen::Vector3d wa = world.row(a).transpose().cast<double>();
      const Eigen::Vector3d outward = (world.row(b).transpose().cast<double>() - wa)
                                          .cross(world.row(c).transpose().cast<double>() - wa);
      if (outward.dot(centre - wa) <= 0) continue;
    }
    const Eigen::Vector2d &pa = pixel[a], &pb = pixel[b], &pc = pixel[c];
    const double area = (pb - pa).x() * (pc - pa).y() - (pb - pa).y() * (pc - pa).x();
    if (area == 0) continue;
    const int x0 = std::max(0, static_cast<int>(std::ceil(std::min({pa.x(), pb.x(), pc.x()}))));
    const int x1 = std::min(camera.width - 1, static_cast<int>(std::floor(std::max({pa.x(), pb.x(), pc.x()}))));
    const int y0 = std::max(0, static_cast<int>(std::ceil(std::min({pa.y(), pb.y(), pc.y()}))));
    const int y1 = std::min(camera.height - 1, static_cast<int>(std::floor(std::max({pa.y(), pb.y(), pc.y()}))));
    // Either winding: a pixel centre is inside when all three edge functions
    // have the sign of the area.
    const auto edge = [](const Eigen::Vector2d& p, const Eigen::Vector2d& q, double x, double y) {
      return (q.x() - p.x()) * (y - p.y()) - (q.y() - p.y()) * (x - p.x());
    };
    for (int y = y0; y <= y1; ++y) {
      for (int x = x0; x <= x1; ++x) {
        const double e0 = edge(pa, pb, x, y) * area, e1 = edge(pb, pc, x, y) * area, e2 = edge(pc, pa, x, y) * area;
        if (e0 >= 0 && e1 >= 0 && e2 >= 0) mask.at(x, y, 0) = 255;
      }
    }
  }
  return mask;
}

}  // namespace tega
