#pragma once
// The views of one frame of a take, ready for stereo: each camera's image read
// as recorded, made RGB, undistorted through the rig's lens model and made
// grey. Undistortion maps are computed once per camera for all frames.

#include <string>
#include <vector>

#include "tega/core/rig.h"
#include "tega/core/take.h"
#include "tega/mvs/patch_match.h"

namespace tega {
class ThreadPool;
}

namespace tega::mvs {

class FrameLoader {
 public:
  // Every camera of the take must be in the rig (tega::Error naming the
  // camera and `rig_source` otherwise).
  FrameLoader(TakeInfo take, const Rig& rig, const std::string& rig_source);

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
};

}  // namespace tega::mvs
