// PatchMatch on a rendered studio frame against its true depth, the CPU path's
// determinism, bad input, and (on a machine with a GPU) the CUDA kernels
// against the CPU path.
#include <gtest/gtest.h>

#include "studio_frame.h"
#include "tega/core/error.h"
#include "tega/core/thread_pool.h"
#include "tega/mvs/patch_match.h"

namespace tega::mvs {
namespace {

using test::agreement;
using test::studio_frame;

PatchMatchOptions quick_options() {
  PatchMatchOptions o;
  o.iterations = 4;
  o.geometric_iterations = 1;
  return o;
}

const std::vector<DepthMap>& cpu_maps() {
  static const std::vector<DepthMap> maps = [] {
    ThreadPool pool(2);
    return estimate_depth_maps(studio_frame().views, studio_frame().tasks, quick_options(), Device::cpu, &pool);
  }();
  return maps;
}

TEST(PatchMatch, DepthMapsMatchTheRenderedHead) {
  const auto& frame = studio_frame();
  const auto& maps = cpu_maps();
  ASSERT_EQ(maps.size(), frame.views.size());
  // 320 x 240: a pixel is about 1.6 mm on the face; the outer cameras see it obliquely.
  double within = 0, coverage = 0;
  for (size_t k = 0; k < maps.size(); ++k) {
    const auto a = agreement(maps[k], frame.true_depth[k], 0.002);
    EXPECT_GT(a.within, 0.6) << frame.views[k].camera.name;
    EXPECT_GT(a.coverage, 0.5) << frame.views[k].camera.name;
    within += a.within / double(maps.size());
    coverage += a.coverage / double(maps.size());
  }
  EXPECT_GT(within, 0.78);
  EXPECT_GT(coverage, 0.65);
}

PatchMatchOptions coarse_to_fine_options() {
  PatchMatchOptions o = quick_options();
  o.pyramid_levels = 1;
  o.refine_iterations = 1;
  return o;
}

const std::vector<DepthMap>& cpu_coarse_to_fine_maps() {
  static const std::vector<DepthMap> maps = [] {
    ThreadPool pool(2);
    return estimate_depth_maps(studio_frame().views, studio_frame().tasks, coarse_to_fine_options(), Device::cpu,
                               &pool);
  }();
  return maps;
}

// Half size (160 x 120) first, then one geometric sweep at full size: close to
// the full-size estimate at a third of the sweeps' cost.
TEST(PatchMatch, CoarseToFineMatchesTheRenderedHead) {
  const auto& frame = studio_frame();
  const auto& maps = cpu_coarse_to_fine_maps();
  ASSERT_EQ(maps.size(), frame.views.size());
  double within = 0, coverage = 0;
  for (size_t k = 0; k < maps.size(); ++k) {
    ASSERT_EQ(maps[k].width, frame.views[k].camera.width);
    const auto a = agreement(maps[k], frame.true_depth[k], 0.002);
    within += a.within / double(maps.size());
    coverage += a.coverage / double(maps.size());
    for (size_t i = 0; i < maps[k].depth.size(); ++i)
      if (maps[k].depth[i] > 0) ASSERT_NE(frame.views[k].mask[i], 0);
  }
  EXPECT_GT(within, 0.74);  // 0.78 measured
  EXPECT_GT(coverage, 0.7);  // 0.77
}

// Radius 9, step 3 halves to radius 4, step 1: 9 samples a side, over the
// window's limit, so the coarse window is narrowed to 7.
TEST(PatchMatch, CoarseWindowStaysWithinItsLimit) {
  const auto& frame = studio_frame();
  PatchMatchOptions o = coarse_to_fine_options();
  o.window_radius = 9;
  o.window_step = 3;
  o.iterations = 1;
  o.geometric_passes = 0;
  ThreadPool pool(2);
  const auto maps = estimate_depth_maps(frame.views, {frame.tasks[0]}, o, Device::cpu, &pool);
  const auto a = agreement(maps[0], frame.true_depth[0], 0.002);
  // One sweep, no geometric pass: a rough estimate (0.48 within 2 mm, 12 % of the head measured).
  EXPECT_GT(a.within, 0.4);
  EXPECT_GT(a.coverage, 0.08);
}

TEST(PatchMatch, NormalsAreUnitAndFaceTheCamera) {
  const auto& maps = cpu_maps();
  const auto& view = studio_frame().views[0];
  const Eigen::Matrix3d K_inverse = view.camera.K.inverse();
  for (int y = 0; y < maps[0].height; y += 3)
    for (int x = 0; x < maps[0].width; x += 3) {
      const size_t i = maps[0].index(x, y);
      if (maps[0].depth[i] <= 0) continue;
      const Eigen::Vector3d n(maps[0].normals[3 * i], maps[0].normals[3 * i + 1], maps[0].normals[3 * i + 2]);
      EXPECT_NEAR(n.norm(), 1.0, 1e-4);
      EXPECT_LT(n.dot(K_inverse * Eigen::Vector3d(x, y, 1)), 0.0);
    }
}

TEST(PatchMatch, MasksAndCostLimitHold) {
  const auto& frame = studio_frame();
  const auto& maps = cpu_maps();
  for (size_t k = 0; k < maps.size(); ++k)
    for (size_t i = 0; i < maps[k].depth.size(); ++i) {
      if (maps[k].depth[i] <= 0) continue;
      ASSERT_NE(frame.views[k].mask[i], 0);
      ASSERT_LE(maps[k].cost[i], quick_options().max_cost);
    }
}

TEST(PatchMatch, SameResultForAnyThreadCount) {
  const auto& frame = studio_frame();
  const std::vector<ViewTask> one_task = {frame.tasks[0]};
  PatchMatchOptions o = quick_options();
  o.geometric_passes = 0;
  ThreadPool one(1), three(3);
  const auto a = estimate_depth_maps(frame.views, one_task, o, Device::cpu, &one);
  const auto b = estimate_depth_maps(frame.views, one_task, o, Device::cpu, &three);
  EXPECT_GT(a[0].valid_pixels(), 1000);
  EXPECT_EQ(a[0].depth, b[0].depth);
  EXPECT_EQ(a[0].normals, b[0].normals);
}

TEST(PatchMatch, BadInputIsNamed) {
  const auto& frame = studio_frame();
  ThreadPool pool(1);
  auto views = frame.views;
  views[1].grey.width -= 1;
  EXPECT_THROW(
      {
        try {
          estimate_depth_maps(views, frame.tasks, quick_options(), Device::cpu, &pool);
        } catch (const Error& e) {
          EXPECT_NE(std::string(e.what()).find(frame.views[1].camera.name), std::string::npos) << e.what();
          throw;
        }
      },
      Error);
  auto tasks = frame.tasks;
  tasks[0].depth_min = tasks[0].depth_max;
  EXPECT_THROW(estimate_depth_maps(frame.views, tasks, quick_options(), Device::cpu, &pool), Error);
  tasks = frame.tasks;
  tasks[1] = tasks[0];
  EXPECT_THROW(estimate_depth_maps(frame.views, tasks, quick_options(), Device::cpu, &pool), Error);
  tasks = frame.tasks;
  tasks[0].sources = {tasks[0].reference};
  EXPECT_THROW(estimate_depth_maps(frame.views, tasks, quick_options(), Device::cpu, &pool), Error);
  PatchMatchOptions wide = quick_options();
  wide.window_radius = 8;
  wide.window_step = 1;
  EXPECT_THROW(estimate_depth_maps(frame.views, frame.tasks, wide, Device::cpu, &pool), Error);
  EXPECT_THROW(parse_device("gpu"), Error);
}

// The kernels run the CPU path's per-pixel math; float rounding (fused
// multiply-adds, fast reciprocals) tips a few hypotheses, which then spread a
// little through propagation: a few per cent of the pixels differ, and the
// accuracy is the CPU path's.
TEST(PatchMatchCuda, MatchesTheCpuPath) {
  if (!cuda_device_available()) GTEST_SKIP() << "no CUDA device";
  const auto& frame = studio_frame();
  const auto gpu = estimate_depth_maps(frame.views, frame.tasks, quick_options(), Device::cuda);
  const auto& cpu = cpu_maps();
  for (size_t k = 0; k < cpu.size(); ++k) {
    int64_t both = 0, either = 0, close = 0;
    for (size_t i = 0; i < cpu[k].depth.size(); ++i) {
      const bool a = cpu[k].depth[i] > 0, b = gpu[k].depth[i] > 0;
      either += a || b;
      if (!(a && b)) continue;
      ++both;
      close += std::abs(cpu[k].depth[i] - gpu[k].depth[i]) < 1e-4f;
    }
    EXPECT_GT(double(both) / double(either), 0.95) << frame.views[k].camera.name;
    EXPECT_GT(double(close) / double(both), 0.93) << frame.views[k].camera.name;
    const auto a = agreement(gpu[k], frame.true_depth[k], 0.002), b = agreement(cpu[k], frame.true_depth[k], 0.002);
    EXPECT_NEAR(a.within, b.within, 0.03) << frame.views[k].camera.name;
    EXPECT_NEAR(a.coverage, b.coverage, 0.03) << frame.views[k].camera.name;
  }
}

TEST(PatchMatchCuda, CoarseToFineMatchesTheCpuPath) {
  if (!cuda_device_available()) GTEST_SKIP() << "no CUDA device";
  const auto& frame = studio_frame();
  const auto gpu = estimate_depth_maps(frame.views, frame.tasks, coarse_to_fine_options(), Device::cuda);
  const auto& cpu = cpu_coarse_to_fine_maps();
  for (size_t k = 0; k < cpu.size(); ++k) {
    const auto a = agreement(gpu[k], frame.true_depth[k], 0.002), b = agreement(cpu[k], frame.true_depth[k], 0.002);
    EXPECT_NEAR(a.within, b.within, 0.03) << frame.views[k].camera.name;
    EXPECT_NEAR(a.coverage, b.coverage, 0.03) << frame.views[k].camera.name;
  }
}

}  // namespace
}  // namespace tega::mvs
