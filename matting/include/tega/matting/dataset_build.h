#pragma once
// `tega dataset build`: the trainer's dataset (docs/layouts.md#dataset) from a
// capture, what `tega track` made of it and its mattes: those `tega matte`
// made, or made here for the sampled images alone
// (docs/matting.md#building-the-dataset). Each image is undistorted to the
// rig's pinhole, downsampled by area and written as RGBA with its matte as
// alpha; the frames are sampled uniformly over the performance takes.

#include <filesystem>
#include <string>
#include <vector>

#include "tega/core/dataset_gaps.h"
#include "tega/matting/matte_options.h"

namespace tega::matting {

struct DatasetBuildOptions {
  int downsample = 2;
  int frames = 400;
  std::vector<std::string> test_takes;
  std::vector<std::string> test_cameras;
  int test_camera_count = 2;
  std::string image_format = "png";  // png | zst
  int png_compression = 1;
  int threads = 0;
  MatteOptions matte;  // without a MATTES folder; its `threads` is not used
  MissingImageLimits missing_images;

  template <class V>
  void visit(V& v) {
    v("downsample", downsample,
      "Integer factor the images are shrunk by (area averaging after undistortion); it must divide every "
      "camera's size. The paper trains on 3072 x 2048, half its 6144 x 4096 captures.");
    v("frames", frames,
      "Frames in the dataset, sampled uniformly over every performance take's tracked frames in take order "
      "(the paper: 400); 0 = all of them.");
    v("test_takes", test_takes,
      "Performance takes whose sampled frames form the test split (reenactment); empty = the last performance "
      "take when there are two or more, none otherwise.");
    v("test_cameras", test_cameras,
      "Cameras held out for the test split (novel views), by name; empty = test_camera_count cameras spread "
      "over the rig.");
    v("test_camera_count", test_camera_count,
      "Held-out cameras when test_cameras is empty (clamped to 1 .. cameras - 1).");
    v("image_format", image_format,
      "png (any image viewer opens it) or zst (tega's raw pixels in zstd: about the same size, written 2-3 times "
      "and read 3-4 times faster; docs/layouts.md#raw-pixels-in-zstd).");
    v("png_compression", png_compression,
      "zlib level of the images (0-9): 1 writes several times faster than 6 for files about 10% larger "
      "(docs/matting.md#storage).");
    v("threads", threads, "Worker threads; 0 = one per hardware thread.");
    v("matte", matte,
      "How the images are matted when no folder of tega matte's mattes is given (the same method and options as "
      "tega matte; matte.threads is not used): each sampled image is matted as it is built, its photo decoded "
      "once.");
    v("missing_images", missing_images,
      "A recorded image that is missing, unreadable or not its camera's size (a camera that dropped frames, "
      "take.json's `missing`, a disk error) is left out with a warning and recorded in the dataset's "
      "missing_images; these limits drop frames that too few cameras saw and stop the build when too much is "
      "missing (docs/matting.md#missing-images).");
  }
};

struct DatasetBuildRequest {
  std::filesystem::path capture;  // CAPTURE/: capture.json, rig.json, takes/
  std::filesystem::path tracked;  // TRACKED/ from tega track
  // MATTES/ from tega matte: <take>/<camera>/<frame:06d>.png, <take>/mattes.json;
  // empty: the images are matted here (DatasetBuildOptions::matte).
  std::filesystem::path mattes;
  std::filesystem::path out;      // DATASET/
  std::filesystem::path rig;      // empty: the capture's rig file
  bool replace_existing = false;  // an existing DATASET/ is an error otherwise
};

struct DatasetBuildSummary {
  std::filesystem::path dataset;
  int train_frames = 0, test_frames = 0;
  std::vector<std::string> train_cameras, test_cameras;
  int images = 0;       // in the dataset
  int images_kept = 0;  // of them, written by an interrupted run with the same options and inputs
  int missing_images = 0, dropped_frames = 0;  // recorded in the manifest (docs/matting.md#missing-images)
};

// Throws tega::Error naming the file for bad input: a missing or damaged
// capture, rig, tracked take, mesh or matte; a matte whose size is not the
// camera's; options the capture cannot satisfy. A recorded image that is
// missing or unreadable is left out and recorded, within
// options.missing_images' limits. An interrupted run
// leaves DATASET.partial/, which a run with the same options and inputs
// continues.
DatasetBuildSummary build_dataset(const DatasetBuildRequest& request, const DatasetBuildOptions& options);

}  // namespace tega::matting
