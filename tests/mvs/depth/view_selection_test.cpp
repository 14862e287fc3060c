#include <gtest/gtest.h>

#include "tega/mvs/view_selection.h"
#include "tega/synth/studio_rig.h"

namespace tega::mvs {
namespace {

std::vector<Camera> studio_cameras() { return synth::make_studio_rig(synth::StudioOptions{}).cameras; }

TEST(ViewSelection, TheStudioRigAimsAtTheHead) {
  const auto cameras = studio_cameras();
  const auto focus = rig_focus_point(cameras);
  ASSERT_TRUE(focus);
  for (const auto& c : cameras) {
    const Eigen::Vector3d p = c.world_to_camera.apply(*focus);
    EXPECT_NEAR(p.z(), 1.0, 0.05) << c.name;  // the studio's cameras stand 1 m from the head
    EXPECT_LT(p.head<2>().norm() / p.z(), 0.05) << c.name;
  }
}

TEST(ViewSelection, SourcesAreOtherCamerasAtUsefulAngles) {
  const auto cameras = studio_cameras();
  const Eigen::Vector3d focus = *rig_focus_point(cameras);
  const auto sources = select_source_views(cameras, focus, 5);
  for (size_t r = 0; r < cameras.size(); ++r) {
    ASSERT_EQ(sources[r].size(), 5u) << cameras[r].name;
    for (int s : sources[r]) {
      EXPECT_NE(s, int(r));
      const double angle = std::acos((cameras[r].center() - focus).normalized().dot((cameras[s].center() - focus).normalized()));
      EXPECT_GT(angle, 2 * M_PI / 180);
      EXPECT_LT(angle, 60 * M_PI / 180);
    }
  }
}

TEST(ViewSelection, ParallelCamerasHaveNoFocusPoint) {
  auto cameras = studio_cameras();
  cameras.resize(2);
  cameras[1].world_to_camera.R = cameras[0].world_to_camera.R;
  cameras[1].world_to_camera.t = cameras[0].world_to_camera.t + Eigen::Vector3d(0.1, 0, 0);
  EXPECT_FALSE(rig_focus_point(cameras));
  const auto sources = select_source_views_by_axes(cameras, 3);
  EXPECT_EQ(sources[0], std::vector<int>{1});
}

}  // namespace
}  // namespace tega::mvs
