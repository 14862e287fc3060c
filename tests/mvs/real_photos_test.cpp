// Real photographs: the Middlebury "Aloe" stereo pair with its ground-truth
// disparity, as opencv-doc ships it (skips where it is absent). A rectified
// pair is a two-camera rig whose right camera sits a baseline B to the right;
// any focal length f and B give depth f B / disparity, so the estimate is
// scored in disparity, where the truth is.
#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>

#include "tega/core/image.h"
#include "tega/core/take_images.h"
#include "tega/core/thread_pool.h"
#include "tega/mvs/frame_views.h"
#include "tega/mvs/fusion.h"
#include "tega/mvs/patch_match.h"
#include "tega/mvs/surface.h"

namespace fs = std::filesystem;

namespace tega::mvs {
namespace {

const fs::path kData = "/usr/share/doc/opencv-doc/examples/data";
constexpr double kFocal = 500, kBaseline = 0.1;

// Half size by 2 x 2 means: the test runs in seconds.
template <class T>
ImageBuffer<T> half_size(const ImageBuffer<T>& image) {
  ImageBuffer<T> half(image.width / 2, image.height / 2, image.channels);
  for (int y = 0; y < half.height; ++y)
    for (int x = 0; x < half.width; ++x)
      for (int c = 0; c < image.channels; ++c)
        half.at(x, y, c) = T((image.at(2 * x, 2 * y, c) + image.at(2 * x + 1, 2 * y, c) + image.at(2 * x, 2 * y + 1, c) +
                              image.at(2 * x + 1, 2 * y + 1, c) + 2) / 4);
  return half;
}

StereoView view(const std::string& name, const Image8& rgb, double x) {
  StereoView v;
  v.camera.name = name;
  v.camera.width = rgb.width;
  v.camera.height = rgb.height;
  v.camera.K << kFocal, 0, (rgb.width - 1) / 2.0, 0, kFocal, (rgb.height - 1) / 2.0, 0, 0, 1;
  v.camera.world_to_camera.t = Eigen::Vector3d(-x, 0, 0);
  v.colour = rgb;
  v.grey = grey_of(rgb);
  return v;
}

TEST(RealPhotos, AloeDisparityMatchesMiddleburyTruth) {
  if (!fs::exists(kData / "aloeL.jpg") || !image_format_supported(kData / "aloeL.jpg"))
    GTEST_SKIP() << "opencv-doc's aloeL.jpg/aloeR.jpg/aloeGT.png are absent or JPEG is not readable in this build";
  std::vector<StereoView> views = {view("left", half_size(read_image_u8(kData / "aloeL.jpg")), 0),
                                   view("right", half_size(read_image_u8(kData / "aloeR.jpg")), kBaseline)};
  // The truth holds full-size disparities in pixels (0: unknown); at half size they halve.
  const Image8 truth = read_image_u8(kData / "aloeGT.png");
  ASSERT_EQ(truth.width / 2, views[0].camera.width);

  const float disparity_min = 5, disparity_max = 160;
  const float depth_min = float(kFocal * kBaseline / disparity_max), depth_max = float(kFocal * kBaseline / disparity_min);
  const std::vector<ViewTask> tasks = {{0, {1}, depth_min, depth_max}, {1, {0}, depth_min, depth_max}};
  PatchMatchOptions options;
  options.top_k = 1;
  options.iterations = 4;
  options.geometric_iterations = 1;
  ThreadPool pool(0);
  const auto maps = estimate_depth_maps(views, tasks, options, Device::cpu, &pool);

  int64_t known = 0, estimated = 0, good = 0;
  for (int y = 0; y < views[0].camera.height; ++y)
    for (int x = 0; x < views[0].camera.width; ++x) {
      const int t = truth.at(2 * x, 2 * y, 0);
      if (t == 0 || x * 2 < t) continue;  // unknown, or seen by the left camera alone
      ++known;
      const float depth = maps[0].depth[maps[0].index(x, y)];
      if (depth <= 0) continue;
      ++estimated;
      good += std::abs(kFocal * kBaseline / depth - 0.5 * t) <= 1.0;
    }
  const double good_share = double(good) / double(estimated), coverage = double(estimated) / double(known);
  std::printf("aloe at half size: %.1f %% of the estimates within 1 px of the truth, %.1f %% of the known pixels estimated\n",
              100 * good_share, 100 * coverage);
  EXPECT_GT(good_share, 0.9);
  EXPECT_GT(coverage, 0.7);

  // Two views confirm each other; the surface through them lies where the truth says.
  FusionOptions fusion;
  fusion.min_consistent_views = 1;
  fusion.voxel_size_m = 0;
  const OrientedPointCloud cloud = fuse_depth_maps(views, {0, 1}, maps, fusion, &pool);
  ASSERT_GT(cloud.size(), 10000);
  SurfaceOptions surface;
  surface.trim_distance_m = 0.005;
  surface.threads = 1;  // OpenMP's spinning threads stall beside other tests
  const Mesh mesh = reconstruct_surface(cloud, surface);
  ASSERT_GT(mesh.num_faces(), 1000);
  std::vector<double> errors;
  for (int v = 0; v < mesh.num_vertices(); ++v) {
    const Eigen::Vector3d p = mesh.positions.row(v).cast<double>();
    const auto pixel = views[0].camera.project(p);
    if (!pixel) continue;
    const int x = int(std::lround(pixel->x())), y = int(std::lround(pixel->y()));
    if (x < 0 || y < 0 || x >= views[0].camera.width || y >= views[0].camera.height) continue;
    const int t = truth.at(2 * x, 2 * y, 0);
    if (t == 0) continue;
    errors.push_back(std::abs(kFocal * kBaseline / p.z() - 0.5 * t));
  }
  ASSERT_GT(errors.size(), 1000u);
  std::nth_element(errors.begin(), errors.begin() + errors.size() / 2, errors.end());
  EXPECT_LT(errors[errors.size() / 2], 1.0) << "median disparity error of the surface, pixels";
}

}  // namespace
}  // namespace tega::mvs
