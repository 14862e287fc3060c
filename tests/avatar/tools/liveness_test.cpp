// tega inspect's liveness figures on the tiny avatar: a perturbed network
// moves and shades Gaussians differently per frame and every part gets a
// gradient; a field whose
// output layer is zero moves nothing; parts switched off are reported off;
// Gaussians off their birth triangle are counted; against a virtual-studio
// ground truth, the share of the meshes' error the field undoes, all of it
// and its frame-to-frame part.

#include "tega/tools/liveness.h"

#include <gtest/gtest.h>

#include <cmath>
#include <map>

#include "tega/core/error.h"
#include "tega/core/mesh.h"
#include "tega/core/rig.h"

#include "tiny_avatar.h"

namespace tega::tools {
namespace {

// A ground_truth/ folder (as tega synth writes it) for the tiny dataset whose
// true meshes are the dataset's, shifted by shifts[frame] metres.
void write_shifted_truth(const std::filesystem::path& capture, const Dataset& d,
                         const std::map<std::string, Eigen::RowVector3f>& shifts) {
  std::filesystem::create_directories(capture);
  write_rig_json(d.rig, capture / "rig.json");  // the dataset's cameras where the truth's are
  for (const DatasetFrame& f : d.frames) {
    const std::filesystem::path take = capture / "ground_truth" / f.sequence;
    std::filesystem::create_directories(take / "coarse");
    test::write_text(take / "frames.json",
                     R"({"coarse": "coarse/{frame:06d}.bin", "frames": [{"index": 0, "head_to_world": )"
                     R"([[1, 0, 0, 0.01], [0, 1, 0, 0], [0, 0, 1, 0]]}]})");
    Vertices truth = d.load_mesh(f.id);
    truth.rowwise() += shifts.at(f.id);
    write_vertices_bin(truth, take / "coarse/000000.bin");
  }
}

// The field set to one constant offset (head space, the tiny frames' head
// rotation being the identity): every Gaussian moves by `offset`.
void set_constant_field(trainer::AvatarModel& model, const Eigen::Vector3f& offset) {
  at::NoGradGuard no_grad;
  for (auto& item : model.network->named_parameters(true)) {
    if (item.key() == "deformation.output.weight") item.value().zero_();
    if (item.key() == "deformation.output.bias")
      item.value().copy_(at::tensor({offset.x(), offset.y(), offset.z()}, at::kFloat));
  }
}

double gradient_of(const Liveness& l, const std::string& part) {
  for (const auto& g : l.gradients)
    if (g.part == part) return g.mean_norm;
  ADD_FAILURE() << "no gradient reported for " << part;
  return std::nan("");
}

TEST(Liveness, PartsOfAPerturbedAvatarAreAliveAndReported) {
  test::TinyAvatar tiny;
  // The blink frame's mesh, otherwise the smile's, gets its own expression:
  // one corner 5 mm out of the plane.
  Vertices blink = tiny.dataset.load_mesh("blink_000000");
  blink(2, 2) += 0.005f;
  write_vertices_bin(blink, tiny.dataset.mesh_path("blink_000000"));
  const Liveness l = inspect_avatar(*tiny.avatar, tiny.dataset, {});
  EXPECT_TRUE(l.deformation);
  EXPECT_TRUE(l.shading);
  EXPECT_EQ(l.gaussians, 300);
  ASSERT_EQ(l.frames.size(), 2u);
  for (const auto& f : l.frames) {
    EXPECT_GT(f.deformation_mean_mm, 0.0) << f.frame;
    EXPECT_GE(f.deformation_p95_mm, f.deformation_mean_mm * 0.5) << f.frame;
    EXPECT_LT(f.shading_p01, f.shading_p99) << f.frame;
  }
  // The two frames' expressions differ, and so do the networks' outputs.
  EXPECT_GT(l.deformation_frame_std_mm, 0.0);
  EXPECT_GT(l.shading_frame_std, 0.0);
  for (const char* part : {"gaussians.uvd", "gaussians.sh_dc", "network.encoder", "network.deformation",
                           "network.shading"})
    EXPECT_GT(gradient_of(l, part), 0.0) << part;
  EXPECT_FALSE(l.off_birth_triangle.has_value());
  const nlohmann::json j = liveness_json(l);
  EXPECT_EQ(j.at("frames").size(), 2u);
  EXPECT_DOUBLE_EQ(j.at("deformation_frame_std_mm").get<double>(), l.deformation_frame_std_mm);
  EXPECT_NE(liveness_markdown(l, "tiny").find("deformation field: mean"), std::string::npos);
}

TEST(Liveness, AFieldWhoseOutputLayerIsZeroMovesNothing) {
  test::TinyAvatar tiny;
  {
    at::NoGradGuard no_grad;
    for (auto& item : tiny.model().network->named_parameters(true))
      if (item.key().rfind("deformation.output", 0) == 0) item.value().zero_();
  }
  const Liveness l = inspect_avatar(*tiny.avatar, tiny.dataset, {});
  for (const auto& f : l.frames) {
    EXPECT_EQ(f.deformation_mean_mm, 0.0) << f.frame;
    EXPECT_EQ(f.deformation_p95_mm, 0.0) << f.frame;
  }
}

TEST(Liveness, PartsSwitchedOffAreReportedOff) {
  test::TinyAvatar tiny;
  tiny.avatar->phase.deformation = tiny.avatar->phase.shading = false;
  const Liveness l = inspect_avatar(*tiny.avatar, tiny.dataset, {});
  EXPECT_FALSE(l.deformation);
  EXPECT_FALSE(l.shading);
  EXPECT_EQ(gradient_of(l, "network.deformation"), 0.0);
  EXPECT_EQ(gradient_of(l, "network.shading"), 0.0);
  EXPECT_GT(gradient_of(l, "gaussians.sh_dc"), 0.0);
  const std::string text = liveness_markdown(l, "off");
  EXPECT_NE(text.find("deformation field: off"), std::string::npos) << text;
  EXPECT_NE(text.find("dynamic shading: off"), std::string::npos) << text;
}

TEST(Liveness, CountsGaussiansOffTheirBirthTriangle) {
  test::TinyAvatar tiny;
  // Every Gaussian lies on the template's one triangle (0); say a third were born elsewhere.
  at::Tensor birth = at::zeros({300}, at::kLong);
  birth.slice(0, 0, 100).fill_(1);
  tiny.model().gaussians.birth_triangle = birth;
  const Liveness l = inspect_avatar(*tiny.avatar, tiny.dataset, {});
  ASSERT_TRUE(l.off_birth_triangle.has_value());
  EXPECT_NEAR(*l.off_birth_triangle, 1.0 / 3.0, 1e-12);
}

// The field moves every Gaussian by 2 mm along x. Where the true mesh lies
// 2 mm along x of the dataset's (the training frame), it undoes the whole
// error; where it lies 4 mm along x (the held-out frame), half of it.
TEST(Liveness, AgainstTheTruthTheShareOfTheMeshErrorTheFieldUndoes) {
  test::TinyAvatar tiny;
  set_constant_field(tiny.model(), {0.002f, 0, 0});
  write_shifted_truth(tiny.tmp / "capture", tiny.dataset,
                      {{"smile_000000", {0.002f, 0, 0}}, {"blink_000000", {0.004f, 0, 0}}});
  LivenessOptions options;
  options.truth = tiny.tmp / "capture";
  const Liveness l = inspect_avatar(*tiny.avatar, tiny.dataset, options);
  ASSERT_EQ(l.frames.size(), 2u);
  EXPECT_NEAR(*l.frames[0].mesh_error_mm, 2.0, 1e-3);
  EXPECT_NEAR(*l.frames[0].corrected_error_mm, 0.0, 1e-3);
  EXPECT_NEAR(*l.frames[1].mesh_error_mm, 4.0, 1e-3);
  EXPECT_NEAR(*l.frames[1].corrected_error_mm, 2.0, 1e-3);
  ASSERT_TRUE(l.error_undone_train && l.error_undone_test);
  EXPECT_NEAR(*l.error_undone_train, 1.0, 1e-3);
  EXPECT_NEAR(*l.error_undone_test, 0.5, 1e-3);
  EXPECT_NEAR(liveness_json(l).at("error_undone_test").get<double>(), 0.5, 1e-3);
  const std::string text = liveness_markdown(l, "truth");
  EXPECT_NE(text.find("100.0 % of it undone on training frames, 50.0 % on held-out frames"), std::string::npos)
      << text;

  // A field pushing the wrong way adds error; with the field off nothing is undone or added.
  set_constant_field(tiny.model(), {-0.002f, 0, 0});
  EXPECT_NEAR(*inspect_avatar(*tiny.avatar, tiny.dataset, options).error_undone_train, -1.0, 1e-3);
  tiny.avatar->phase.deformation = false;
  const Liveness off = inspect_avatar(*tiny.avatar, tiny.dataset, options);
  EXPECT_NEAR(*off.frames[1].mesh_error_mm, 4.0, 1e-3);
  EXPECT_FALSE(off.frames[1].corrected_error_mm.has_value());
  EXPECT_FALSE(off.error_undone_train.has_value());
}

// Both frames in training, their true meshes 2 and 4 mm along x of the
// dataset's: 3 mm common to the frames, ±1 mm from frame to frame. A constant
// field of 3 mm undoes the common part and none of the frame-to-frame one.
TEST(Liveness, AConstantFieldUndoesNoneOfTheFrameToFramePartOfTheError) {
  test::TinyAvatar tiny;
  tiny.dataset.train.frames = {"smile_000000", "blink_000000"};
  tiny.dataset.test.frames.clear();
  set_constant_field(tiny.model(), {0.003f, 0, 0});
  write_shifted_truth(tiny.tmp / "capture", tiny.dataset,
                      {{"smile_000000", {0.002f, 0, 0}}, {"blink_000000", {0.004f, 0, 0}}});
  LivenessOptions options;
  options.truth = tiny.tmp / "capture";
  const Liveness l = inspect_avatar(*tiny.avatar, tiny.dataset, options);
  ASSERT_TRUE(l.error_undone_train && l.varying_error_mm_train && l.varying_error_undone_train);
  EXPECT_NEAR(*l.error_undone_train, 1.0 - 1.0 / std::sqrt(10.0), 1e-3);  // √10 mm RMS down to 1 mm
  EXPECT_NEAR(*l.varying_error_mm_train, 1.0, 1e-3);
  EXPECT_NEAR(*l.varying_error_undone_train, 0.0, 1e-3);
  EXPECT_FALSE(l.varying_error_mm_test.has_value());  // no held-out frames
  EXPECT_NEAR(l.deformation_frame_std_mm, 0.0, 1e-4);  // the same 3 mm in every frame
  const std::string text = liveness_markdown(l, "varying");
  EXPECT_NE(text.find("per-Gaussian std over frames 0.000 mm"), std::string::npos) << text;
  EXPECT_NE(text.find("frame-to-frame part"), std::string::npos) << text;
  EXPECT_NE(text.find("1.000 mm on training frames, 0.0 % of it undone"), std::string::npos) << text;
  EXPECT_NEAR(liveness_json(l).at("varying_error_mm_train").get<double>(), 1.0, 1e-3);

  // Without the field the frame-to-frame part is still measured, with no share undone.
  tiny.avatar->phase.deformation = false;
  const Liveness off = inspect_avatar(*tiny.avatar, tiny.dataset, options);
  EXPECT_NEAR(*off.varying_error_mm_train, 1.0, 1e-3);
  EXPECT_FALSE(off.varying_error_undone_train.has_value());
}

TEST(Liveness, ATruthThatIsNoVirtualStudioCaptureIsNamed) {
  test::TinyAvatar tiny;
  LivenessOptions options;
  options.truth = tiny.tmp / "nowhere";
  try {
    inspect_avatar(*tiny.avatar, tiny.dataset, options);
    FAIL() << "no error";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("nowhere: no ground_truth/ folder"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace tega::tools
