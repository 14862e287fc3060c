#include "tega/core/undistort.h"

#include <algorithm>
#include <string>
#include <vector>

#include "tega/core/error.h"

namespace tega {

Camera without_distortion(const Camera& camera) {
  Camera pinhole = camera;
  pinhole.distortion = {};
  return pinhole;
}

Image8 undistort_image(const Image8& captured, const Camera& camera) {
  if (captured.width != camera.width || captured.height != camera.height) {
    throw Error("undistort: image of camera '" + camera.name + "' is " + std::to_string(captured.width) + "x" +
                std::to_string(captured.height) + "; the camera is " + std::to_string(camera.width) + "x" +
                std::to_string(camera.height));
  }
  return undistort_image(captured, camera.undistortion_maps());
}

namespace {

// The bilinear sample of `captured` at map entry i, written to `pixel`
// (captured.channels values); false, and `pixel` untouched, where the entry
// falls outside the captured image. Rounds by truncating value + 0.5 (values
// are never negative): lround is four times slower, and datasets undistort
// 26-megapixel images.
bool sample(const Image8& captured, const UndistortionMaps& maps, size_t i, uint8_t* pixel) {
  const int w = captured.width, h = captured.height, channels = captured.channels;
  const float x = maps.map_x[i], y = maps.map_y[i];
  // The captured image covers [-0.5, w - 0.5] x [-0.5, h - 0.5]; within the
  // outer half pixel the nearest row or column stands in for its missing
  // neighbour.
  if (!(x >= -0.5f && x <= w - 0.5f && y >= -0.5f && y <= h - 0.5f)) return false;
  const float cx = std::clamp(x, 0.0f, static_cast<float>(w - 1));
  const float cy = std::clamp(y, 0.0f, static_cast<float>(h - 1));
  const int x0 = std::min(static_cast<int>(cx), w - 1), y0 = std::min(static_cast<int>(cy), h - 1);
  const float fx = cx - x0, fy = cy - y0;
  const size_t row = static_cast<size_t>(w) * channels;
  const uint8_t* top = captured.pixels.data() + static_cast<size_t>(y0) * row + static_cast<size_t>(x0) * channels;
  const uint8_t* bottom = y0 + 1 < h ? top + row : top;
  const int right = x0 + 1 < w ? channels : 0;
  for (int c = 0; c < channels; ++c) {
    const float upper = top[c] + fx * (top[c + right] - top[c]);
    const float lower = bottom[c] + fx * (bottom[c + right] - bottom[c]);
    pixel[c] = static_cast<uint8_t>(upper + fy * (lower - upper) + 0.5f);
  }
  return true;
}

void check_maps(const Image8& captured, const UndistortionMaps& maps) {
  if (captured.width != maps.width || captured.height != maps.height)
    throw Error("undistort: the image and the undistortion maps differ in size");
}

}  // namespace

Image8 undistort_image(const Image8& captured, const UndistortionMaps& maps) {
  check_maps(captured, maps);
  Image8 out(captured.width, captured.height, captured.channels, 0);
  const size_t pixels = static_cast<size_t>(captured.width) * captured.height;
  for (size_t i = 0; i < pixels; ++i) sample(captured, maps, i, out.pixels.data() + i * captured.channels);
  return out;
}

Image8 undistort_image(const Image8& captured, const UndistortionMaps& maps, int factor) {
  check_maps(captured, maps);
  if (factor == 1) return undistort_image(captured, maps);
  const int w = captured.width, channels = captured.channels;
  if (factor < 1 || w % factor != 0 || captured.height % factor != 0) {
    throw Error("downsample " + std::to_string(factor) + " does not divide the image size " + std::to_string(w) + "x" +
                std::to_string(captured.height));
  }
  Image8 out(w / factor, captured.height / factor, channels);
  const size_t row = static_cast<size_t>(w) * channels;
  std::vector<uint8_t> line(row);  // one undistorted row
  std::vector<int> sums(static_cast<size_t>(out.width) * channels);
  const int area = factor * factor;
  for (int y = 0; y < out.height; ++y) {
    std::fill(sums.begin(), sums.end(), 0);
    for (int dy = 0; dy < factor; ++dy) {
      std::fill(line.begin(), line.end(), 0);
      const size_t first = static_cast<size_t>(y * factor + dy) * w;
      for (int u = 0; u < w; ++u) sample(captured, maps, first + u, line.data() + static_cast<size_t>(u) * channels);
      for (int u = 0; u < w; ++u)
        for (int c = 0; c < channels; ++c)
          sums[static_cast<size_t>(u / factor) * channels + c] += line[static_cast<size_t>(u) * channels + c];
    }
    uint8_t* pixels = &out.at(0, y, 0);
    for (size_t i = 0; i < sums.size(); ++i) pixels[i] = static_cast<uint8_t>((sums[i] + area / 2) / area);
  }
  return out;
}

}  // namespace tega
