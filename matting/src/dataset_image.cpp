#include "tega/matting/dataset_image.h"

#include <algorithm>
#include <opencv2/imgproc.hpp>
#include <string>

#include "tega/core/error.h"

namespace tega::matting {
namespace fs = std::filesystem;

void check_matte(const fs::path& file, const ImageHeader& header, int width, int height) {
  if (header.channels != 1 || header.bit_depth != 8)
    throw Error(file, "has " + std::to_string(header.channels) + " channel(s) of " + std::to_string(header.bit_depth) +
                          " bits; a matte is 8-bit grey");
  if (header.width != width || header.height != height)
    throw Error(file, "is " + std::to_string(header.width) + "x" + std::to_string(header.height) +
                          "; the captured image it mattes is " + std::to_string(width) + "x" + std::to_string(height));
}

Image8 read_matte(const fs::path& file, int width, int height, const std::string& what) {
  if (!fs::exists(file)) throw Error(file, "is missing (the matte of " + what + "; run tega matte)");
  const Image8 matte = read_image_u8(file);
  check_matte(file, {matte.width, matte.height, matte.channels, 8}, width, height);
  return matte;
}

namespace {

cv::Mat view_of(const Image8& image) {
  return cv::Mat(image.height, image.width, CV_8UC(image.channels), const_cast<uint8_t*>(image.pixels.data()));
}

}  // namespace

Camera recorded_camera_at_dataset_size(const Camera& captured, int downsample) {
  if (downsample < 1 || captured.width % downsample != 0 || captured.height % downsample != 0)
    throw Error("downsample " + std::to_string(downsample) + " does not divide camera " + captured.name + "'s size " +
                std::to_string(captured.width) + "x" + std::to_string(captured.height));
  return captured.scaled(1.0 / downsample);
}

DatasetResampler::DatasetResampler(const Camera& captured, int downsample) {
  const Camera camera = recorded_camera_at_dataset_size(captured, downsample);
  width_ = camera.width;
  height_ = camera.height;
  if (!camera.has_distortion()) return;
  UndistortionMaps maps = camera.undistortion_maps();
  // core's rule (undistort.h): the captured image covers [-0.5, w - 0.5];
  // inside, positions clamp to the outermost pixel centres; outside, black.
  // A position moved well off the image gives OpenCV's constant border.
  const float w = float(width_), h = float(height_);
  for (size_t i = 0; i < maps.map_x.size(); ++i) {
    float& x = maps.map_x[i];
    float& y = maps.map_y[i];
    if (x >= -0.5f && x <= w - 0.5f && y >= -0.5f && y <= h - 0.5f) {
      x = std::clamp(x, 0.0f, w - 1);
      y = std::clamp(y, 0.0f, h - 1);
    } else {
      x = y = -16;
    }
  }
  const cv::Mat map_x(height_, width_, CV_32F, maps.map_x.data()), map_y(height_, width_, CV_32F, maps.map_y.data());
  cv::convertMaps(map_x, map_y, map_xy_, map_fraction_, CV_16SC2);
}

Image8 DatasetResampler::rgba(const Image8& rgb, const Image8& matte) const {
  if (rgb.width != width_ || rgb.height != height_ || rgb.channels != 3 || matte.width != width_ ||
      matte.height != height_ || matte.channels != 1)
    throw Error("dataset image: the photo (" + std::to_string(rgb.width) + "x" + std::to_string(rgb.height) +
                ") and its matte (" + std::to_string(matte.width) + "x" + std::to_string(matte.height) +
                ") must both have the dataset's size " + std::to_string(width_) + "x" + std::to_string(height_));
  Image8 recorded(width_, height_, 4);
  cv::Mat interleaved = view_of(recorded);
  const cv::Mat sources[] = {view_of(rgb), view_of(matte)};
  const int from_to[] = {0, 0, 1, 1, 2, 2, 3, 3};
  cv::mixChannels(sources, 2, &interleaved, 1, from_to, 4);
  if (map_xy_.empty()) return recorded;
  Image8 out(width_, height_, 4);
  cv::Mat target = view_of(out);
  cv::remap(interleaved, target, map_xy_, map_fraction_, cv::INTER_LINEAR, cv::BORDER_CONSTANT);
  return out;
}

}  // namespace tega::matting
