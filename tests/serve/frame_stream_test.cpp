// The frame stream: round trips within the quantisation it states, refusal
// of malformed streams, and a served frame against `tega export`'s cloud of
// the same frame, with its size against that frame's PLY.

#include "tega/serve/frame_stream.h"

#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "tega/core/error.h"
#include "tega/serve/posed_frame.h"
#include "tega/tools/export.h"
#include "tega/tools/load_run.h"
#include "tega/trainer/spherical_harmonics.h"
#include "tiny_run.h"

namespace tega::serve {
namespace {

namespace fs = std::filesystem;

FramePart random_frame(int n, uint32_t seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> position(-0.3f, 0.4f), log_scale(-9, -2), component(-1, 1), shade(0.5f, 1.7f);
  FramePart f;
  for (int i = 0; i < n; ++i) {
    for (int a = 0; a < 3; ++a) f.means.push_back(position(rng) * (a + 1));
    for (int a = 0; a < 3; ++a) f.log_scales.push_back(log_scale(rng));
    float q[4], norm = 0;
    for (float& c : q) norm += (c = component(rng)) * c;
    for (float c : q) f.rotations.push_back(c / std::sqrt(norm));
    f.shading.push_back(shade(rng));
  }
  f.log_scales[4] = -27.6f;  // a flat Gaussian, as tega's variance floor makes them
  return f;
}

// |q1 · q2| = 1 for the same rotation (q and -q are one rotation).
double rotation_misfit(const float* a, const float* b) {
  return 1.0 - std::abs(a[0] * b[0] + a[1] * b[1] + a[2] * b[2] + a[3] * b[3]);
}

TEST(FrameStream, RoundTripsWithinHalfAStepOfEachQuantiser) {
  const FramePart original = random_frame(2000, 3);
  const std::string bytes = encode_frame(original);
  EXPECT_EQ(bytes.size(), 52u + 14u * 2000u);
  const FramePart decoded = decode_frame(bytes, "test");
  const FrameTolerance tolerance = frame_tolerance(bytes, "test");
  EXPECT_NEAR(tolerance.position[2], 0.5 * 2.1 / 65535, 1e-6);  // z spans about [-0.9, 1.2]
  EXPECT_NEAR(tolerance.log_scale, 0.5 * (-2 - kMinStreamLogScale) / 255, 1e-3);
  ASSERT_EQ(decoded.size(), 2000);
  double worst_rotation = 0;
  for (int64_t i = 0; i < decoded.size(); ++i) {
    for (int a = 0; a < 3; ++a) {
      EXPECT_NEAR(decoded.means[3 * i + a], original.means[3 * i + a], tolerance.position[a] * 1.001 + 1e-7);
      const double log_scale = std::max(double(original.log_scales[3 * i + a]), kMinStreamLogScale);
      EXPECT_NEAR(decoded.log_scales[3 * i + a], log_scale, tolerance.log_scale * 1.001 + 1e-6);
    }
    EXPECT_NEAR(decoded.shading[i], original.shading[i], tolerance.shading * 1.001 + 1e-7);
    worst_rotation = std::max(worst_rotation, rotation_misfit(&decoded.rotations[4 * i], &original.rotations[4 * i]));
  }
  // Three components off by at most half a step each: 1 - cos of the angle stays below ~3 steps².
  EXPECT_LT(worst_rotation, 3 * std::pow(2 * tolerance.rotation_component, 2));
  EXPECT_FLOAT_EQ(decoded.log_scales[4], static_cast<float>(kMinStreamLogScale));
}

TEST(FrameStream, StaticPartRoundTripsExactly) {
  StaticPart part;
  part.sh_degree = 2;
  part.antialiased = true;
  part.background = {0.1f, 0.2f, 0.3f};
  part.opacities = {0.25f, 0.75f};
  for (int k = 0; k < 2 * 9 * 3; ++k) part.sh.push_back(0.01f * k - 0.2f);
  const StaticPart decoded = decode_static(encode_static(part), "test");
  EXPECT_EQ(decoded.sh_degree, 2);
  EXPECT_TRUE(decoded.antialiased);
  EXPECT_EQ(decoded.background, part.background);
  EXPECT_EQ(decoded.opacities, part.opacities);
  EXPECT_EQ(decoded.sh, part.sh);
}

void expect_refused(const std::string& bytes, const std::string& message) {
  try {
    decode_frame(bytes, "frames/x.bin");
    FAIL() << "expected an error containing " << message;
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("frames/x.bin: " + message), std::string::npos) << e.what();
  }
}

TEST(FrameStream, MalformedStreamsAreRefusedNamingTheSource) {
  const std::string good = encode_frame(random_frame(10, 4));
  expect_refused(good.substr(0, 20), "20 bytes, shorter than its header");
  expect_refused(good.substr(0, good.size() - 1), std::to_string(good.size() - 1) + " bytes where its header says");
  std::string magic = good;
  magic[0] = 'X';
  expect_refused(magic, "not a tega frame stream");
  std::string version = good;
  version[4] = 9;
  expect_refused(version, "stream version 9");
  EXPECT_THROW(decode_frame(encode_static(StaticPart{}), "x"), Error);  // a static part is no frame
  FramePart bad = random_frame(3, 5);
  bad.means[2] = NAN;
  EXPECT_THROW(encode_frame(bad), Error);
}

// What the browser gets for a frame, decoded and folded as export_frame
// folds the shading, against export_frame's cloud of the loaded run.
TEST(FrameStream, AServedFrameIsTheExportedFrameWithinTheQuantisation) {
  test::TinyRun tiny;
  tools::LoadedRun loaded = tools::load_run(tiny.run, "", "cpu");
  trainer::TrainedAvatar& avatar = *loaded.avatar;
  const tools::RenderFrame frame = tools::dataset_frames(loaded.dataset, {"blink_000000"}).front();
  const tools::GaussianCloud exported =
      tools::export_frame(avatar.model, avatar.model.frame_input(frame.world_vertices, frame.head_to_world), avatar.phase);

  const std::string frame_bytes = encode_frame(posed_frame(avatar, frame));
  const FramePart served = decode_frame(frame_bytes, "frame");
  const StaticPart fixed = decode_static(encode_static(static_part(avatar)), "static");
  const FrameTolerance tolerance = frame_tolerance(frame_bytes, "frame");
  const int64_t n = exported.size();
  ASSERT_EQ(served.size(), n);
  ASSERT_EQ(fixed.size(), n);
  ASSERT_GT(tolerance.shading, 1e-4) << "the tiny avatar's shading must vary to test it";

  const at::Tensor means = exported.means.contiguous(), log_scale = exported.log_scale.contiguous();
  const at::Tensor covariances = exported.covariances().contiguous(), sh = exported.sh.contiguous();
  tools::GaussianCloud rebuilt = exported;
  rebuilt.log_scale = at::from_blob(const_cast<float*>(served.log_scales.data()), {n, 3}).clone();
  rebuilt.rotation = at::from_blob(const_cast<float*>(served.rotations.data()), {n, 4}).clone();
  const at::Tensor served_covariances = rebuilt.covariances().contiguous();
  const int k = trainer::sh_coefficients(fixed.sh_degree);
  constexpr double c0 = 0.28209479177387814;
  for (int64_t i = 0; i < n; ++i) {
    for (int a = 0; a < 3; ++a) {
      EXPECT_NEAR(served.means[3 * i + a], means[i][a].item<float>(), tolerance.position[a] * 1.001 + 1e-7);
      EXPECT_NEAR(served.log_scales[3 * i + a], log_scale[i][a].item<float>(), tolerance.log_scale * 1.001 + 1e-6);
    }
    // Σ = R diag(σ²) Rᵀ: σ² within e^{±2·tolerance}, rotations within theirs.
    const double sigma2 = std::exp(2.0 * log_scale[i].max().item<double>());
    for (int e = 0; e < 6; ++e)
      EXPECT_NEAR(served_covariances[i][e].item<float>(), covariances[i][e].item<float>(),
                  sigma2 * (2.2 * tolerance.log_scale + 8 * tolerance.rotation_component));
    // The shading folded into the coefficients as export_frame folds it.
    const double s = served.shading[i];
    for (int b = 0; b < k; ++b)
      for (int ch = 0; ch < 3; ++ch) {
        const double h = fixed.sh[(i * k + b) * 3 + ch];
        const double folded = b == 0 ? ((c0 * h + 0.5) * s - 0.5) / c0 : s * h;
        const double bound = (b == 0 ? std::abs(c0 * h + 0.5) / c0 : std::abs(h)) * tolerance.shading * 1.001 + 1e-5;
        EXPECT_NEAR(folded, sh[i][b][ch].item<float>(), bound);
      }
  }

  // The size: what changes per frame against the frame's 3DGS PLY.
  const fs::path ply = tiny.tmp / "frame.ply";
  tools::write_gaussian_ply(exported, ply);
  const double ratio = double(fs::file_size(ply)) / frame_bytes.size();
  std::cout << "frame stream: " << frame_bytes.size() << " bytes a frame of " << n << " Gaussians, PLY "
            << fs::file_size(ply) << " bytes (" << ratio << "x)\n";
  EXPECT_GE(ratio, 8.0);
}

}  // namespace
}  // namespace tega::serve
