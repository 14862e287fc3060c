#include <ATen/ATen.h>
#include <ATen/core/grad_mode.h>
#include <gtest/gtest.h>

#include <cmath>
#include <nlohmann/json.hpp>

#include "tega/core/error.h"
#include "tega/core/files.h"
#include "tega/core/image.h"
#include "tega/tools/evaluate.h"
#include "tega/tools/landmarks.h"
#include "tega/tools/metrics.h"
#include "tega/trainer/render.h"
#include "tiny_avatar.h"

namespace {

using namespace tega;
using namespace tega::tools;

at::Tensor dataset_image(const Dataset& d, const std::string& camera, const std::string& frame) {
  Image8 image = read_image_u8(d.image_path(camera, frame));
  return at::from_blob(image.pixels.data(), {image.height, image.width, image.channels}, at::kByte).clone();
}

TEST(Eval, ScoresTheViewsOfThePapersProtocol) {
  test::TinyAvatar tiny;
  const std::vector<SplitResult> splits = evaluate_avatar(*tiny.avatar, tiny.dataset, "test", nullptr);
  ASSERT_EQ(splits.size(), 2u);
  // Reenactment: the test frame from the training camera; novel view: the
  // training frame from the test camera.
  ASSERT_EQ(splits[0].name, "reenactment");
  ASSERT_EQ(splits[0].views.size(), 1u);
  EXPECT_EQ(splits[0].views[0].frame, "blink_000000");
  EXPECT_EQ(splits[0].views[0].camera, "cam00");
  ASSERT_EQ(splits[1].name, "novel_view");
  ASSERT_EQ(splits[1].views.size(), 1u);
  EXPECT_EQ(splits[1].views[0].frame, "smile_000000");
  EXPECT_EQ(splits[1].views[0].camera, "cam01");

  // Each view is scored against its own image (the tiny dataset's images
  // differ per camera and frame).
  const at::Tensor background = at::tensor(tiny.avatar->options.background, at::kFloat);
  for (const SplitResult& split : splits) {
    const ViewResult& v = split.views[0];
    at::NoGradGuard no_grad;
    const trainer::FrameInput input = tiny.model().frame_input(tiny.dataset.load_mesh(v.frame), tiny.dataset.frame(v.frame).head_to_world);
    const at::Tensor rendered = trainer::render_view(tiny.model(), input, tiny.dataset.rig.camera(v.camera), tiny.avatar->phase,
                                                     background, false)
                                    .clamp(0, 1);
    const at::Tensor target = trainer::composite_target(dataset_image(tiny.dataset, v.camera, v.frame), background);
    EXPECT_NEAR(v.metrics.at("psnr"), psnr(rendered, target), 1e-9);
    EXPECT_NEAR(v.metrics.at("l1"), l1(rendered, target), 1e-9);
    EXPECT_NEAR(v.metrics.at("ssim"), ssim(rendered, target), 1e-9);
    const at::Tensor everywhere = at::ones({rendered.size(1), rendered.size(2)}, at::kBool);
    EXPECT_NEAR(v.metrics.at("hf_psnr_masked"), hf_psnr(rendered, target, everywhere), 1e-9);
    EXPECT_NEAR(v.metrics.at("gradient_error_masked"), gradient_error(rendered, target, everywhere), 1e-9);
    EXPECT_GT(v.metrics.at("gradient_error_masked"), 0.0);
    // The tiny dataset's matte is opaque everywhere: masked = full.
    EXPECT_NEAR(v.metrics.at("psnr_masked"), v.metrics.at("psnr"), 1e-9);
    EXPECT_TRUE(std::isnan(v.metrics.at("psnr_background")));  // no background pixel
    EXPECT_EQ(v.metrics.count("lpips"), 0u);
    EXPECT_EQ(v.metrics.count("landmark_px"), 0u);
    EXPECT_EQ(v.metrics.count("landmark_drift_px"), 0u);
    EXPECT_EQ(v.metrics.count("closeup_mouth_psnr"), 0u);
  }
}

// The head mask and the background split every view's pixels: the full image's
// squared error is their area-weighted sum, so a render's error lands in one or
// the other, never in both and never lost.
TEST(Eval, BackgroundPsnrScoresWhatLiesOutsideTheHeadMask) {
  test::TinyAvatar tiny;
  const std::string camera = "cam01", frame = "smile_000000";  // the novel view
  Image8 image = read_image_u8(tiny.dataset.image_path(camera, frame));
  ASSERT_EQ(image.channels, 4);
  const int head_columns = image.width / 3;  // the matte: opaque in the left third only
  for (int y = 0; y < image.height; ++y)
    for (int x = head_columns; x < image.width; ++x) image.at(x, y, 3) = 0;
  write_image(image, tiny.dataset.image_path(camera, frame));

  const std::vector<SplitResult> splits = evaluate_avatar(*tiny.avatar, tiny.dataset, "test", nullptr);
  const ViewResult& v = splits[1].views[0];
  ASSERT_EQ(v.camera, camera);
  const at::Tensor background = at::tensor(tiny.avatar->options.background, at::kFloat);
  at::NoGradGuard no_grad;
  const trainer::FrameInput input =
      tiny.model().frame_input(tiny.dataset.load_mesh(frame), tiny.dataset.frame(frame).head_to_world);
  const at::Tensor rendered = trainer::render_view(tiny.model(), input, tiny.dataset.rig.camera(camera),
                                                   tiny.avatar->phase, background, false)
                                  .clamp(0, 1);
  const at::Tensor target = trainer::composite_target(dataset_image(tiny.dataset, camera, frame), background);
  at::Tensor outside = at::ones({image.height, image.width}, at::kBool);
  outside.narrow(1, 0, head_columns).fill_(false);
  EXPECT_NEAR(v.metrics.at("psnr_background"), psnr(rendered, target, outside), 1e-9);
  EXPECT_NEAR(v.metrics.at("psnr_masked"), psnr(rendered, target, outside.logical_not()), 1e-9);
  const auto mse = [](double psnr_db) { return std::pow(10.0, -psnr_db / 10); };
  const double head_share = static_cast<double>(head_columns) / image.width;
  EXPECT_NEAR(mse(v.metrics.at("psnr")),
              head_share * mse(v.metrics.at("psnr_masked")) + (1 - head_share) * mse(v.metrics.at("psnr_background")),
              1e-6 * mse(v.metrics.at("psnr")));
  // Where the truth is the background, the Gaussians the avatar draws there are the error.
  EXPECT_TRUE(std::isfinite(v.metrics.at("psnr_background")));
}

TEST(Eval, LandmarkDriftFollowsTheDeformationField) {
  test::TinyAvatar tiny;
  tiny.dataset.landmark_vertices = {0, 1, 2};
  const LandmarkProbe probe(tiny.dataset, tiny.model());
  const Vertices vertices = tiny.dataset.load_mesh("blink_000000");
  const trainer::FrameInput input = tiny.model().frame_input(vertices, tiny.dataset.frame("blink_000000").head_to_world);
  const Camera& camera = tiny.dataset.rig.camera("cam00");
  // Without the field the avatar's landmarks are the tracked vertices.
  const at::Tensor rigid = probe.avatar(tiny.model(), input, {false, true, 3});
  EXPECT_TRUE(at::allclose(rigid, probe.reference(vertices), 1e-6, 1e-6));
  EXPECT_NEAR(landmark_drift_px(probe.reference(vertices), rigid, camera), 0.0, 1e-4);
  // With it, they move by the field's displacement, projected.
  const at::Tensor moved = probe.avatar(tiny.model(), input, {true, true, 3});
  const double error = landmark_drift_px(probe.reference(vertices), moved, camera);
  EXPECT_GT(error, 1e-3);
  double expected = 0;
  for (int l = 0; l < 3; ++l) {
    const auto p = camera.project(Eigen::Vector3d(vertices(l, 0), vertices(l, 1), vertices(l, 2)));
    const auto q = camera.project(Eigen::Vector3d(moved[l][0].item<double>(), moved[l][1].item<double>(), moved[l][2].item<double>()));
    ASSERT_TRUE(p && q) << "landmark " << l << " must be in front of the camera";
    expected += (*p - *q).norm() / 3;
  }
  EXPECT_NEAR(error, expected, 1e-9);

  const std::vector<SplitResult> splits = evaluate_avatar(*tiny.avatar, tiny.dataset, "test", nullptr);
  EXPECT_NEAR(splits[0].views[0].metrics.at("landmark_drift_px"), landmark_drift_px(probe.reference(vertices), moved, camera), 1e-6);
  // Three landmarks are not the 68-point markup: no close-ups, no face box for a detector.
  EXPECT_EQ(splits[0].views[0].metrics.count("closeup_eyes_psnr"), 0u);
  const LandmarkPredictor never_called = [](const Image8&, const Eigen::AlignedBox2d&) {
    ADD_FAILURE() << "a predictor without a face box";
    return std::vector<Eigen::Vector2d>(68);
  };
  EXPECT_THROW(evaluate_avatar(*tiny.avatar, tiny.dataset, "test", nullptr, &never_called), Error);
}

// The tiny triangle's three vertices stand for the 68 landmarks (landmark i
// is vertex i mod 3): every part's box covers the 8x6 image.
TEST(Eval, CloseupsAndDetectedLandmarksOfEveryView) {
  test::TinyAvatar tiny;
  tiny.dataset.landmark_vertices.clear();
  for (int i = 0; i < 68; ++i) tiny.dataset.landmark_vertices.push_back(i % 3);
  // A stand-in predictor: the 68 points at the box's centre, moved right by
  // ten times the image's mean red (so render and truth differ), and every
  // box it is given.
  std::vector<Eigen::AlignedBox2d> boxes;
  const LandmarkPredictor predictor = [&boxes](const Image8& image, const Eigen::AlignedBox2d& box) {
    boxes.push_back(box);
    double red = 0;
    for (int y = 0; y < image.height; ++y)
      for (int x = 0; x < image.width; ++x) red += image.at(x, y, 0) / 255.0 / (image.width * image.height);
    return std::vector<Eigen::Vector2d>(68, box.center() + Eigen::Vector2d(10 * red, 0));
  };
  const std::vector<SplitResult> splits = evaluate_avatar(*tiny.avatar, tiny.dataset, "test", nullptr, &predictor);
  ASSERT_EQ(boxes.size(), 4u);  // render and truth of two views

  const at::Tensor background = at::tensor(tiny.avatar->options.background, at::kFloat);
  const auto mean_red = [](const at::Tensor& rgb) {
    return rgb[0].clamp(0, 1).mul(255).round().to(at::kDouble).mean().item<double>() / 255;
  };
  for (size_t s = 0; s < splits.size(); ++s) {
    const ViewResult& v = splits[s].views[0];
    const Camera& camera = tiny.dataset.rig.camera(v.camera);
    // The box: the projected vertices' bounding box, grown by 7.5 % of its size on each side.
    Eigen::AlignedBox2d expected;
    const Vertices vertices = tiny.dataset.load_mesh(v.frame);
    for (int i = 0; i < 3; ++i) expected.extend(*camera.project(vertices.row(i).cast<double>().transpose()));
    const Eigen::Vector2d grow = 0.075 * expected.sizes();
    for (const Eigen::AlignedBox2d& box : {boxes[2 * s], boxes[2 * s + 1]}) {
      EXPECT_TRUE(box.min().isApprox(expected.min() - grow, 1e-9)) << box.min().transpose();
      EXPECT_TRUE(box.max().isApprox(expected.max() + grow, 1e-9)) << box.max().transpose();
    }
    at::NoGradGuard no_grad;
    const trainer::FrameInput input = tiny.model().frame_input(vertices, tiny.dataset.frame(v.frame).head_to_world);
    const at::Tensor rendered =
        trainer::render_view(tiny.model(), input, camera, tiny.avatar->phase, background, false).clamp(0, 1);
    const at::Tensor target = trainer::composite_target(dataset_image(tiny.dataset, v.camera, v.frame), background);
    EXPECT_NEAR(v.metrics.at("landmark_px"), 10 * std::abs(mean_red(rendered) - mean_red(target)), 1e-9);
    EXPECT_GT(v.metrics.at("landmark_px"), 0.01);
    // Every box covers the whole image, whose matte is opaque: the close-ups are the masked metrics.
    for (const char* region : {"eyes", "mouth"}) {
      const std::string prefix = std::string("closeup_") + region + "_";
      EXPECT_NEAR(v.metrics.at(prefix + "psnr"), v.metrics.at("psnr_masked"), 1e-9);
      EXPECT_NEAR(v.metrics.at(prefix + "ssim"), v.metrics.at("ssim_masked"), 1e-9);
      EXPECT_NEAR(v.metrics.at(prefix + "hf_psnr"), v.metrics.at("hf_psnr_masked"), 1e-9);
      EXPECT_NEAR(v.metrics.at(prefix + "gradient_error"), v.metrics.at("gradient_error_masked"), 1e-9);
    }
  }

  ModelResult model{"Ours", tiny.tmp / "run", 6, 300, splits};
  write_evaluation({model}, evaluation_notes(tiny.dataset, false, "predictor.dat"), tiny.tmp / "eval.json");
  const auto doc = nlohmann::json::parse(read_text_file(tiny.tmp / "eval.json"));
  const auto& reenactment = doc["models"][0]["splits"]["reenactment"]["metrics"];
  EXPECT_NEAR(reenactment["landmark_px"]["mean"].get<double>(), splits[0].views[0].metrics.at("landmark_px"), 1e-9);
  EXPECT_EQ(reenactment["closeup_mouth_hf_psnr"]["count"].get<int>(), 1);
  EXPECT_NE(doc["notes"]["landmark_px"].get<std::string>().find("predictor.dat"), std::string::npos);
  EXPECT_NE(doc["notes"]["closeups"].get<std::string>().find("40 % of its longer side"), std::string::npos);
  const std::string markdown = read_text_file(tiny.tmp / "eval.md");
  EXPECT_NE(markdown.find("## Close-up: mouth"), std::string::npos) << markdown;
  EXPECT_NE(markdown.find("Novel view HF PSNR ↑"), std::string::npos) << markdown;
  EXPECT_NE(markdown.find("Test reenactment Landmark px ↓"), std::string::npos) << markdown;
}

TEST(Eval, JsonAndMarkdownHoldStatisticsNotesAndInfinity) {
  test::TinyAvatar tiny;
  ModelResult model{"Ours", tiny.tmp / "run", 6, 300, evaluate_avatar(*tiny.avatar, tiny.dataset, "test", nullptr)};
  // A second model whose reenactment renders are perfect: PSNR = inf.
  ModelResult perfect = model;
  perfect.name = "Perfect";
  for (auto& v : perfect.splits[0].views) {
    v.metrics["psnr"] = std::numeric_limits<double>::infinity();
    v.metrics["ssim"] = 1.0;
    v.metrics["l1"] = 0.0;
  }
  const EvalNotes notes = evaluation_notes(tiny.dataset, false, "");
  write_evaluation({model, perfect}, notes, tiny.tmp / "eval/out.json");

  const auto doc = nlohmann::json::parse(read_text_file(tiny.tmp / "eval/out.json"));
  EXPECT_NE(doc["notes"]["lpips"].get<std::string>().find("skipped"), std::string::npos);
  for (const char* note : {"landmark_px", "landmark_drift_px", "closeups"})
    EXPECT_NE(doc["notes"][note].get<std::string>().find("skipped"), std::string::npos) << note;
  ASSERT_EQ(doc["models"].size(), 2u);
  const auto& ours = doc["models"][0]["splits"];
  const double psnr_value = model.splits[0].views[0].metrics.at("psnr");
  EXPECT_NEAR(ours["reenactment"]["metrics"]["psnr"]["mean"].get<double>(), psnr_value, 1e-9);
  EXPECT_EQ(ours["reenactment"]["metrics"]["psnr"]["std"].get<double>(), 0.0);
  EXPECT_EQ(ours["reenactment"]["metrics"]["psnr"]["count"].get<int>(), 1);
  EXPECT_NEAR(ours["reenactment"]["per_camera"]["cam00"]["metrics"]["psnr"]["mean"].get<double>(), psnr_value, 1e-9);
  EXPECT_NEAR(ours["reenactment"]["per_frame"]["blink_000000"]["metrics"]["psnr"]["mean"].get<double>(), psnr_value, 1e-9);
  EXPECT_TRUE(ours["novel_view"]["per_camera"].contains("cam01"));
  EXPECT_EQ(ours["novel_view"]["per_view"][0]["frame"], "smile_000000");
  EXPECT_FALSE(ours["reenactment"]["metrics"].contains("lpips"));
  for (const char* detail : {"hf_psnr_masked", "gradient_error_masked"}) {
    EXPECT_NEAR(ours["novel_view"]["metrics"][detail]["mean"].get<double>(),
                model.splits[1].views[0].metrics.at(detail), 1e-9);
    EXPECT_NE(doc["notes"]["detail"].get<std::string>().find(detail), std::string::npos);
  }
  // The tiny dataset's matte is opaque: no view has a background pixel to score.
  EXPECT_EQ(ours["novel_view"]["metrics"]["psnr_background"]["undefined"].get<int>(), 1);
  EXPECT_NE(doc["notes"]["background"].get<std::string>().find("psnr_background"), std::string::npos);
  const auto& perfect_json = doc["models"][1]["splits"]["reenactment"]["metrics"];
  EXPECT_EQ(perfect_json["psnr"]["mean"], "inf");
  EXPECT_EQ(perfect_json["psnr"]["std"], "nan");
  EXPECT_EQ(perfect_json["ssim"]["mean"].get<double>(), 1.0);

  const std::string markdown = read_text_file(tiny.tmp / "eval/out.md");
  EXPECT_NE(markdown.find("| Ours |"), std::string::npos) << markdown;
  EXPECT_NE(markdown.find("| Perfect |"), std::string::npos) << markdown;
  EXPECT_NE(markdown.find("Test reenactment PSNR ↑"), std::string::npos) << markdown;
  EXPECT_NE(markdown.find("Novel view SSIM ↑"), std::string::npos) << markdown;
  EXPECT_NE(markdown.find("Test reenactment HF PSNR ↑"), std::string::npos) << markdown;
  EXPECT_NE(markdown.find("Novel view Gradient error ↓"), std::string::npos) << markdown;
  EXPECT_NE(markdown.find("## Outside the head mask"), std::string::npos) << markdown;
  EXPECT_NE(markdown.find("∞ ± nan"), std::string::npos) << markdown;
  char psnr_text[32];
  std::snprintf(psnr_text, sizeof psnr_text, "%.2f ± 0.00", psnr_value);
  EXPECT_NE(markdown.find(psnr_text), std::string::npos) << markdown;
  EXPECT_NE(markdown.find("LPIPS skipped"), std::string::npos) << markdown;
  EXPECT_NE(markdown.find("landmark_px skipped: no landmark predictor"), std::string::npos) << markdown;
}

TEST(Eval, TrainSplitAndUnknownSplits) {
  test::TinyAvatar tiny;
  const auto train = evaluation_views(tiny.dataset, "train");
  ASSERT_EQ(train.size(), 1u);
  EXPECT_EQ(train[0].views.size(), 1u);
  EXPECT_EQ(train[0].views[0].camera, "cam00");
  EXPECT_THROW(evaluation_views(tiny.dataset, "validation"), Error);
}

}  // namespace
