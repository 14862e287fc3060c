// Close-ups of tega eval: boxes around the projected eye and mouth landmarks,
// and metrics that see detail lost inside one box.
#include <ATen/ATen.h>
#include <gtest/gtest.h>

#include <cmath>
#include <iostream>

#include "tega/core/camera.h"
#include "tega/tools/closeups.h"
#include "tega/tools/landmarks.h"
#include "tega/tools/metrics.h"

namespace {

using namespace tega;
using namespace tega::tools;

// Six points on an ellipse (an eye's corners and lids, or the lips' points).
void place_ellipse(at::Tensor& points, int first, int count, double x, double y, double half_width,
                   double half_height, double z) {
  for (int i = 0; i < count; ++i) {
    const double angle = 2 * M_PI * i / count;
    points[first + i][0] = x + half_width * std::cos(angle);
    points[first + i][1] = y + half_height * std::sin(angle);
    points[first + i][2] = z;
  }
}

// A face's 68 landmarks at depth z (metres, camera space = world space):
// eyes 30 x 10 mm, 64 mm apart, 30 mm above the centre; the mouth 50 x 20 mm,
// 45 mm below it. The other points sit at the centre.
at::Tensor face_landmarks(double z) {
  at::Tensor points = at::zeros({68, 3}, at::kDouble);
  points.select(1, 2).fill_(z);
  place_ellipse(points, 36, 6, -0.032, -0.03, 0.015, 0.005, z);
  place_ellipse(points, 42, 6, 0.032, -0.03, 0.015, 0.005, z);
  place_ellipse(points, 48, 20, 0.0, 0.045, 0.025, 0.01, z);
  return points;
}

Camera closeup_camera() {
  Camera camera;
  camera.name = "front";
  camera.width = 640;
  camera.height = 480;
  camera.K << 800, 0, 320, 0, 800, 240, 0, 0, 1;
  return camera;
}

bool box_contains(const PixelBox& box, const Eigen::Vector2d& p) {
  return p.x() >= box.x0 && p.x() <= box.x1 - 1 && p.y() >= box.y0 && p.y() <= box.y1 - 1;
}

TEST(Closeups, BoxesLandAroundTheProjectedEyeAndMouthLandmarks) {
  const Camera camera = closeup_camera();
  const std::vector<std::optional<Eigen::Vector2d>> projected = project_landmarks(face_landmarks(1.0), camera);
  ASSERT_EQ(closeup_regions().size(), 2u);
  const CloseupRegion& eyes = closeup_regions()[0];
  const CloseupRegion& mouth = closeup_regions()[1];
  const std::vector<PixelBox> eye_boxes = region_boxes(eyes, projected, camera.width, camera.height);
  const std::vector<PixelBox> mouth_boxes = region_boxes(mouth, projected, camera.width, camera.height);
  ASSERT_EQ(eye_boxes.size(), 2u);
  ASSERT_EQ(mouth_boxes.size(), 1u);

  // At 1 m, 800 px/m: the right eye spans 24 x 8 px about (294.4, 216).
  const PixelBox& right_eye = eye_boxes[0];
  for (int i = 36; i < 42; ++i) EXPECT_TRUE(box_contains(right_eye, *projected[i])) << "landmark " << i;
  // 24 px grown by 40 % of 24 on each side: 43.2 px wide; 8 px high grows
  // to 27.2, under the 32 px minimum, so it is 32-33 px high.
  EXPECT_NEAR(right_eye.x1 - right_eye.x0, 43.2, 1.0);
  EXPECT_GE(right_eye.y1 - right_eye.y0, kCloseupMinimumSide);
  EXPECT_LE(right_eye.y1 - right_eye.y0, kCloseupMinimumSide + 1);
  EXPECT_NEAR((right_eye.x0 + right_eye.x1 - 1) / 2.0, 294.4, 0.6);
  EXPECT_NEAR((right_eye.y0 + right_eye.y1 - 1) / 2.0, 216.0, 0.6);
  // The left eye is the mirror image about x = 320.
  EXPECT_NEAR((eye_boxes[1].x0 + eye_boxes[1].x1 - 1) / 2.0, 345.6, 0.6);
  for (int i = 42; i < 48; ++i) EXPECT_TRUE(box_contains(eye_boxes[1], *projected[i])) << "landmark " << i;
  // The mouth, 40 x 16 px about (320, 276): 72 x 48 px.
  const PixelBox& lips = mouth_boxes[0];
  for (int i = 48; i < 68; ++i) EXPECT_TRUE(box_contains(lips, *projected[i])) << "landmark " << i;
  EXPECT_NEAR(lips.x1 - lips.x0, 72.0, 1.0);
  EXPECT_NEAR(lips.y1 - lips.y0, 48.0, 1.0);
  EXPECT_NEAR((lips.y0 + lips.y1 - 1) / 2.0, 276.0, 0.6);
  // Neither region's box reaches the other's landmarks.
  EXPECT_FALSE(box_contains(lips, *projected[37]));
  EXPECT_FALSE(box_contains(right_eye, *projected[51]));

  // Ten times as far, every part is a few pixels: the boxes keep the minimum size.
  const auto far = project_landmarks(face_landmarks(10.0), camera);
  for (const CloseupRegion& region : closeup_regions())
    for (const PixelBox& box : region_boxes(region, far, camera.width, camera.height)) {
      EXPECT_GE(box.x1 - box.x0, kCloseupMinimumSide);
      EXPECT_LE(box.x1 - box.x0, kCloseupMinimumSide + 1);
      EXPECT_GE(box.y1 - box.y0, kCloseupMinimumSide);
    }
}

TEST(Closeups, BoxesAreClippedToTheImageAndMissingBehindTheCamera) {
  const Camera camera = closeup_camera();
  // The face 0.45 m to the left: the right eye's box is cut by the image's left edge.
  at::Tensor moved = face_landmarks(1.0);
  moved.select(1, 0).sub_(0.36);
  const auto projected = project_landmarks(moved, camera);
  const std::vector<PixelBox> eyes = region_boxes(closeup_regions()[0], projected, camera.width, camera.height);
  ASSERT_EQ(eyes.size(), 2u);
  EXPECT_EQ(eyes[0].x0, 0);
  EXPECT_GT(eyes[0].x1, 0);
  // Entirely off the image: no box, and no region.
  moved.select(1, 0).sub_(1.0);
  EXPECT_TRUE(region_boxes(closeup_regions()[1], project_landmarks(moved, camera), 640, 480).empty());
  // A mouth landmark behind the camera: no mouth box; the eyes keep theirs.
  at::Tensor behind = face_landmarks(1.0);
  behind[50][2] = -1.0;
  const auto projected_behind = project_landmarks(behind, camera);
  EXPECT_FALSE(projected_behind[50].has_value());
  EXPECT_TRUE(region_boxes(closeup_regions()[1], projected_behind, 640, 480).empty());
  EXPECT_EQ(region_boxes(closeup_regions()[0], projected_behind, 640, 480).size(), 2u);
}

// A textured image, blurred only inside the mouth's box: the close-up of the
// mouth loses more than 10 dB against the whole image's PSNR, the eyes' see
// nothing, and the detail metrics follow.
TEST(Closeups, SeeBlurInsideTheMouthThatWholeImagePsnrHardlyDoes) {
  constexpr int kSize = 256;
  at::manual_seed(3);
  const at::Tensor y = at::linspace(0, 1, kSize).view({1, kSize, 1}), x = at::linspace(0, 1, kSize).view({1, 1, kSize});
  const at::Tensor shading = 0.5 + 0.2 * at::sin(5 * x + at::arange(3).view({3, 1, 1}).to(at::kFloat)) * at::cos(3 * y);
  const at::Tensor truth = (shading + 0.2 * (at::rand({3, kSize, kSize}) - 0.5)).clamp(0, 1).to(at::kDouble);

  // Landmarks in pixels, 1000 px/m: eyes 30 x 10 px at y = 100, the mouth 50 x 20 px at (128, 175).
  at::Tensor pixels = face_landmarks(1.0);
  pixels.select(1, 0).mul_(1000).add_(128);
  pixels.select(1, 1).mul_(1000).add_(130);
  std::vector<std::optional<Eigen::Vector2d>> landmarks;
  for (int i = 0; i < 68; ++i)
    landmarks.push_back(Eigen::Vector2d(pixels[i][0].item<double>(), pixels[i][1].item<double>()));
  const std::vector<PixelBox> mouth = region_boxes(closeup_regions()[1], landmarks, kSize, kSize);
  ASSERT_EQ(mouth.size(), 1u);

  // A 5x5 binomial blur (σ = 1 px), pasted into the mouth's box only.
  const at::Tensor taps = at::tensor({1.0, 4.0, 6.0, 4.0, 1.0}, at::kDouble) / 16;
  const at::Tensor blurred = at::conv2d(at::replication_pad2d(truth.unsqueeze(1), {2, 2, 2, 2}),
                                        at::outer(taps, taps).view({1, 1, 5, 5}))
                                 .squeeze(1);
  at::Tensor render = truth.clone();
  const auto inside = [&](const at::Tensor& image) {
    return image.slice(1, mouth[0].y0, mouth[0].y1).slice(2, mouth[0].x0, mouth[0].x1);
  };
  inside(render).copy_(inside(blurred));

  const at::Tensor head = at::ones({kSize, kSize}, at::kBool);
  const std::map<std::string, double> closeups = closeup_metrics(error_maps(render, truth), head, landmarks);
  const double whole = psnr(render, truth);
  const double mouth_psnr = closeups.at("closeup_mouth_psnr");
  std::cout << "whole image " << whole << " dB, mouth close-up " << mouth_psnr << " dB, mouth hf_psnr "
            << closeups.at("closeup_mouth_hf_psnr") << " dB, gradient error "
            << closeups.at("closeup_mouth_gradient_error")
            << " vs " << gradient_error(render, truth, head) << " over the image\n";
  // All the error is in the box: the whole image's MSE is the box's times its share of the pixels.
  const double share = double((mouth[0].x1 - mouth[0].x0) * (mouth[0].y1 - mouth[0].y0)) / (kSize * kSize);
  EXPECT_NEAR(whole - mouth_psnr, -10 * std::log10(share), 1e-6);
  EXPECT_GT(whole - mouth_psnr, 10.0);
  EXPECT_LT(mouth_psnr, 30.0);
  EXPECT_LT(closeups.at("closeup_mouth_ssim"), 0.95);
  EXPECT_LT(closeups.at("closeup_mouth_hf_psnr"), 35.0);
  EXPECT_GT(closeups.at("closeup_mouth_gradient_error"), 5 * gradient_error(render, truth, head));
  // The eyes' boxes are far from the blur: their renders are the truth.
  EXPECT_TRUE(std::isinf(closeups.at("closeup_eyes_psnr")));
  EXPECT_TRUE(std::isinf(closeups.at("closeup_eyes_hf_psnr")));
  EXPECT_NEAR(closeups.at("closeup_eyes_ssim"), 1.0, 1e-12);
  EXPECT_EQ(closeups.at("closeup_eyes_gradient_error"), 0.0);
  // Outside the head mask nothing is scored.
  EXPECT_TRUE(std::isnan(closeup_metrics(error_maps(render, truth), at::zeros_like(head), landmarks)
                             .at("closeup_mouth_psnr")));
}

}  // namespace
