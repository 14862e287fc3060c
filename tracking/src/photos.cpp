#include "tega/tracking/photos.h"

#include <algorithm>

#include "tega/core/downsample.h"
#include "tega/mvs/debayer.h"
#include "tega/mvs/frame_views.h"

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
  const bool bayer = take.pixel_format.rfind("Bayer", 0) == 0;
  pool.parallel_for(0, int64_t(take.cameras.size()), [&](int64_t c) {
    const std::string& camera = take.cameras[size_t(c)];
    if (!take.has_image(camera, frame)) return;
    const Image8 raw = read_image_u8(take.image_path(camera, frame));
    if (bayer && factor % 2 == 0)
      photos[size_t(c)] = box_downsample_dropping_remainder(mvs::debayer_half(raw, take.pixel_format), factor / 2);
    else
      photos[size_t(c)] = box_downsample_dropping_remainder(bayer ? mvs::debayer(raw, take.pixel_format) : mvs::rgb_of(raw), factor);
  });
  return photos;
}

}  // namespace tega::tracking
