#pragma once
// Degraded captures: what a dataset producer (tega ingest multiface, tega
// dataset build) does with the images it cannot use, and how the gaps are
// reported (docs/layouts.md#missing-images). An image that is missing or
// unreadable is left out and recorded in Dataset::missing_images; a frame
// that too few cameras saw is dropped whole; a capture missing so much that
// training would be pointless stops the producer with an error saying what is
// missing and what to do.

#include <filesystem>
#include <string>

#include "tega/core/dataset.h"

namespace tega {

// A stage option (`missing_images` of both producers).
struct MissingImageLimits {
  double min_camera_fraction_per_frame = 0.5;
  double max_missing_fraction_per_camera = 0.5;
  double max_dropped_frame_fraction = 0.25;

  template <class V>
  void visit(V& v) {
    v("min_camera_fraction_per_frame", min_camera_fraction_per_frame,
      "A frame is kept when at least this fraction of the dataset's cameras have a usable image of it; otherwise "
      "it is dropped whole (recorded as dropped_frames): seen from one side only, an expression teaches the "
      "avatar little and biases it. 0 keeps every frame that has any image.");
    v("max_missing_fraction_per_camera", max_missing_fraction_per_camera,
      "When a camera lacks the images of more than this fraction of the kept frames (a dead camera, a failed "
      "copy), the producer stops with an error naming it rather than train on a view it barely has. 1 never "
      "stops.");
    v("max_dropped_frame_fraction", max_dropped_frame_fraction,
      "When more than this fraction of the train frames, or of the test frames, is dropped, the producer stops "
      "with an error: the capture is too damaged for the avatar to be worth training. A split left with no "
      "frame always stops it.");
  }
};

// Throws tega::Error when a limit is out of [0, 1]; `stage` names the options.
void check_missing_image_limits(const MissingImageLimits& limits, const std::string& stage);

// Applies the limits to a dataset whose producer filled frames, split and
// the images it could not use (missing_images): frames with too few usable
// cameras move to dropped_frames (their missing images with them) and leave
// the split. Throws tega::Error(source, ...) naming what is missing when the
// rest is not worth training on; `remedy` says what the user can do (the
// limit to raise is named already). Writes nothing, logs nothing.
void apply_missing_image_limits(Dataset& dataset, const MissingImageLimits& limits,
                                const std::filesystem::path& source, const std::string& remedy);

// What a producer does once it has written every image it could: applies
// the limits as above, then removes each dropped frame's mesh and images from
// dataset.root, warning (as `stage`) with the reason.
void drop_frames_lacking_images(Dataset& dataset, const MissingImageLimits& limits,
                                const std::filesystem::path& source, const std::string& remedy,
                                const std::string& stage);

// One line for reports: "2 missing images (cam01: 1, cam03: 1), 1 dropped
// frame"; empty when the dataset has no gap.
std::string dataset_gap_summary(const Dataset& dataset);

}  // namespace tega
