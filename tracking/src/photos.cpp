#include "tega/tracking/photos.h"

#include <algorithm>

#include "tega/core/take_images.h"

namespace tega::tracking {

int photo_downsample(const std::vector<Camera>& cameras, int max_side) {
  if (max_side <= 0) return 1;
  int longest = 0;
  for (const Camera& c : cameras) longest = std::max({longest, c.width, c.height});
  return std::max(1, (longest + max_side - 1) / max_side);
}

std::vector<Camera> photo_cameras(const std::vector<Camera>& cameras, int factor) {
  std::vector<Camera> out;
  for (const Camera& c : cameras) {
    Camera scaled = c.scaled(1.0 / factor);
    scaled.width = c.width / factor;
    scaled.height = c.height / factor;
    out.push_back(scaled);
  }
  return out;
}

std::vector<Image8> frame_photos(const TakeInfo& take, int frame, int factor, ThreadPool& pool) {
  std::vector<Image8> photos(take.cameras.size());
  pool.parallel_for(0, int64_t(take.cameras.size()), [&](int64_t c) {
    const std::string& camera = take.cameras[size_t(c)];
    if (!take.has_image(camera, frame)) return;
    photos[size_t(c)] = read_recorded_rgb(take, camera, frame, factor);
  });
  return photos;
}

}  // namespace tega::tracking
