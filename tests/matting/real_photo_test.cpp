// Mattes of real photographs: OpenCV's sample video vtest.avi (opencv-doc,
// /usr/share/doc/opencv-doc/examples/data: a fixed camera over a campus, people
// walking through) gives a real clean plate, the per-pixel median of its
// frames, and real people to matte in frame 100. There is no true alpha: the
// test checks that each person there is found and the empty ground is not,
// and writes photo | alpha | composite to test-artifacts/ to be looked at.
// Skipped where opencv-doc or OpenCV's video reader is missing.
#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <opencv2/core.hpp>
#include <opencv2/videoio.hpp>

#include "tega/core/image.h"
#include "tega/matting/matte.h"

namespace fs = std::filesystem;

namespace tega::matting {
namespace {

const fs::path kVideo = "/usr/share/doc/opencv-doc/examples/data/vtest.avi";
constexpr int kFrame = 100;

Image8 rgb_of(const cv::Mat& bgr) {
  Image8 image(bgr.cols, bgr.rows, 3);
  for (int y = 0; y < bgr.rows; ++y)
    for (int x = 0; x < bgr.cols; ++x)
      for (int c = 0; c < 3; ++c) image.at(x, y, c) = bgr.at<cv::Vec3b>(y, x)[2 - c];
  return image;
}

// The empty scene: the median of every 8th frame (nobody stays that long).
Image8 median_of(const std::vector<cv::Mat>& frames) {
  Image8 plate = rgb_of(frames.front());
  std::vector<uint8_t> values(frames.size());
  for (int y = 0; y < plate.height; ++y) {
    for (int x = 0; x < plate.width; ++x) {
      for (int c = 0; c < 3; ++c) {
        for (size_t k = 0; k < frames.size(); ++k) values[k] = frames[k].at<cv::Vec3b>(y, x)[2 - c];
        std::nth_element(values.begin(), values.begin() + long(values.size() / 2), values.end());
        plate.at(x, y, c) = values[values.size() / 2];
      }
    }
  }
  return plate;
}

double share_above_half(const Image8& alpha, const cv::Rect& box) {
  int count = 0;
  for (int y = box.y; y < box.y + box.height; ++y)
    for (int x = box.x; x < box.x + box.width; ++x) count += alpha.at(x, y, 0) >= 128;
  return double(count) / box.area();
}

double mean_alpha(const Image8& alpha, const cv::Rect& box) {
  double sum = 0;
  for (int y = box.y; y < box.y + box.height; ++y)
    for (int x = box.x; x < box.x + box.width; ++x) sum += alpha.at(x, y, 0) / 255.0;
  return sum / box.area();
}

// Photo, alpha and the photo over magenta by alpha, side by side.
Image8 contact_sheet(const Image8& photo, const Image8& alpha) {
  const int w = photo.width;
  Image8 sheet(3 * w, photo.height, 3);
  for (int y = 0; y < photo.height; ++y) {
    for (int x = 0; x < w; ++x) {
      const double a = alpha.at(x, y, 0) / 255.0;
      const uint8_t magenta[3] = {255, 0, 255};
      for (int c = 0; c < 3; ++c) {
        sheet.at(x, y, c) = photo.at(x, y, c);
        sheet.at(w + x, y, c) = alpha.at(x, y, 0);
        sheet.at(2 * w + x, y, c) = uint8_t(std::lround(a * photo.at(x, y, c) + (1 - a) * magenta[c]));
      }
    }
  }
  return sheet;
}

TEST(MatteRealPhoto, FindsThePeopleInFrontOfARealCleanPlate) {
  if (!fs::exists(kVideo)) GTEST_SKIP() << kVideo << " is missing (Debian package opencv-doc)";
  cv::VideoCapture video(kVideo.string());
  if (!video.isOpened()) GTEST_SKIP() << "this OpenCV cannot read " << kVideo;
  std::vector<cv::Mat> every_8th;
  cv::Mat frame, subject_frame;
  for (int i = 0; video.read(frame); ++i) {
    if (i % 8 == 0) every_8th.push_back(frame.clone());
    if (i == kFrame) subject_frame = frame.clone();
  }
  ASSERT_FALSE(subject_frame.empty()) << kVideo << " has fewer than " << kFrame + 1 << " frames";
  const Image8 plate = median_of(every_8th);
  const Image8 photo = rgb_of(subject_frame);

  // No mesh here: the clean plate alone, every region that differs kept;
  // daylight changes over the video: shading is not subject.
  MatteOptions options;
  options.mesh.keep_connected_only = false;
  options.difference.shading_tolerance = 0.4;
  const Image8 no_mesh(photo.width, photo.height, 1, 0);
  const Image8 alpha = compute_matte(photo, &plate, no_mesh, 1, options);

  const fs::path sheet = fs::path(TEGA_TEST_ARTIFACTS) / "matting" / "vtest_frame100_matte.png";
  fs::create_directories(sheet.parent_path());
  write_image(contact_sheet(photo, alpha), sheet);
  std::printf("photo | alpha | over magenta: %s\n", sheet.c_str());

  // The people of frame 100 (boxes drawn by hand on the photo).
  const std::vector<cv::Rect> people = {{344, 197, 25, 76}, {376, 178, 35, 79}, {490, 150, 27, 72},
                                        {512, 152, 29, 69}, {587, 155, 29, 83}};
  for (const auto& box : people)
    EXPECT_GE(share_above_half(alpha, box), 0.3) << "person at " << box.x << ", " << box.y << " not found";
  // The lawn and the road in front, where nobody walks in that frame.
  EXPECT_LE(mean_alpha(alpha, {150, 300, 270, 180}), 0.01);
  EXPECT_LE(mean_alpha(alpha, {560, 300, 200, 120}), 0.01);
  EXPECT_LE(share_above_half(alpha, {0, 0, photo.width, photo.height}), 0.05);
}

}  // namespace
}  // namespace tega::matting
