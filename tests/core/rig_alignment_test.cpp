#include <gtest/gtest.h>

#include <random>

#include "tega/core/error.h"
#include "tega/core/rig.h"

namespace tega {
namespace {

// Cameras on an arc a metre from the origin, looking at it.
Rig arc_rig(int cameras) {
  Rig rig;
  for (int i = 0; i < cameras; ++i) {
    const double angle = -0.8 + 1.6 * i / std::max(1, cameras - 1);
    Camera c;
    c.name = "cam" + std::to_string(i);
    c.width = 640, c.height = 480;
    c.K << 800, 0, 320, 0, 800, 240, 0, 0, 1;
    const Eigen::Vector3d centre(std::sin(angle), 0.2 * (i % 2), std::cos(angle));
    c.world_to_camera.R = Eigen::AngleAxisd(M_PI - angle, Eigen::Vector3d::UnitY()).toRotationMatrix();
    c.world_to_camera.t = -c.world_to_camera.R * centre;
    rig.cameras.push_back(c);
  }
  return rig;
}

// The same rig seen from another world: every camera's world moved by `motion`.
Rig moved(Rig rig, const RigidTransform& motion) {
  for (Camera& c : rig.cameras) c.world_to_camera = c.world_to_camera * motion.inverse();
  return rig;
}

TEST(RigAlignment, RecoversTheMotionBetweenTwoWorlds) {
  const Rig truth = arc_rig(13);
  RigidTransform motion;
  motion.R = Eigen::AngleAxisd(0.7, Eigen::Vector3d(0.3, -1, 0.2).normalized()).toRotationMatrix();
  motion.t = Eigen::Vector3d(0.4, -1.2, 2.5);
  const RigidTransform found = align_camera_centres(moved(truth, motion), truth);
  EXPECT_LT((found.R - motion.R.transpose()).norm(), 1e-12);
  EXPECT_LT((found.t - motion.inverse().t).norm(), 1e-12);
}

TEST(RigAlignment, SpreadsOneCameraErrorOverTheRigInsteadOfTyingTheWorldToIt) {
  const Rig truth = arc_rig(13);
  Rig off = truth;
  // The first camera turned by half a degree: tying the worlds by it would
  // swing every other camera by as much, a metre away 9 mm.
  off.cameras[0].world_to_camera.R =
      Eigen::AngleAxisd(0.5 * M_PI / 180, Eigen::Vector3d::UnitX()).toRotationMatrix() * off.cameras[0].world_to_camera.R;
  off.cameras[0].world_to_camera.t = -off.cameras[0].world_to_camera.R * truth.cameras[0].center();
  const RigidTransform tie = truth.cameras[0].world_to_camera.inverse() * off.cameras[0].world_to_camera;
  EXPECT_GT((tie.apply(off.cameras[12].center()) - truth.cameras[12].center()).norm(), 0.005);
  const RigidTransform found = align_camera_centres(off, truth);
  for (const Camera& c : truth.cameras)
    EXPECT_LT((found.apply(off.camera(c.name).center()) - c.center()).norm(), 1e-12) << c.name;
}

TEST(RigAlignment, NamesWhatItLacks) {
  const Rig truth = arc_rig(13);
  Rig two;
  two.cameras = {truth.cameras[0], truth.cameras[5]};
  EXPECT_THROW(align_camera_centres(two, truth), Error);
  Rig line = arc_rig(3);
  for (int i = 0; i < 3; ++i) line.cameras[size_t(i)].world_to_camera.t = -line.cameras[size_t(i)].world_to_camera.R * Eigen::Vector3d(0.1 * i, 0, 1);
  try {
    align_camera_centres(line, line);
    FAIL() << "collinear centres were aligned";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("line"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace tega
