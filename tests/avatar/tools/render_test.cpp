#include <ATen/ATen.h>
#include <gtest/gtest.h>

#include <cmath>
#include <nlohmann/json.hpp>

#include "tega/core/error.h"
#include "tega/core/files.h"
#include "tega/core/image.h"
#include "tega/tools/render_avatar.h"
#include "tega/tools/video.h"
#include "tiny_avatar.h"

namespace {

using namespace tega;
using namespace tega::tools;
namespace fs = std::filesystem;

Camera probe_camera() {
  Camera c;
  c.name = "probe";
  c.width = 8;
  c.height = 6;
  c.K << 10, 0.5, 4, 0, 12, 3, 0, 0, 1;
  c.world_to_camera.t = {0.1, -0.2, 1.5};
  return c;
}

TEST(Render, ResizedKeepsPixelCentresConsistent) {
  const Camera c = probe_camera();
  const Camera twice = resized(c, 16, 0);
  EXPECT_EQ(twice.width, 16);
  EXPECT_EQ(twice.height, 12);
  const Camera stretched = resized(c, 24, 12);  // x x3, y x2
  for (const Eigen::Vector3d& p : {Eigen::Vector3d(0.1, 0.2, 0.3), Eigen::Vector3d(-0.3, 0.1, -0.2)}) {
    const Eigen::Vector2d a = *c.project(p), b = *twice.project(p), s = *stretched.project(p);
    EXPECT_NEAR(b.x(), 2 * (a.x() + 0.5) - 0.5, 1e-9);
    EXPECT_NEAR(b.y(), 2 * (a.y() + 0.5) - 0.5, 1e-9);
    EXPECT_NEAR(s.x(), 3 * (a.x() + 0.5) - 0.5, 1e-9);
    EXPECT_NEAR(s.y(), 2 * (a.y() + 0.5) - 0.5, 1e-9);
  }
  EXPECT_EQ(resized(c, 0, 0).K, c.K);
  EXPECT_EQ(resized(c, 4096, 0).width, 4096);
  EXPECT_THROW(resized(c, 4104, 0), Error);  // 4104 x 3078 is beyond 4K
  EXPECT_THROW(resized(c, 0, 4097), Error);
}

TEST(Render, LookAtAndOrbit) {
  // OpenCV axes: a camera at -z looking at the origin with world up = -y is the identity.
  const RigidTransform t = look_at({0, 0, -1}, {0, 0, 0}, {0, -1, 0});
  EXPECT_TRUE(t.R.isApprox(Eigen::Matrix3d::Identity(), 1e-12));
  EXPECT_TRUE(t.t.isApprox(Eigen::Vector3d(0, 0, 1), 1e-12));

  std::vector<Camera> reference(2, probe_camera());
  // Level cameras (looking at their own height), so that their common up is exactly -y.
  reference[0].world_to_camera = look_at({0.4, 0.1, -2}, {0, 0.1, 0}, {0, -1, 0});
  reference[1].world_to_camera = look_at({-0.4, 0.1, -2}, {0, 0.1, 0}, {0, -1, 0});
  const Eigen::Vector3d centre(0.05, -0.02, 0.1);
  const auto orbit = orbit_cameras(reference, centre, 4, resized(probe_camera(), 32, 0));
  ASSERT_EQ(orbit.size(), 4u);
  EXPECT_EQ(orbit[0].name, "orbit000");
  EXPECT_EQ(orbit[3].name, "orbit003");
  const double distance = ((reference[0].center() - centre).norm() + (reference[1].center() - centre).norm()) / 2;
  for (const Camera& c : orbit) {
    EXPECT_EQ(c.width, 32);
    EXPECT_NEAR((c.center() - centre).norm(), distance, 1e-9);
    const Eigen::Vector2d pixel = *c.project(centre);  // the head centre is in the image centre
    EXPECT_NEAR(pixel.x(), c.K(0, 2), 1e-9);
    EXPECT_NEAR(pixel.y(), c.K(1, 2), 1e-9);
    EXPECT_NEAR((c.center() - centre).y(), (reference[0].center() - centre).y(), 1e-9);  // the references' height
  }
  // The first camera faces the head from the references' mean direction; the
  // next ones turn a quarter each about the up axis.
  const Eigen::Vector3d mean_direction = (reference[0].center() + reference[1].center()) / 2 - centre;
  EXPECT_GT((orbit[0].center() - centre).normalized().dot(mean_direction.normalized()), 0.999);
  const auto flat = [&](const Camera& c) { return Eigen::Vector3d((c.center() - centre).x(), 0, (c.center() - centre).z()); };
  EXPECT_NEAR(flat(orbit[0]).dot(flat(orbit[1])), 0.0, 1e-9);
  EXPECT_NEAR(flat(orbit[0]).dot(flat(orbit[2])), -flat(orbit[0]).squaredNorm(), 1e-9);
}

TEST(Render, WritesRendersSideBySideVideosAndAReport) {
  test::TinyAvatar tiny;
  RenderJob job;
  job.cameras.push_back({resized(tiny.dataset.rig.camera("cam00"), 16, 0), true});
  for (const Camera& c : orbit_cameras(tiny.dataset.rig.cameras, {0.33, 0.33, 0}, 2, resized(tiny.dataset.rig.cameras[0], 16, 0)))
    job.cameras.push_back({c, false});
  job.frames = dataset_frames(tiny.dataset, {"smile_000000", "blink_000000"});
  job.out = tiny.tmp / "renders";
  const RenderSummary summary = render_avatar(*tiny.avatar, tiny.dataset, job);
  EXPECT_EQ(summary.images, 6);
  EXPECT_EQ(summary.side_by_side, 2);  // cam00 only: the orbit has no ground truth

  const ImageF render = read_image(job.out / "cam00/smile_000000.png");
  EXPECT_EQ(render.width, 16);
  EXPECT_EQ(render.height, 12);
  EXPECT_TRUE(fs::exists(job.out / "orbit001/blink_000000.png"));
  EXPECT_FALSE(fs::exists(job.out / "side_by_side/orbit000"));
  const Image8 strip = read_image_u8(job.out / "side_by_side/cam00/blink_000000.png");
  ASSERT_EQ(strip.width, 32);
  ASSERT_EQ(strip.height, 12);
  const Image8 left = read_image_u8(job.out / "cam00/blink_000000.png");
  for (int y = 0; y < 12; ++y)
    for (int x = 0; x < 16; ++x)
      for (int c = 0; c < 3; ++c) {
        EXPECT_EQ(strip.at(x, y, c), left.at(x, y, c));
        // The right half is the dataset image (opaque, R = 10 * camera + frame = 1, G = B = 255).
        EXPECT_EQ(strip.at(16 + x, y, c), c == 0 ? 1 : 255);
      }

  const auto report = nlohmann::json::parse(read_text_file(job.out / "render.json"));
  EXPECT_EQ(report["images"], 6);
  EXPECT_EQ(report["cameras"].size(), 3u);
  EXPECT_EQ(report["frames"][1], "blink_000000");
  if (video_supported()) {
    EXPECT_EQ(summary.videos.size(), 3u);
    EXPECT_GT(fs::file_size(job.out / "cam00.mp4"), 0u);
    EXPECT_GT(fs::file_size(job.out / "orbit001.mp4"), 0u);
  } else {
    EXPECT_TRUE(summary.videos.empty());
    EXPECT_NE(report["video_note"].get<std::string>().find("OpenCV"), std::string::npos);
  }

  // An existing output is kept unless replacing is asked for.
  EXPECT_THROW(render_avatar(*tiny.avatar, tiny.dataset, job), Error);
  job.replace_existing = true;
  job.frames.pop_back();
  job.cameras.resize(1);
  const RenderSummary again = render_avatar(*tiny.avatar, tiny.dataset, job);
  EXPECT_EQ(again.images, 1);
  EXPECT_FALSE(fs::exists(job.out / "orbit000"));
  EXPECT_FALSE(again.video_note.empty());  // one image makes no video
}

TEST(Render, MeshSequencesInWorldOrHeadSpace) {
  test::TempDir tmp;
  fs::create_directories(tmp / "meshes");
  Vertices v(3, 3);
  v << 0, 0, 0, 1, 0, 0, 0, 1, 0;
  write_vertices_bin(v, tmp / "meshes/b.bin");
  Mesh m;
  m.positions = v * 2;
  m.faces.resize(1, 3);
  m.faces << 0, 1, 2;
  write_obj(m, tmp / "meshes/a.obj");
  test::write_text(tmp / "meshes/notes.txt", "ignored");
  RigidTransform pose;
  pose.R = Eigen::AngleAxisd(0.5, Eigen::Vector3d::UnitY()).toRotationMatrix();
  pose.t = {0.1, 0.2, 0.3};

  const auto world = mesh_sequence(tmp / "meshes", 3, pose, false);
  ASSERT_EQ(world.size(), 2u);
  EXPECT_EQ(world[0].id, "a");
  EXPECT_EQ(world[1].id, "b");
  EXPECT_FALSE(world[0].from_dataset);
  EXPECT_TRUE(world[1].world_vertices.isApprox(v));
  EXPECT_TRUE(world[1].head_to_world.R.isApprox(pose.R));

  const auto head = mesh_sequence(tmp / "meshes", 3, pose, true);
  const Eigen::Vector3d moved = pose.apply(Eigen::Vector3d(2, 0, 0));
  EXPECT_TRUE(head[0].world_vertices.row(1).transpose().cast<double>().isApprox(moved, 1e-6));

  EXPECT_THROW(mesh_sequence(tmp / "meshes", 4, pose, false), Error);  // wrong vertex count
  EXPECT_THROW(mesh_sequence(tmp / "nothing", 3, pose, false), Error);
}

}  // namespace
