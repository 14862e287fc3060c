#include "tega/mvs/frame_views.h"

#include "tega/core/error.h"
#include "tega/core/thread_pool.h"
#include "tega/core/undistort.h"

namespace tega::mvs {

Image8 recorded_rgb(const Image8& recorded, const TakeInfo& take, const RawToRgb& raw_to_rgb, const std::string& file) {
  const std::string& format = take.pixel_format;
  if (format.rfind("RGB", 0) == 0 && recorded.channels >= 3) return rgb_of(recorded);
  if (format.rfind("BGR", 0) == 0 && recorded.channels == 3) {
    Image8 rgb = recorded;
    for (size_t i = 0; i < rgb.pixels.size(); i += 3) std::swap(rgb.pixels[i], rgb.pixels[i + 2]);
    return rgb;
  }
  if (format.rfind("Mono", 0) == 0 && recorded.channels == 1) return rgb_of(recorded);
  if (format.rfind("Bayer", 0) == 0 && recorded.channels == 1) {
    if (!raw_to_rgb) throw Error(file, "is raw Bayer (" + format + "), which this build cannot debayer (needs OpenCV)");
    return raw_to_rgb(recorded, format);
  }
  throw Error(file, "has " + std::to_string(recorded.channels) + " channel(s), which does not fit the take's pixel format " +
                        format);
}

Image8 rgb_of(const Image8& image) {
  if (image.channels == 3) return image;
  Image8 rgb(image.width, image.height, 3);
  const bool grey = image.channels < 3;
  for (size_t i = 0; i < size_t(image.width) * image.height; ++i)
    for (int c = 0; c < 3; ++c) rgb.pixels[3 * i + c] = image.pixels[image.channels * i + (grey ? 0 : c)];
  return rgb;
}

ImageF grey_of(const Image8& image) {
  ImageF grey(image.width, image.height, 1);
  for (size_t i = 0; i < grey.pixels.size(); ++i) {
    const uint8_t* p = &image.pixels[i * image.channels];
    grey.pixels[i] = image.channels >= 3 ? (0.299f * p[0] + 0.587f * p[1] + 0.114f * p[2]) / 255.0f : p[0] / 255.0f;
  }
  return grey;
}

FrameLoader::FrameLoader(TakeInfo take, const Rig& rig, const std::string& rig_source, RawToRgb raw_to_rgb)
    : take_(std::move(take)), raw_to_rgb_(std::move(raw_to_rgb)) {
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
  view.colour = undistort_image(recorded_rgb(recorded, take_, raw_to_rgb_, file.string()), maps_[camera]);
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
