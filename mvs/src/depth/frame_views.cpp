#include "tega/mvs/frame_views.h"

#include "tega/core/error.h"
#include "tega/core/take_images.h"
#include "tega/core/thread_pool.h"
#include "tega/core/undistort.h"

namespace tega::mvs {

FrameLoader::FrameLoader(TakeInfo take, const Rig& rig, const std::string& rig_source) : take_(std::move(take)) {
  for (const auto& name : take_.cameras) {
    if (!rig.contains(name))
      throw Error(rig_source, "has no camera '" + name + "', which take '" + take_.name + "' recorded");
    cameras_.push_back(rig.camera(name));
    maps_.push_back(cameras_.back().undistortion_maps());
  }
}

StereoView FrameLoader::load_view(size_t camera, int frame) const {
  const auto file = take_.image_path(take_.cameras[camera], frame);
  const Camera& c = cameras_[camera];
  Image8 recorded = read_image_u8(file);
  if (recorded.width != c.width || recorded.height != c.height)
    throw Error(file, "is " + std::to_string(recorded.width) + "x" + std::to_string(recorded.height) +
                          ", but the rig's camera " + c.name + " is " + std::to_string(c.width) + "x" +
                          std::to_string(c.height));
  StereoView view;
  view.camera = without_distortion(c);
  view.colour = undistort_image(recorded_rgb(recorded, take_.pixel_format, file), maps_[camera]);
  view.grey = grey_of(view.colour);
  return view;
}

std::vector<StereoView> FrameLoader::load(int frame, ThreadPool& pool) const {
  if (frame < 0 || frame >= take_.frames)
    throw Error("take " + take_.name + " has no frame " + std::to_string(frame) + " (it has " +
                std::to_string(take_.frames) + ")");
  std::vector<size_t> present;
  for (size_t k = 0; k < take_.cameras.size(); ++k)
    if (take_.has_image(take_.cameras[k], frame)) present.push_back(k);
  std::vector<StereoView> views(present.size());
  pool.parallel_for(0, int64_t(present.size()), [&](int64_t k) { views[size_t(k)] = load_view(present[size_t(k)], frame); });
  return views;
}

}  // namespace tega::mvs
