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

#include "tega/core/camera.h"
#include "tega/core/image.h"
#include "tega/core/mesh.h"
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

// The mattes of one camera, with what they share made once: the clean plate
// at the size the photos are matted at (MatteOptions::max_work_width), and
// the camera the tracked mesh is rasterised through at that size. The same
// method as compute_matte; matte() is thread-safe.
class CameraMatting {
 public:
  // `clean_plate`: RGB, the camera's size; empty: none (the mesh prior alone).
  // Throws tega::Error when its size is not the camera's.
  CameraMatting(const Camera& camera, Image8 clean_plate, const MatteOptions& options);
  // `photo`: RGB as recorded, the camera's size; `world`: the tracked mesh.
  Image8 matte(const Image8& photo, const Vertices& world, const Triangles& faces) const;

 private:
  Camera camera_, work_camera_;  // work_camera_: the camera at 1/shrink_ of its size
  int shrink_;
  Image8 plate_, work_plate_;    // empty without a clean plate; work_plate_ only when shrunk
  Image16 work_plate_sums_;      // its 3 x 3 sums, which every matte's difference uses
  const Image8& work_plate() const { return shrink_ > 1 ? work_plate_ : plate_; }
  MatteOptions options_;
};

// A matte as tega matte stores it: 8-bit grey PNG at zlib level 1 (a matte
// is mostly 0 and 255: the fastest level is nearly as small as the best),
// written atomically.
void write_matte(const Image8& alpha, const std::filesystem::path& file);

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
