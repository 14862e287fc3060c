// A performance take: the head performing a script, filmed by every camera;
// ground truth (coarse and fine meshes, alpha, pose, expression) and the
// dataset's meshes and matted images for each frame.

#include <spdlog/spdlog.h>

#include "studio.h"
#include "tega/core/files.h"
#include "tega/synth/performance.h"
#include "tega/synth/random.h"

namespace tega::synth {
namespace {

struct FrameGeometry {
  std::vector<float> expression;  // the model's coefficient vector
  RigidTransform head_to_world;
  Vertices coarse;  // world
  FineFrame fine;   // world
};

}  // namespace

void render_performance(const Studio& studio, const std::string& take, const Dataset& dataset,
                        std::vector<DatasetFrame>& dataset_frames) {
  const Options& o = studio.options;
  const BlendshapeModel& model = studio.head.model;
  const std::vector<PerformanceFrame> script = perform(take, o.frames, uint64_t(o.seed));

  // Script channels the model lacks are left out (and said so).
  std::vector<std::pair<size_t, int>> channels;  // script channel -> model expression
  for (size_t i = 0; i < script.front().expression.size(); ++i) {
    const std::string& name = script.front().expression[i].first;
    const int index = model.expression_index(name);
    if (index >= 0) channels.emplace_back(i, index);
    else spdlog::warn("synth: the head model has no expression '{}'; take {} goes without it", name, take);
  }

  const auto& cameras = studio.rig.cameras;
  const int n_cameras = static_cast<int>(cameras.size());
  const std::filesystem::path gt = studio.truth / "ground_truth" / take;
  std::filesystem::create_directories(gt / "coarse");
  if (o.write_fine_meshes) std::filesystem::create_directories(gt / "fine");
  for (const auto& cam : cameras) {
    std::filesystem::create_directories(studio.root / "takes" / take / cam.name);
    std::filesystem::create_directories(gt / "alpha" / cam.name);
    std::filesystem::create_directories(dataset.image_path(cam.name, "x").parent_path());
  }
  std::filesystem::create_directories(dataset.mesh_path("x").parent_path());

  nlohmann::json frames_json = nlohmann::json::array();
  const RigidTransform pivot_to_origin{Eigen::Matrix3d::Identity(), -studio.head.pivot};
  // Frames are made in batches large enough to keep every worker busy, and
  // small enough that only a few fine meshes are held at once.
  const int batch = std::max(1, (2 * studio.pool.size() + n_cameras - 1) / n_cameras);
  for (int first = 0; first < o.frames; first += batch) {
    const int count = std::min(batch, o.frames - first);
    std::vector<FrameGeometry> geometry(count);
    studio.pool.parallel_for(0, count, [&](int64_t i) {
      const int f = first + static_cast<int>(i);
      FrameGeometry& g = geometry[i];
      g.expression.assign(model.expression_names.size(), 0.0f);
      for (const auto& [channel, index] : channels) g.expression[index] = script[f].expression[channel].second;
      g.head_to_world = script[f].motion * pivot_to_origin;
      g.coarse = model.evaluate({}, g.expression, g.head_to_world);
      g.fine = studio.maker.make(g.coarse, g.expression);
      const std::string id = take + "_" + frame_name(f);
      write_vertices_bin(g.coarse, gt / "coarse" / (frame_name(f) + ".bin"));
      if (o.write_fine_meshes) write_vertices_bin(g.fine.positions, gt / "fine" / (frame_name(f) + ".bin"));
      write_vertices_bin(g.coarse, dataset.mesh_path(id));
    });

    studio.pool.parallel_for(0, int64_t(count) * n_cameras, [&](int64_t task) {
      const int i = static_cast<int>(task / n_cameras), c = static_cast<int>(task % n_cameras);
      const int f = first + i;
      const Surface head = studio.shader.surface(geometry[i].fine);
      const uint64_t noise = hash_of(uint64_t(o.seed), hash_string(take.c_str()), c, f);
      // One render through the lens-free camera gives the dataset's
      // undistorted image (alpha = exact coverage); the lens bends it into
      // the captured image.
      const ImageF pinhole = rasterize(dataset.rig.cameras[c], {head}, o.supersampling);
      const ImageF captured = resample_through_lens(pinhole, studio.lens[c]);
      const std::string name = frame_name(f);
      write_image(capture_image(&captured, studio.backgrounds[c], noise, o.noise_sigma),
                  studio.root / "takes" / take / cameras[c].name / (name + ".png"));
      write_image(alpha_image(captured), gt / "alpha" / cameras[c].name / (name + ".png"));
      write_image(matte_image(pinhole, noise, o.noise_sigma), dataset.image_path(cameras[c].name, take + "_" + name));
      studio.progress.advance();
    });

    for (int i = 0; i < count; ++i) {
      const int f = first + i;
      const FrameGeometry& g = geometry[i];
      nlohmann::json expression = nlohmann::json::object();
      for (const auto& [channel, index] : channels) expression[model.expression_names[index]] = g.expression[index];
      nlohmann::json wrinkles = nlohmann::json::object();
      const std::vector<double> activation = studio.maker.region_activations(g.expression);
      for (size_t r = 0; r < activation.size(); ++r) wrinkles[studio.maker.region_names()[r]] = activation[r];
      frames_json.push_back({{"index", f},
                             {"time", script[f].time},
                             {"expression", expression},
                             {"wrinkles", wrinkles},
                             {"head_to_world", pose_json(g.head_to_world)}});
      dataset_frames.push_back({take + "_" + frame_name(f), take, g.head_to_world});
    }
  }

  const nlohmann::json j = {{"take", take},
                            {"kind", "performance"},
                            {"script", take},
                            {"coarse", "coarse/{frame:06d}.bin"},
                            {"fine", o.write_fine_meshes ? "fine/{frame:06d}.bin" : ""},
                            {"alpha", "alpha/{camera}/{frame:06d}.png"},
                            {"frames", frames_json}};
  write_text_atomic(gt / "frames.json", j.dump(2) + "\n");
  write_take_json(studio, take, "performance", o.frames);
}

}  // namespace tega::synth
