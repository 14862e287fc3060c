#pragma once
// Options of `tega ingest multiface` (docs/multiface.md). Defaults equal
// studio_configs/multiface.yaml (section `ingest`), which a test keeps in sync.

#include <string>
#include <vector>

#include "tega/core/dataset_gaps.h"

namespace tega::ingest {

struct IngestOptions {
  int width = 1334;
  int height = 2048;
  std::vector<std::string> expressions;
  std::vector<std::string> test_expressions = {"EXP_ROM", "EXP_free_face"};
  int frames = 400;
  int test_frames = 100;
  std::string neutral_expression = "E001_Neutral_Eyes_Open";
  std::string template_obj;
  std::vector<std::string> cameras;
  double max_azimuth_deg = 120.0;
  double max_elevation_deg = 60.0;
  std::vector<double> face_forward;
  std::vector<std::string> test_cameras;
  std::vector<double> test_camera_azimuths_deg = {-45.0, 0.0, 45.0};
  std::string matte = "mesh";
  double matte_dilation_px = 40.0;
  double matte_feather_px = 10.0;
  int downsample = 1;
  MissingImageLimits missing_images;
  int threads = 0;

  template <class V>
  void visit(V& v) {
    v("width", width, "Width in pixels of the capture's images (Multiface: 1334, portrait); every image is checked.");
    v("height", height, "Height in pixels of the capture's images (Multiface: 2048).");
    v("expressions", expressions,
      "Expression sequences to use, by name as in frame_list.txt; empty = every sequence listed there.");
    v("test_expressions", test_expressions,
      "Name prefixes of the held-out expression sequences (test frames), as Multiface's test_segment.json; "
      "when no sequence matches, the last sequence of frame_list.txt is held out.");
    v("frames", frames, "Training frames, sampled uniformly over the training sequences in frame_list.txt order.");
    v("test_frames", test_frames, "Test frames, sampled uniformly over the held-out sequences; 0 = all of them.");
    v("neutral_expression", neutral_expression,
      "Sequence whose first frame is the template (the neutral in head space); when the capture lacks it, the "
      "first frame of frame_list.txt is.");
    v("template", template_obj,
      "OBJ with the mesh topology and UVs; empty = tracked_mesh/<EXP>/<frame>.obj of the template frame.");
    v("cameras", cameras, "Cameras to use, by KRT name; empty = every camera the rules below keep.");
    v("max_azimuth_deg", max_azimuth_deg,
      "Cameras further than this around the head (about the up axis) from the face's forward direction are "
      "dropped: they see the back of the head.");
    v("max_elevation_deg", max_elevation_deg,
      "Cameras higher than this above the head's horizontal plane are dropped: they look down on the crown.");
    v("face_forward", face_forward,
      "The face's forward direction in Multiface head space (3 numbers), carried to the world by the head poses; "
      "empty = estimated from the rig as the mean direction from the head to the cameras.");
    v("test_cameras", test_cameras, "Held-out cameras, by KRT name; empty = one per test_camera_azimuths_deg.");
    v("test_camera_azimuths_deg", test_camera_azimuths_deg,
      "For each, the kept camera nearest to the direction at that azimuth (from the face's forward direction, "
      "positive towards the subject's left) at eye level is held out.");
    v("matte", matte,
      "Alpha of the dataset images: mesh = the tracked mesh's silhouette, dilated and feathered; none = opaque.");
    v("matte_dilation_px", matte_dilation_px,
      "Growth of the mesh silhouette, in pixels of the capture's images, to take in the hair fringe.");
    v("matte_feather_px", matte_feather_px,
      "Width of the soft edge beyond the dilation, in pixels of the capture's images (0 = hard edge).");
    v("downsample", downsample, "Image size divisor: 1 = full size (as the paper trains on Multiface), 2 = half.");
    v("missing_images", missing_images,
      "An image the capture lacks or that cannot be read (an interrupted download, a truncated file) is left out "
      "with a warning and recorded in the dataset's missing_images; these limits drop frames that too few "
      "cameras saw and stop the ingest when too much is missing (docs/multiface.md#missing-images).");
    v("threads", threads, "Worker threads; 0 = one per hardware thread.");
  }
};

}  // namespace tega::ingest
