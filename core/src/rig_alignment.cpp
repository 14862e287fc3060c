#include <Eigen/Geometry>
#include <Eigen/SVD>

#include "tega/core/error.h"
#include "tega/core/rig.h"

namespace tega {

RigidTransform align_camera_centres(const Rig& from, const Rig& to) {
  std::vector<Eigen::Vector3d> source, target;
  for (const Camera& camera : from.cameras)
    if (to.contains(camera.name)) {
      source.push_back(camera.center());
      target.push_back(to.camera(camera.name).center());
    }
  if (source.size() < 3)
    throw Error("aligning two rigs needs 3 cameras in both; they share " + std::to_string(source.size()));
  Eigen::Matrix3Xd a(3, source.size()), b(3, target.size());
  for (size_t i = 0; i < source.size(); ++i) a.col(Eigen::Index(i)) = source[i], b.col(Eigen::Index(i)) = target[i];
  const Eigen::Vector3d mean = a.rowwise().mean();
  const Eigen::JacobiSVD<Eigen::Matrix3Xd> spread(a.colwise() - mean);
  if (spread.singularValues()(1) < 1e-6 * std::max(1.0, spread.singularValues()(0)))
    throw Error("aligning two rigs needs camera centres that span a plane; the shared ones lie on a line");
  const Eigen::Matrix4d m = Eigen::umeyama(a, b, false);
  RigidTransform out;
  out.R = m.topLeftCorner<3, 3>();
  out.t = m.topRightCorner<3, 1>();
  return out;
}

}  // namespace tega
