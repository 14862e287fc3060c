#include "tega/core/undistort.h"

#include <algorithm>
#include <string>

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

Image8 undistort_image(const Image8& captured, const UndistortionMaps& maps) {
  if (captured.width != maps.width || captured.height != maps.height)
    throw Error("undistort: the image and the undistortion maps differ in size");
  const int w = captured.width, h = captured.height, channels = captured.channels;
  const size_t row = static_cast<size_t>(w) * channels;
  Image8 out(w, h, channels, 0);
  // Datasets undistort 26-megapixel images: the loop works on raw pointers
  // and rounds by truncating value + 0.5 (values are never negative), which
  // lround would do four times slower.
  for (int v = 0; v < h; ++v) {
    for (int u = 0; u < w; ++u) {
      const size_t i = static_cast<size_t>(v) * w + u;
      const float x = maps.map_x[i], y = maps.map_y[i];
      // The captured image covers [-0.5, w - 0.5] x [-0.5, h - 0.5]; within the
      // outer half pixel the nearest row or column stands in for its missing
      // neighbour.
      if (!(x >= -0.5f && x <= w - 0.5f && y >= -0.5f && y <= h - 0.5f)) continue;
      const float cx = std::clamp(x, 0.0f, static_cast<float>(w - 1));
      const float cy = std::clamp(y, 0.0f, static_cast<float>(h - 1));
      const int x0 = std::min(static_cast<int>(cx), w - 1), y0 = std::min(static_cast<int>(cy), h - 1);
      const float fx = cx - x0, fy = cy - y0;
      const uint8_t* top = captured.pixels.data() + static_cast<size_t>(y0) * row + static_cast<size_t>(x0) * channels;
      const uint8_t* bottom = y0 + 1 < h ? top + row : top;
      const int right = x0 + 1 < w ? channels : 0;
      uint8_t* pixel = out.pixels.data() + i * channels;
      for (int c = 0; c < channels; ++c) {
        const float upper = top[c] + fx * (top[c + right] - top[c]);
        const float lower = bottom[c] + fx * (bottom[c + right] - bottom[c]);
        pixel[c] = static_cast<uint8_t>(upper + fy * (lower - upper) + 0.5f);
      }
    }
  }
  return out;
}

}  // namespace tega
