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

// Output rows resampled at a time: the strip of full-size rows behind them
// (3 + 1 channels) stays within a few megabytes.
constexpr int kStripRows = 32;

}  // namespace

DatasetResampler::DatasetResampler(const Camera& captured, int downsample)
    : width_(captured.width), height_(captured.height), downsample_(downsample) {
  if (downsample < 1 || width_ % downsample != 0 || height_ % downsample != 0)
    throw Error("downsample " + std::to_string(downsample) + " does not divide camera " + captured.name + "'s size " +
                std::to_string(width_) + "x" + std::to_string(height_));
  if (!captured.has_distortion()) return;
  UndistortionMaps maps = captured.undistortion_maps();
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
                ") must both have the camera's size " + std::to_string(width_) + "x" + std::to_string(height_));
  const cv::Mat colour = view_of(rgb), alpha = view_of(matte);
  Image8 out(width_ / downsample_, height_ / downsample_, 4);
  const cv::Mat result = view_of(out);
  const int strip = kStripRows * downsample_;
  cv::Mat colour_strip, alpha_strip, small_colour, small_alpha;
  for (int y = 0; y < height_; y += strip) {
    const cv::Range rows(y, std::min(height_, y + strip));
    if (map_xy_.empty()) {
      colour_strip = colour.rowRange(rows);
      alpha_strip = alpha.rowRange(rows);
    } else {
      cv::remap(colour, colour_strip, map_xy_.rowRange(rows), map_fraction_.rowRange(rows), cv::INTER_LINEAR,
                cv::BORDER_CONSTANT);
      cv::remap(alpha, alpha_strip, map_xy_.rowRange(rows), map_fraction_.rowRange(rows), cv::INTER_LINEAR,
                cv::BORDER_CONSTANT);
    }
    const cv::Size small(width_ / downsample_, rows.size() / downsample_);
    if (downsample_ > 1) {
      cv::resize(colour_strip, small_colour, small, 0, 0, cv::INTER_AREA);
      cv::resize(alpha_strip, small_alpha, small, 0, 0, cv::INTER_AREA);
    } else {
      small_colour = colour_strip;
      small_alpha = alpha_strip;
    }
    const cv::Mat sources[] = {small_colour, small_alpha};
    cv::Mat target = result.rowRange(rows.start / downsample_, rows.end / downsample_);
    const int from_to[] = {0, 0, 1, 1, 2, 2, 3, 3};
    cv::mixChannels(sources, 2, &target, 1, from_to, 4);
  }
  return out;
}

}  // namespace tega::matting
