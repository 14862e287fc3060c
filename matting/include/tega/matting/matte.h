#pragma once
// Alpha mattes of a capture's performance takes (`tega matte`,
// docs/matting.md): per image, the difference from the clean plate, the
// tracked mesh's silhouette through the lens as a prior for the head, and
// fractional alpha at the edge by unmixing against the known background.
//
//   MATTES/<take>/<camera>/<frame:06d>.png   8-bit grey alpha of the image as recorded (distorted)
//   MATTES/<take>/options.yaml               what they were made with (a rerun with the same keeps them)
//   MATTES/<take>/mattes.json                the take's summary, written last

#include <filesystem>
#include <string>
#include <vector>

#include "tega/core/image.h"
#include "tega/matting/matte_options.h"

namespace tega::matting {

// One image's alpha (one channel, 255 = subject). `photo`: RGB as recorded.
// `clean_plate`: the same camera's image of the empty studio, or nullptr
// (the mesh prior alone then, feathered along the photo's edges).
// `silhouette`: 255 where the tracked mesh covers the photo. `margin_px`:
// MeshPriorOptions::margin_m in this camera's pixels. Throws tega::Error when
// the sizes differ.
Image8 compute_matte(const Image8& photo, const Image8* clean_plate, const Image8& silhouette, double margin_px,
                     const MatteOptions& options);

struct MatteRequest {
  std::filesystem::path capture;   // CAPTURE/: capture.json, takes/
  std::filesystem::path tracked;   // TRACKED/ from tega track
  std::filesystem::path out;       // MATTES/
  std::vector<std::string> takes;  // empty: every performance take
  std::filesystem::path rig;       // empty: the capture's rig file
};

struct MatteSummary {
  int takes = 0;
  int images = 0;              // matted by this run
  int images_kept = 0;         // matted by an earlier run with the same options
  int frames_not_tracked = 0;  // failed or skipped by the tracker: no mattes
  bool clean_plate = false;    // whether a clean plate was used
};

// Errors name the file: a camera missing from the rig, an image of the wrong
// size, a frame without a tracking record.
MatteSummary matte_capture(const MatteRequest& request, const MatteOptions& options);

}  // namespace tega::matting
