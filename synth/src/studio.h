#pragma once
// What every take of one virtual-studio run shares, and the take renderers
// (one file each). Internal to tega_synth.

#include <filesystem>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "head_shader.h"
#include "lens_resampling.h"
#include "tega/core/dataset.h"
#include "tega/core/progress.h"
#include "tega/core/thread_pool.h"
#include "tega/synth/appearance.h"
#include "tega/synth/backdrop.h"
#include "tega/synth/fine_mesh.h"
#include "tega/synth/options.h"
#include "tega/synth/tracking_error.h"

namespace tega::synth {

struct Studio {
  const Options& options;
  std::filesystem::path root;   // the capture's staging directory: takes/
  std::filesystem::path truth;  // where ground_truth/ goes: `root`, or the truth's staging directory (truth_apart)
  const Head& head;
  const FineMeshMaker& maker;
  const Rig& rig;
  const Appearance& appearance;
  const HeadShader& shader;
  const std::vector<ImageF>& backgrounds;  // per camera, noise-free
  const std::vector<PinholeLookup>& lens;  // per camera
  ThreadPool& pool;
  Progress& progress;
  const TrackingError& tracking_error;  // of the dataset's meshes
};

// `foreground`: premultiplied RGBA from rasterize(). Sensor noise is a pure
// function of (noise_seed, pixel, channel).
// As recorded: foreground (if any) over the background, with noise; RGB.
Image8 capture_image(const ImageF* foreground, const ImageF& background, uint64_t noise_seed, double sigma);
// Coverage; grey.
Image8 alpha_image(const ImageF& foreground);
// RGBA: the foreground's own colour (not premultiplied) with noise, alpha = coverage.
Image8 matte_image(const ImageF& foreground, uint64_t noise_seed, double sigma);
// The studio's images (photos, alpha, dataset images) as tega capture and tega dataset build
// write theirs: a PNG at zlib level 1 (at the default level, zlib took 40 % of a 3072 x 2048
// capture's rendering); other extensions as write_image writes them.
void write_studio_image(const Image8& image, const std::filesystem::path& file);

nlohmann::json pose_json(const RigidTransform& pose);  // 3 x 4 rows [R | t]
std::string frame_name(int frame);                      // 000012
void write_take_json(const Studio& studio, const std::string& take, const std::string& kind, int frames);

void render_clean_plate(const Studio& studio);
void render_calibration(const Studio& studio, const std::string& take);
// Appends the take's frames to `dataset_frames` (their meshes and matted
// images are written under `dataset`) and, when the tracking-error model is
// on, what it did to each frame's mesh to `tracking_error_frames`.
void render_performance(const Studio& studio, const std::string& take, const Dataset& dataset,
                        std::vector<DatasetFrame>& dataset_frames, nlohmann::json& tracking_error_frames);

}  // namespace tega::synth
