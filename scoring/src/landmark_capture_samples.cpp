#include <string>

#include "tega/core/error.h"
#include "tega/core/progress.h"
#include "tega/core/take.h"
#include "tega/scoring/landmark_capture_training.h"
#include "tega/scoring/studio_landmarks.h"

namespace tega::scoring {
namespace fs = std::filesystem;

namespace {

void check_sampling(const LandmarkSamplingOptions& options) {
  if (options.frame_stride < 1)
    throw Error("landmark sampling: frame_stride must be 1 or more, got " + std::to_string(options.frame_stride));
  if (!(options.max_view_angle_deg > 0 && options.max_view_angle_deg <= 180))
    throw Error("landmark sampling: max_view_angle_deg must lie in (0, 180], got " +
                std::to_string(options.max_view_angle_deg));
}

const CaptureTake& performance_take(const CaptureInfo& info, const std::string& name) {
  for (const CaptureTake& take : info.takes)
    if (take.name == name && take.kind == "performance") return take;
  throw Error(info.root / "capture.json", "has no performance take " + name);
}

}  // namespace

std::vector<CaptureLandmarkSample> capture_landmark_samples(const fs::path& capture,
                                                            const std::vector<int>& landmark_vertices,
                                                            const LandmarkSamplingOptions& options) {
  check_sampling(options);
  const CaptureInfo info = read_capture(capture);
  const StudioLandmarkTruth truth(capture, landmark_vertices);
  const std::vector<std::string> take_names = info.performance_takes(options.takes, "to sample landmarks from");
  const std::vector<std::string> cameras = options.cameras.empty() ? truth.rig().camera_names() : options.cameras;
  for (const std::string& camera : cameras)
    if (!truth.rig().contains(camera))
      throw Error(studio_truth_root(capture) / "rig.json", "has no camera " + camera + " to sample landmarks from");

  int sampled_frames = 0;
  for (const std::string& name : take_names)
    sampled_frames += (performance_take(info, name).frames + options.frame_stride - 1) / options.frame_stride;
  Progress progress("landmark samples of " + capture.string(), sampled_frames, "frames");
  std::vector<CaptureLandmarkSample> samples;
  for (const std::string& name : take_names) {
    const TakeInfo take = read_take(capture / "takes" / name);
    for (int frame = 0, position = 0; frame < take.frames; frame += options.frame_stride, ++position) {
      const StudioFrameLandmarks landmarks = truth.frame(name, frame);
      for (const std::string& camera : cameras)
        if (take.has_image(camera, frame) && truth.view_angle_deg(landmarks, camera) <= options.max_view_angle_deg)
          samples.push_back({name, camera, frame, position, truth.sample(landmarks, camera)});
      progress.advance();
    }
  }
  progress.finish();
  if (samples.empty())
    throw Error(capture, "no photo shows the face within " + std::to_string(options.max_view_angle_deg) +
                             " degrees of its front (sampling.max_view_angle_deg)");
  return samples;
}

}  // namespace tega::scoring
