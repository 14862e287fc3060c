#include "tega/mvs/colmap_workspace.h"

#include <gtest/gtest.h>

#include <cstring>
#include <fstream>

#include "sphere_scene.h"
#include "tega/core/error.h"
#include "test_support.h"

namespace tega::mvs {
namespace {

namespace fs = std::filesystem;
using test::kRadius;

using tega::test::error_message;

#define EXPECT_CONTAINS(text, part) \
  EXPECT_NE(std::string(text).find(part), std::string::npos) << "'" << (text) << "' lacks '" << (part) << "'"

std::string read_bytes(const fs::path& file) {
  std::ifstream in(file, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

void write_bytes(const fs::path& file, const std::string& bytes) {
  fs::create_directories(file.parent_path());
  std::ofstream(file, std::ios::binary) << bytes;
}

template <class T>
std::string bytes_of(const std::vector<T>& values) {
  return std::string(reinterpret_cast<const char*>(values.data()), values.size() * sizeof(T));
}

// Three views of the sphere with exact depth, normals and images, their
// source views, and a fused cloud with colours.
DenseWorkspace sphere_workspace() {
  DenseWorkspace workspace;
  workspace.rig = test::cap_rig(2, 20, 0.5, 40, 30, 70);
  for (const Camera& camera : workspace.rig.cameras) {
    workspace.images[camera.name] = test::sphere_image(camera, kRadius);
    workspace.depth_maps[camera.name] = test::sphere_depth_map(camera, kRadius);
  }
  workspace.source_views = {{"cam00", {"cam01", "cam02"}}, {"cam02", {"cam00"}}};
  OrientedPointCloud fused = test::sphere_cloud(100, kRadius);
  fused.colors.resize(fused.size(), 3);
  for (int i = 0; i < fused.size(); ++i) fused.colors.row(i) << uint8_t(i), uint8_t(2 * i), uint8_t(255 - i);
  workspace.fused = fused;
  return workspace;
}

TEST(ColmapArray, WritesColmapsHeaderThenChannelAfterChannel) {
  tega::test::TempDir dir;
  // 2 x 1 pixels, 2 channels, interleaved: (a0 b0) (a1 b1).
  write_colmap_array(dir / "a.bin", 2, 1, 2, {1.0f, 10.0f, 2.0f, 20.0f});
  EXPECT_EQ(read_bytes(dir / "a.bin"), "2&1&2&" + bytes_of(std::vector<float>{1.0f, 2.0f, 10.0f, 20.0f}));
  int width, height, channels;
  EXPECT_EQ(read_colmap_array(dir / "a.bin", width, height, channels), (std::vector<float>{1, 10, 2, 20}));
  EXPECT_EQ(width, 2);
  EXPECT_EQ(height, 1);
  EXPECT_EQ(channels, 2);
  EXPECT_CONTAINS(error_message([&] {
                    write_colmap_array(dir / "b.bin", 2, 2, 1, {1, 2, 3});
                  }),
                  (dir / "b.bin").string() + ": size mismatch");
  EXPECT_FALSE(fs::exists(dir / "b.bin"));
}

TEST(ColmapArray, BadFilesNameTheFileAndTheProblem) {
  tega::test::TempDir dir;
  int width, height, channels;
  const auto read = [&](const std::string& bytes) {
    write_bytes(dir / "x.bin", bytes);
    return error_message([&] { read_colmap_array(dir / "x.bin", width, height, channels); });
  };
  const std::string file = (dir / "x.bin").string() + ": ";
  EXPECT_CONTAINS(read("2&x&1&"), file + "bad header");
  EXPECT_CONTAINS(read("2&1&"), file + "bad header");
  EXPECT_CONTAINS(read("0&1&1&"), file + "bad header");
  EXPECT_CONTAINS(read("2&2&1&" + bytes_of(std::vector<float>{1, 2, 3})), file + "truncated data");
  EXPECT_CONTAINS(read("999999&999999&99&" + bytes_of(std::vector<float>{1})), file + "truncated data");
  EXPECT_CONTAINS(read("1&1&1&" + bytes_of(std::vector<float>{1, 2})), file + "size mismatch");
  EXPECT_CONTAINS(error_message([&] { read_colmap_array(dir / "missing.bin", width, height, channels); }),
                  (dir / "missing.bin").string());
}

TEST(PointCloudPly, WritesColmapsLayoutAndReadsItBack) {
  tega::test::TempDir dir;
  const OrientedPointCloud cloud = *sphere_workspace().fused;
  write_point_cloud_ply(cloud, dir / "fused.ply");
  const std::string bytes = read_bytes(dir / "fused.ply");
  const std::string header =
      "ply\nformat binary_little_endian 1.0\nelement vertex 100\n"
      "property float x\nproperty float y\nproperty float z\n"
      "property float nx\nproperty float ny\nproperty float nz\n"
      "property uchar red\nproperty uchar green\nproperty uchar blue\nend_header\n";
  ASSERT_EQ(bytes.substr(0, header.size()), header);
  ASSERT_EQ(bytes.size(), header.size() + 100 * 27);
  float first_y;
  std::memcpy(&first_y, bytes.data() + header.size() + 4, 4);
  EXPECT_EQ(first_y, cloud.points(0, 1));
  EXPECT_EQ(uint8_t(bytes[header.size() + 27 + 25]), 2);  // the second point's green

  const OrientedPointCloud back = read_point_cloud_ply(dir / "fused.ply");
  EXPECT_EQ(back.points, cloud.points);
  EXPECT_EQ(back.normals, cloud.normals);
  EXPECT_EQ(back.colors, cloud.colors);
}

TEST(PointCloudPly, BadFilesNameTheFileAndTheProblem) {
  tega::test::TempDir dir;
  const OrientedPointCloud cloud = *sphere_workspace().fused;
  write_point_cloud_ply(cloud, dir / "fused.ply");
  const std::string bytes = read_bytes(dir / "fused.ply");
  const std::string file = (dir / "x.ply").string() + ": ";
  const auto read = [&](const std::string& content) {
    write_bytes(dir / "x.ply", content);
    return error_message([&] { read_point_cloud_ply(dir / "x.ply"); });
  };
  EXPECT_CONTAINS(read(bytes.substr(0, bytes.size() - 5)), file + "truncated data");
  EXPECT_CONTAINS(read("not a ply"), file + "bad header");
  std::string ascii = bytes;
  ascii.replace(ascii.find("binary_little_endian"), 20, "ascii");
  EXPECT_CONTAINS(read(ascii), file + "bad header: format 'ascii'");
  std::string no_x = bytes;
  no_x.replace(no_x.find("float x\n"), 8, "float w\n");
  EXPECT_CONTAINS(read(no_x), file + "bad header: no float or double vertex property 'x'");
}

TEST(DenseWorkspace, RoundTripKeepsEverything) {
  tega::test::TempDir dir;
  const DenseWorkspace workspace = sphere_workspace();
  write_dense_workspace(workspace, dir / "ws");

  for (const char* file :
       {"images/cam00.png", "sparse/cameras.txt", "sparse/images.txt", "sparse/points3D.txt",
        "stereo/depth_maps/cam01.png.geometric.bin", "stereo/normal_maps/cam01.png.geometric.bin", "fused.ply"})
    EXPECT_TRUE(fs::exists(dir / "ws" / file)) << file;
  EXPECT_EQ(read_bytes(dir / "ws/stereo/patch-match.cfg"), "cam00.png\ncam01.png, cam02.png\ncam02.png\ncam00.png\n");
  EXPECT_EQ(read_bytes(dir / "ws/stereo/fusion.cfg"), "cam00.png\ncam01.png\ncam02.png\n");

  const DenseWorkspace back = read_dense_workspace(dir / "ws");
  EXPECT_EQ(back.rig.camera_names(), workspace.rig.camera_names());
  for (const Camera& camera : workspace.rig.cameras) {
    SCOPED_TRACE(camera.name);
    const Camera& read = back.rig.camera(camera.name);
    EXPECT_LT((read.K - camera.K).cwiseAbs().maxCoeff(), 1e-12);
    EXPECT_LT((read.world_to_camera.R - camera.world_to_camera.R).cwiseAbs().maxCoeff(), 1e-12);
    EXPECT_LT((read.world_to_camera.t - camera.world_to_camera.t).cwiseAbs().maxCoeff(), 1e-12);
    EXPECT_EQ(back.images.at(camera.name).pixels, workspace.images.at(camera.name).pixels);
    const DepthMap& expected = workspace.depth_maps.at(camera.name);
    const DepthMap& map = back.depth_maps.at(camera.name);
    EXPECT_EQ(map.width, expected.width);
    EXPECT_EQ(map.depth, expected.depth);
    EXPECT_EQ(map.normals, expected.normals);
    EXPECT_GT(map.valid_pixels(), 100);
  }
  EXPECT_EQ(back.source_views, workspace.source_views);
  ASSERT_TRUE(back.fused);
  EXPECT_EQ(back.fused->points, workspace.fused->points);
  EXPECT_EQ(back.fused->colors, workspace.fused->colors);

  // The photometric maps go beside the geometric ones; views without maps are left out.
  DenseWorkspace partial = workspace;
  partial.depth_maps.erase("cam02");
  write_dense_workspace(partial, dir / "ws", "photometric");
  EXPECT_EQ(read_dense_workspace(dir / "ws", "photometric").depth_maps.size(), 2u);
}

TEST(DenseWorkspace, SparsePointsTieTheViewsThatSeeThemConsistently) {
  tega::test::TempDir dir;
  write_dense_workspace(sphere_workspace(), dir / "ws");
  std::ifstream in(dir / "ws/sparse/points3D.txt");
  int points = 0, observations = 0;
  for (std::string line; std::getline(in, line);) {
    if (line.empty() || line[0] == '#') continue;
    std::istringstream words(line);
    long id;
    double x, y, z;
    words >> id >> x >> y >> z;
    EXPECT_NEAR(Eigen::Vector3d(x, y, z).norm(), kRadius, 1e-6);
    int track = 0;
    for (std::string word; words >> word;) ++track;
    observations += (track - 4) / 2;  // after R G B ERROR, (IMAGE_ID, POINT2D_IDX) pairs
    ++points;
  }
  EXPECT_GT(points, 50);
  EXPECT_GT(observations, 2 * points);
}

TEST(DenseWorkspace, ReadsColmapsFilesWrittenByHand) {
  tega::test::TempDir dir;
  const fs::path ws = dir / "ws";
  for (const char* folder : {"sparse", "images", "stereo"}) fs::create_directories(ws / folder);
  tega::test::write_text(ws / "sparse/cameras.txt", "1 PINHOLE 3 2 100 100 1.5 1\n");
  tega::test::write_text(ws / "sparse/images.txt", "1 1 0 0 0 0 0 0 1 left.png\n\n2 1 0 0 0 0.1 0 0 1 right.png\n\n");
  tega::test::write_text(ws / "sparse/points3D.txt", "");
  for (const char* name : {"left.png", "right.png"}) write_image(Image8(3, 2, 1, 77), ws / "images" / name);
  // Planar: row 0 then row 1; -1 is COLMAP's "no estimate".
  write_bytes(ws / "stereo/depth_maps/left.png.geometric.bin",
              "3&2&1&" + bytes_of(std::vector<float>{1, 2, 3, 4, 5, -1}));
  std::vector<float> normals_planar(18);
  for (int i = 0; i < 6; ++i) normals_planar[size_t(i)] = 0.1f * float(i), normals_planar[size_t(12 + i)] = -1;
  write_bytes(ws / "stereo/normal_maps/left.png.geometric.bin", "3&2&3&" + bytes_of(normals_planar));
  tega::test::write_text(ws / "stereo/patch-match.cfg", "left.png\nright.png\nright.png\n__auto__, 20\n");

  const DenseWorkspace workspace = read_dense_workspace(ws);
  EXPECT_EQ(workspace.rig.camera_names(), (std::vector<std::string>{"left", "right"}));
  EXPECT_EQ(workspace.images.at("right").channels, 3);
  EXPECT_EQ(workspace.images.at("right").at(2, 1, 2), 77);
  ASSERT_EQ(workspace.depth_maps.size(), 1u);
  const DepthMap& map = workspace.depth_maps.at("left");
  EXPECT_EQ(map.depth, (std::vector<float>{1, 2, 3, 4, 5, 0}));
  EXPECT_EQ(map.normals[3 * map.index(1, 1) + 0], 0.4f);
  EXPECT_EQ(map.normals[3 * map.index(1, 1) + 2], -1.0f);
  EXPECT_EQ(map.normals[3 * map.index(2, 1) + 2], 0.0f);  // no estimate, no normal
  EXPECT_EQ(workspace.source_views, (std::map<std::string, std::vector<std::string>>{{"left", {"right"}}}));
  EXPECT_FALSE(workspace.fused);

  fs::remove(ws / "stereo/normal_maps/left.png.geometric.bin");
  EXPECT_CONTAINS(error_message([&] { read_dense_workspace(ws); }),
                  (ws / "stereo/normal_maps/left.png.geometric.bin").string() + ": missing");
  write_bytes(ws / "stereo/normal_maps/left.png.geometric.bin", "3&2&3&" + bytes_of(std::vector<float>(17)));
  EXPECT_CONTAINS(error_message([&] { read_dense_workspace(ws); }),
                  (ws / "stereo/normal_maps/left.png.geometric.bin").string() + ": truncated data");
  write_bytes(ws / "stereo/normal_maps/left.png.geometric.bin", "3&2&3&" + bytes_of(normals_planar));
  fs::remove(ws / "images/right.png");
  EXPECT_CONTAINS(error_message([&] { read_dense_workspace(ws); }), "no image of camera 'right'");
}

TEST(DenseWorkspace, RefusesWhatItCannotWrite) {
  tega::test::TempDir dir;
  DenseWorkspace workspace = sphere_workspace();
  workspace.source_views["cam01"] = {"cam09"};
  EXPECT_CONTAINS(error_message([&] { write_dense_workspace(workspace, dir / "ws"); }),
                  "source view 'cam09' of camera 'cam01' is not in the rig");
  workspace = sphere_workspace();
  workspace.rig.cameras[1].distortion[0] = 0.1;
  EXPECT_CONTAINS(error_message([&] { write_dense_workspace(workspace, dir / "ws"); }), "camera 'cam01' has distortion");
  workspace = sphere_workspace();
  workspace.depth_maps["cam00"].normals.pop_back();
  EXPECT_CONTAINS(error_message([&] { write_dense_workspace(workspace, dir / "ws"); }), "the depth map of camera 'cam00'");
  EXPECT_CONTAINS(error_message([&] { write_dense_workspace(sphere_workspace(), dir / "ws", "raw"); }),
                  "depth map type 'raw'");
  EXPECT_FALSE(fs::exists(dir / "ws"));
}

}  // namespace
}  // namespace tega::mvs
