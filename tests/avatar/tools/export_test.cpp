#include <ATen/ATen.h>
#include <ATen/core/grad_mode.h>
#include <gtest/gtest.h>

#include <cstring>
#include <fstream>
#include <sstream>

#include "tega/core/dataset.h"
#include "tega/core/error.h"
#include "tega/core/files.h"
#include "tega/tools/export.h"
#include "tega/tools/gaussian_ply.h"
#include "tega/tools/gaussian_spz.h"
#include "tega/trainer/render.h"
#include "tega/trainer/spherical_harmonics.h"
#include "test_support.h"
#include "tiny_avatar.h"
#include "../tensor_compare.h"

namespace {

using namespace tega;
using namespace tega::tools;
namespace fs = std::filesystem;

Camera test_camera() {
  Camera c;
  c.name = "probe";
  c.width = 64;
  c.height = 48;
  c.K << 60, 0, 31.5, 0, 60, 23.5, 0, 0, 1;
  // Looking at the triangle's centroid from 1.2 m, slightly from the side.
  c.world_to_camera.R = Eigen::AngleAxisd(0.3, Eigen::Vector3d(0.2, 1, 0).normalized()).toRotationMatrix();
  c.world_to_camera.t = -c.world_to_camera.R * Eigen::Vector3d(0.33, 0.33, 0) + Eigen::Vector3d(0, 0, 1.2);
  return c;
}

struct Fixture : test::TinyAvatar {
  trainer::FrameInput frame;
  trainer::AvatarModel* model = &avatar->model;

  Fixture() {
    Vertices vertices = dataset.load_mesh("blink_000000");
    vertices.row(2) += Eigen::RowVector3f(0.05f, 0.0f, 0.02f);  // an expression
    frame = model->frame_input(vertices, dataset.frame("blink_000000").head_to_world);
  }
};

using test::relative_error;

// pose() folds the shading multiplier into the SH coefficients that the
// rasterizer evaluates; this holds it against colours computed the direct
// way (SH colour per view, times the shading) and rasterized as RGB.
TEST(Export, FoldedShadingRendersLikeShadedColours) {
  Fixture f;
  const Camera camera = test_camera();
  const at::Tensor background = at::full({3}, 0.2);
  at::NoGradGuard no_grad;
  // The tiny network's shading is near 1 everywhere, where a wrong fold
  // would go unseen: a bias and larger weights on its output layer push it
  // well away from 1, whatever the machine's random numbers.
  auto shading_output = f.model->network->named_parameters();
  shading_output["shading.output.bias"].add_(0.4);
  shading_output["shading.output.weight"].add_(at::randn_like(shading_output["shading.output.weight"]) * 0.5);
  for (const trainer::Phase phase :
       {trainer::Phase{true, true, 3}, trainer::Phase{true, true, 2}, trainer::Phase{true, false, 1}}) {
    SCOPED_TRACE("shading " + std::to_string(phase.shading) + ", SH degree " + std::to_string(phase.sh_degree));
    const trainer::PosedGaussians posed = f.model->pose(f.frame, phase);
    ASSERT_EQ(posed.sh.size(1), trainer::sh_coefficients(phase.sh_degree));
    const trainer::Gaussians& g = f.model->gaussians;
    const Eigen::Vector3d centre = camera.center();
    const at::Tensor directions = posed.means - at::tensor({centre.x(), centre.y(), centre.z()}, at::kFloat);
    at::Tensor colors = trainer::sh_to_rgb(g.sh_dc, g.sh_rest, directions, phase.sh_degree);
    if (phase.shading) {
      const at::Tensor shading =
          f.model->network->shade(g.uvd, f.model->network->encode(f.frame.displacement_texture));
      ASSERT_GT((shading - 1).abs().max().item<double>(), 0.05) << "shading must differ from 1 to test the fold";
      colors = colors * shading.unsqueeze(1);
    }
    const at::Tensor expected = splat::rasterize(posed.means, posed.covariances, colors, posed.opacities, background,
                                                 {trainer::raster_camera(camera)},
                                                 trainer::raster_settings(camera, false))
                                    .rgb[0]
                                    .permute({2, 0, 1});
    const at::Tensor actual = trainer::render_view(*f.model, f.frame, camera, phase, background, false);
    ASSERT_GT((expected - 0.2).abs().mean().item<double>(), 0.02) << "the avatar must be in view";
    EXPECT_LE(relative_error(actual, expected), 1e-5);
  }
}

TEST(Export, PlyReadBackReproducesTheRenderedImage) {
  Fixture f;
  const Camera camera = test_camera();
  const at::Tensor background = at::zeros({3});
  for (const trainer::Phase phase : {trainer::Phase{true, true, 3}, trainer::Phase{true, false, 1}}) {
    SCOPED_TRACE("shading " + std::to_string(phase.shading) + ", SH degree " + std::to_string(phase.sh_degree));
    const fs::path file = f.tmp / "avatar.ply";
    write_gaussian_ply(export_frame(*f.model, f.frame, phase), file);
    const GaussianCloud cloud = read_gaussian_ply(file);
    ASSERT_EQ(cloud.size(), 300);
    ASSERT_EQ(cloud.sh_degree(), 3);

    at::NoGradGuard no_grad;
    const at::Tensor expected = trainer::render_view(*f.model, f.frame, camera, phase, background, false);
    const at::Tensor actual = render_cloud(cloud, camera, background, false);
    ASSERT_GT(expected.mean().item<double>(), 0.05) << "the avatar must be in view for the test to mean anything";
    EXPECT_LE(relative_error(actual, expected), 1e-4);
    EXPECT_LE((actual - expected).abs().max().item<double>(), 1e-3);

    // The same from a second, opposite view: the baked SH stays view-dependent.
    Camera behind = camera;
    behind.world_to_camera.R = Eigen::AngleAxisd(M_PI, Eigen::Vector3d::UnitY()).toRotationMatrix() * camera.world_to_camera.R;
    behind.world_to_camera.t = -behind.world_to_camera.R * Eigen::Vector3d(0.33, 0.33, 0) + Eigen::Vector3d(0, 0, 1.2);
    const at::Tensor expected_behind = trainer::render_view(*f.model, f.frame, behind, phase, background, false);
    EXPECT_LE(relative_error(render_cloud(cloud, behind, background, false), expected_behind), 1e-4);
    EXPECT_GT(relative_error(expected_behind, expected), 0.01);  // the two views do differ
  }
}

// Reads float `index` of vertex `v` straight from the file's bytes.
float raw_property(const std::string& bytes, size_t header, int64_t properties, int64_t v, int64_t index) {
  float value;
  std::memcpy(&value, bytes.data() + header + 4 * (v * properties + index), 4);
  return value;
}

TEST(Export, PlyHasThe3dgsLayout) {
  Fixture f;
  const trainer::Phase phase{true, true, 3};
  const fs::path file = f.tmp / "avatar.ply";
  write_gaussian_ply(export_frame(*f.model, f.frame, phase), file);

  const std::string bytes = read_text_file(file);
  const std::string end = "end_header\n";
  const size_t header = bytes.find(end) + end.size();
  std::ostringstream expected;
  expected << "ply\nformat binary_little_endian 1.0\n";
  // Comments are allowed anywhere in a PLY header; drop them before comparing.
  std::istringstream lines(bytes.substr(0, header));
  std::string line, kept;
  while (std::getline(lines, line))
    if (line.rfind("comment", 0) != 0) kept += line + "\n";
  expected << "element vertex 300\n";
  for (const char* p : {"x", "y", "z", "nx", "ny", "nz", "f_dc_0", "f_dc_1", "f_dc_2"}) expected << "property float " << p << "\n";
  for (int i = 0; i < 45; ++i) expected << "property float f_rest_" << i << "\n";
  expected << "property float opacity\n";
  for (int i = 0; i < 3; ++i) expected << "property float scale_" << i << "\n";
  for (int i = 0; i < 4; ++i) expected << "property float rot_" << i << "\n";
  expected << "end_header\n";
  EXPECT_EQ(kept, expected.str());
  constexpr int64_t P = 62;
  ASSERT_EQ(bytes.size(), header + 300 * P * 4);

  // Independent expectations for a few Gaussians.
  at::NoGradGuard no_grad;
  const trainer::PosedGaussians posed = f.model->pose(f.frame, phase);
  const at::Tensor shading = f.model->network->shade(f.model->gaussians.uvd, f.model->network->encode(f.frame.displacement_texture));
  ASSERT_GT((shading - 1).abs().max().item<double>(), 0.05) << "shading must differ from 1 to test the bake";
  const trainer::Gaussians& g = f.model->gaussians;
  constexpr double c0 = 0.28209479177387814;
  for (int64_t v : {0, 1, 150, 299}) {
    SCOPED_TRACE("vertex " + std::to_string(v));
    const double s = shading[v].item<double>();
    for (int k = 0; k < 3; ++k) {
      EXPECT_NEAR(raw_property(bytes, header, P, v, k), posed.means[v][k].item<double>(), 1e-6);
      EXPECT_EQ(raw_property(bytes, header, P, v, 3 + k), 0.0f);  // normals
      const double dc = g.sh_dc[v][0][k].item<double>();
      EXPECT_NEAR(raw_property(bytes, header, P, v, 6 + k), ((c0 * dc + 0.5) * s - 0.5) / c0, 1e-5);
      // f_rest: 15 coefficients of red, then of green, then of blue.
      for (int coefficient : {0, 1, 14})
        EXPECT_NEAR(raw_property(bytes, header, P, v, 9 + 15 * k + coefficient),
                    s * g.sh_rest[v][coefficient][k].item<double>(), 1e-5);
    }
    EXPECT_FLOAT_EQ(raw_property(bytes, header, P, v, 54), g.opacity_logit[v].item<float>());
    // scale (log std) and rotation (w, x, y, z) rebuild the posed covariance.
    Eigen::Quaterniond q(raw_property(bytes, header, P, v, 58), raw_property(bytes, header, P, v, 59),
                         raw_property(bytes, header, P, v, 60), raw_property(bytes, header, P, v, 61));
    EXPECT_NEAR(q.norm(), 1.0, 1e-6);
    Eigen::Vector3d variance;
    for (int k = 0; k < 3; ++k) variance[k] = std::exp(2.0 * raw_property(bytes, header, P, v, 55 + k));
    const Eigen::Matrix3d r = q.normalized().toRotationMatrix();
    const Eigen::Matrix3d sigma = r * variance.asDiagonal() * r.transpose();
    const at::Tensor packed = posed.covariances[v].to(at::kDouble);
    const double expected_entries[6] = {sigma(0, 0), sigma(0, 1), sigma(0, 2), sigma(1, 1), sigma(1, 2), sigma(2, 2)};
    const double largest = variance.maxCoeff();
    for (int k = 0; k < 6; ++k) EXPECT_NEAR(packed[k].item<double>(), expected_entries[k], 1e-5 * largest) << k;
  }
}

TEST(Export, HigherShDegreesThanTheAvatarsAreZero) {
  Fixture f;
  const GaussianCloud cloud = export_frame(*f.model, f.frame, trainer::Phase{false, false, 1});
  EXPECT_EQ(cloud.sh.size(1), 16);
  EXPECT_EQ(cloud.sh.slice(1, 4).abs().max().item<double>(), 0.0);
  EXPECT_GT(cloud.sh.slice(1, 1, 4).abs().max().item<double>(), 0.0);
  // Without shading the coefficients are the avatar's own.
  EXPECT_TRUE(at::allclose(cloud.sh.select(1, 0), f.model->gaussians.sh_dc.select(1, 0)));
}

TEST(Export, DecompositionRebuildsCovariances) {
  at::manual_seed(3);
  const at::Tensor a = at::randn({50, 3, 3}, at::kDouble);
  const at::Tensor sigma = a.bmm(a.transpose(1, 2)) + 1e-3 * at::eye(3, at::kDouble);
  const at::Tensor packed = at::stack({sigma.select(2, 0).select(1, 0), sigma.select(2, 1).select(1, 0),
                                       sigma.select(2, 2).select(1, 0), sigma.select(2, 1).select(1, 1),
                                       sigma.select(2, 2).select(1, 1), sigma.select(2, 2).select(1, 2)},
                                      1);
  const ScaleRotation sr = decompose_covariances(packed);
  EXPECT_TRUE(at::allclose(sr.rotation.norm(2, 1), at::ones({50}, at::kDouble)));
  EXPECT_TRUE(sr.rotation.select(1, 0).ge(0).all().item<bool>());
  const at::Tensor rebuilt = splat::covariance_from_scale_rotation(sr.log_scale.exp(), sr.rotation);
  EXPECT_TRUE(at::allclose(rebuilt, packed, 1e-9, 1e-9));
}

TEST(Export, FormatIsTheFlagsElseTheExtensionsElsePly) {
  EXPECT_EQ(export_format("", "avatar.spz"), ExportFormat::spz);
  EXPECT_EQ(export_format("", "avatar.ply"), ExportFormat::ply);
  EXPECT_EQ(export_format("", "frames"), ExportFormat::ply);
  EXPECT_EQ(export_format("spz", "frames"), ExportFormat::spz);
  EXPECT_EQ(export_format("spz", "frames.v2"), ExportFormat::spz);  // a directory with a dot
  EXPECT_EQ(export_format("ply", "avatar.ply"), ExportFormat::ply);
  EXPECT_EQ(file_extension(ExportFormat::spz), ".spz");
  const std::string message = test::error_message([] { export_format("spz", "avatar.ply"); });
  EXPECT_NE(message.find("avatar.ply"), std::string::npos) << message;
  EXPECT_NE(message.find("--format is spz"), std::string::npos) << message;

  // write_gaussians writes the format it is given.
  test::TempDir tmp;
  const GaussianCloud cloud{at::zeros({2, 3}), at::zeros({2, 1, 3}), at::zeros({2}), at::zeros({2, 3}),
                            at::tensor({1.f, 0.f, 0.f, 0.f}).repeat({2, 1})};
  write_gaussians(cloud, tmp / "a.spz", ExportFormat::spz, true);
  EXPECT_TRUE(read_gaussian_spz(tmp / "a.spz").antialiased);
  write_gaussians(cloud, tmp / "a.ply", ExportFormat::ply, true);
  EXPECT_EQ(read_gaussian_ply(tmp / "a.ply").size(), 2);
}

TEST(GaussianPly, ReadsAsciiAnyOrderAndNamesWhatIsMissing) {
  test::TempDir tmp;
  // Degree 0, properties shuffled, an extra property and a second element.
  test::write_text(tmp / "ascii.ply",
                   "ply\nformat ascii 1.0\nelement vertex 2\nproperty float opacity\nproperty float x\n"
                   "property float y\nproperty float z\nproperty uchar red\nproperty float f_dc_0\n"
                   "property float f_dc_1\nproperty float f_dc_2\nproperty double scale_0\nproperty float scale_1\n"
                   "property float scale_2\nproperty float rot_0\nproperty float rot_1\nproperty float rot_2\n"
                   "property float rot_3\nelement face 0\nproperty list uchar int vertex_indices\nend_header\n"
                   "0.5 1 2 3 255 0.1 0.2 0.3 -4 -5 -6 1 0 0 0\n"
                   "-1 4 5 6 0 0.4 0.5 0.6 -1 -2 -3 0 1 0 0\n");
  const GaussianCloud cloud = read_gaussian_ply(tmp / "ascii.ply");
  ASSERT_EQ(cloud.size(), 2);
  EXPECT_EQ(cloud.sh_degree(), 0);
  EXPECT_TRUE(at::allclose(cloud.means, at::tensor({1.f, 2.f, 3.f, 4.f, 5.f, 6.f}).view({2, 3})));
  EXPECT_TRUE(at::allclose(cloud.sh.view({2, 3}), at::tensor({0.1f, 0.2f, 0.3f, 0.4f, 0.5f, 0.6f}).view({2, 3})));
  EXPECT_TRUE(at::allclose(cloud.opacity_logit, at::tensor({0.5f, -1.f})));
  EXPECT_TRUE(at::allclose(cloud.log_scale[1], at::tensor({-1.f, -2.f, -3.f})));
  EXPECT_TRUE(at::allclose(cloud.rotation[1], at::tensor({0.f, 1.f, 0.f, 0.f})));

  test::write_text(tmp / "bad.ply",
                   "ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\nproperty float y\nproperty float z\n"
                   "end_header\n1 2 3\n");
  try {
    read_gaussian_ply(tmp / "bad.ply");
    FAIL() << "a PLY without Gaussian properties was read";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("bad.ply"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("f_dc_0"), std::string::npos) << e.what();
  }
}

}  // namespace
