#pragma once
// The views of one frame of a take, ready for stereo: each camera's image read
// as recorded, made RGB, undistorted through the rig's lens model and made
// grey. Undistortion maps are computed once per camera for all frames.

#include <functional>
#include <string>
#include <vector>

#include "tega/core/rig.h"
#include "tega/core/take.h"
#include "tega/mvs/patch_match.h"

namespace tega {
class ThreadPool;
}

namespace tega::mvs {

// Makes an 8-bit RGB image of a recorded one whose pixel format is not RGB,
// BGR or Mono (raw Bayer): given the image and the take's pixel format.
using RawToRgb = std::function<Image8(const Image8& raw, const std::string& pixel_format)>;

class FrameLoader {
 public:
  // Every camera of the take must be in the rig (tega::Error naming the
  // camera and `rig_source` otherwise). `raw_to_rgb` may be empty when the
  // take holds RGB, BGR or Mono images.
  FrameLoader(TakeInfo take, const Rig& rig, const std::string& rig_source, RawToRgb raw_to_rgb = {});

  // The take's cameras that have an image of `frame` (TakeInfo::missing).
  // Errors name the frame and the file.
  std::vector<StereoView> load(int frame, ThreadPool& pool) const;
  const TakeInfo& take() const { return take_; }
  const std::vector<Camera>& cameras() const { return cameras_; }  // as recorded, with distortion

 private:
  StereoView load_view(size_t camera, int frame) const;
  TakeInfo take_;
  std::vector<Camera> cameras_;
  std::vector<UndistortionMaps> maps_;
  RawToRgb raw_to_rgb_;
};

// A recorded image of `take` (as read from `file`) as 8-bit RGB, by the
// take's pixel format; tega::Error naming the file when its channels do not
// fit the format, or it is raw Bayer and `raw_to_rgb` is empty.
Image8 recorded_rgb(const Image8& recorded, const TakeInfo& take, const RawToRgb& raw_to_rgb, const std::string& file);

// An 8-bit grey, grey + alpha, RGB or RGBA image as RGB (alpha dropped).
Image8 rgb_of(const Image8& image);

// Rec. 601 luma of an RGB (or grey) 8-bit image, in [0, 1].
ImageF grey_of(const Image8& image);

}  // namespace tega::mvs
