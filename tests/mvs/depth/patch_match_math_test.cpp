// The per-pixel math that the CPU path and the CUDA kernels share.
#include <gtest/gtest.h>

#include <random>

#include "patch_match_backend.h"
#include "patch_match_math.h"

namespace tega::mvs::detail {
namespace {

Camera camera(double x, double yaw_deg) {
  Camera c;
  c.name = "cam";
  c.width = 64;
  c.height = 48;
  c.K << 80, 0, 31.5, 0, 80, 23.5, 0, 0, 1;
  const Eigen::Matrix3d R = Eigen::AngleAxisd(yaw_deg * M_PI / 180, Eigen::Vector3d::UnitY()).toRotationMatrix();
  c.world_to_camera.R = R;
  c.world_to_camera.t = -R * Eigen::Vector3d(x, 0, 0);
  return c;
}

TEST(PatchMatchMath, HomographyMapsThePlaneThroughTheSourceCamera) {
  const Camera ref = camera(0, 0), src = camera(0.2, -8);
  const ReferenceView r = reference_geometry(ref);
  const SourceView s = source_geometry(ref, src);
  float normal[3] = {0.3f, -0.2f, -1.0f};
  normalize3(normal);
  float ray[3];
  pixel_ray(r.K_inverse, 30, 20, ray);
  const float depth = 1.1f;
  const float point[3] = {depth * ray[0], depth * ray[1], depth * ray[2]};
  float H[9];
  plane_homography(s, r.K_inverse, normal, dot3(normal, point), H);
  for (const auto& [px, py] : std::vector<std::pair<float, float>>{{30, 20}, {35, 18}, {22, 27}}) {
    float q[3];
    pixel_ray(r.K_inverse, px, py, q);
    const float d = plane_depth(point, normal, q);
    const Eigen::Vector3d on_plane = ref.world_to_camera.inverse().apply(d * Eigen::Vector3d(q[0], q[1], q[2]));
    const Eigen::Vector2d expected = *src.project(on_plane);
    const float hz = H[6] * px + H[7] * py + H[8];
    EXPECT_NEAR((H[0] * px + H[1] * py + H[2]) / hz, expected.x(), 1e-3);
    EXPECT_NEAR((H[3] * px + H[4] * py + H[5]) / hz, expected.y(), 1e-3);
  }
}

TEST(PatchMatchMath, PlaneDepthPropagatesAlongThePlane) {
  const ReferenceView r = reference_geometry(camera(0, 0));
  float normal[3] = {0.1f, 0.4f, -1.0f};
  normalize3(normal);
  float a[3], b[3];
  pixel_ray(r.K_inverse, 10, 10, a);
  pixel_ray(r.K_inverse, 11, 10, b);
  const float point[3] = {0.9f * a[0], 0.9f * a[1], 0.9f * a[2]};
  const float d = plane_depth(point, normal, b);
  const float moved[3] = {d * b[0] - point[0], d * b[1] - point[1], d * b[2] - point[2]};
  EXPECT_NEAR(dot3(moved, normal), 0.0f, 1e-6f);
  EXPECT_GT(d, 0.0f);
}

// A textured fronto-parallel plane seen by a camera shifted along x: the
// source image is the reference image shifted by the disparity f B / Z.
TEST(PatchMatchMath, CostIsLowestAtTheTrueDepth) {
  const int width = 64, height = 48;
  std::mt19937 random(3);
  std::uniform_real_distribution<float> texture(0.1f, 0.9f);
  std::vector<float> ref_pixels(width * height), src_pixels(width * height);
  for (auto& v : ref_pixels) v = texture(random);
  const int disparity = 4;  // f B / Z = 80 * 0.05 / 1.0
  for (int y = 0; y < height; ++y)
    for (int x = 0; x < width; ++x) src_pixels[y * width + x] = ref_pixels[y * width + std::max(0, x - disparity)];
  const Camera ref_camera = camera(0, 0), src_camera = camera(-0.05, 0);
  ReferenceView r = reference_geometry(ref_camera);
  r.image = {ref_pixels.data(), width, height};
  SourceView s = source_geometry(ref_camera, src_camera);
  s.image = {src_pixels.data(), width, height};
  Parameters p;
  p.num_sources = 1;
  p.top_k = 1;
  ReferenceWindow w;
  reference_window(r, p, 30, 20, w);
  const float normal[3] = {0, 0, -1};
  const float at_truth = hypothesis_cost(r, &s, p, w, 30, 20, 1.0f, normal);
  EXPECT_LT(at_truth, 1e-4f);
  // A pixel of disparity off decorrelates the noise texture; a fifth of one already shows.
  for (float wrong : {0.8f, 1.3f}) EXPECT_GT(hypothesis_cost(r, &s, p, w, 30, 20, wrong, normal), 0.3f);
  for (float near : {0.95f, 1.05f}) EXPECT_GT(hypothesis_cost(r, &s, p, w, 30, 20, near, normal), at_truth + 0.02f);
  // A window out of the source image costs the maximum.
  reference_window(r, p, 58, 20, w);
  EXPECT_EQ(hypothesis_cost(r, &s, p, w, 58, 20, 0.2f, normal), kMaxCost);
}

TEST(PatchMatchMath, RandomNumbersAreDeterministicAndUniform) {
  double sum = 0;
  for (int k = 0; k < 10000; ++k) {
    const float u = random_uniform(7, k % 100, k / 100, 3, 1);
    ASSERT_GE(u, 0.0f);
    ASSERT_LT(u, 1.0f);
    ASSERT_EQ(u, random_uniform(7, k % 100, k / 100, 3, 1));
    sum += u;
  }
  EXPECT_NEAR(sum / 10000, 0.5, 0.01);
  EXPECT_NE(random_uniform(7, 1, 2, 3, 1), random_uniform(8, 1, 2, 3, 1));
}

TEST(PatchMatchMath, RandomNormalsFaceTheCamera) {
  const float ray[3] = {0.2f, -0.1f, 1.0f};
  for (int k = 0; k < 100; ++k) {
    float n[3];
    random_normal(ray, random_uniform(1, k, 0, 0, 0), random_uniform(1, k, 0, 0, 1), n);
    EXPECT_NEAR(dot3(n, n), 1.0f, 1e-5f);
    EXPECT_LE(dot3(n, ray), 0.0f);
  }
}

}  // namespace
}  // namespace tega::mvs::detail
