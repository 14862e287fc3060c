// A performance take: the head performing a script, filmed by every camera;
// ground truth (coarse and fine meshes, alpha, pose, expression) and the
// dataset's meshes and matted images for each frame.

#include <spdlog/spdlog.h>

#include <algorithm>
#include <cmath>

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
  FrameLighting lighting;          // the expression's shadows and gloss, for every camera
  RigidTransform dataset_pose;     // the dataset's head_to_world (lagged with tracking_error.lag_pose)
  nlohmann::json tracking_error;   // what the tracking-error model did (when it is on)
};

}  // namespace

void render_performance(const Studio& studio, const std::string& take, const Dataset& dataset,
                        std::vector<DatasetFrame>& dataset_frames, nlohmann::json& tracking_error_frames) {
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

  std::vector<int> driven;  // model expressions the script sets
  for (const auto& [channel, index] : channels) driven.push_back(index);
  const auto script_expression = [&](int f) {
    std::vector<float> e(model.expression_names.size(), 0.0f);
    for (const auto& [channel, index] : channels) e[index] = script[f].expression[channel].second;
    return e;
  };
  const TrackingError& errors = studio.tracking_error;

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
      g.expression = script_expression(f);
      g.head_to_world = script[f].motion * pivot_to_origin;
      g.dataset_pose = g.head_to_world;
      g.coarse = model.evaluate({}, g.expression, g.head_to_world);
      g.fine = studio.maker.make(g.coarse, g.expression);
      g.lighting = studio.shader.frame_lighting(g.coarse, g.expression, g.fine);
      const std::string id = take + "_" + frame_name(f);
      write_vertices_bin(g.coarse, gt / "coarse" / (frame_name(f) + ".bin"));
      if (o.write_fine_meshes) write_vertices_bin(g.fine.positions, gt / "fine" / (frame_name(f) + ".bin"));
      if (!errors.enabled()) {
        write_vertices_bin(g.coarse, dataset.mesh_path(id));
        return;
      }
      // The dataset's mesh as a tracker would have it: lagged, misfit, its model's shapes, offset.
      const TrackingError::LagSource lag = errors.lag_source(f, o.frames);
      std::vector<float> lagged = script_expression(lag.first);
      if (lag.weight > 0) {
        const std::vector<float> next = script_expression(lag.second);
        for (size_t e = 0; e < lagged.size(); ++e)
          lagged[e] = static_cast<float>((1 - lag.weight) * lagged[e] + lag.weight * next[e]);
      }
      const std::vector<float> expression = errors.misfit(lagged, driven, take, f);
      if (errors.options().lag_pose)
        g.dataset_pose = interpolate_pose(script[lag.first].motion, script[lag.second].motion, lag.weight) *
                         pivot_to_origin;
      Vertices mesh = model.evaluate({}, expression, g.dataset_pose);
      const auto add_head_space = [&](const Vertices& d) {
        mesh += (d.cast<double>() * g.dataset_pose.R.transpose()).cast<float>();
      };
      double shape_rms = 0;
      if (errors.options().shape_misfit > 0) {
        const Vertices shape = errors.shape_error(expression);
        add_head_space(shape);
        shape_rms = errors.skin_rms(shape);
      }
      double rms = 0, largest = 0;
      if (errors.options().offset_m > 0) {
        const Vertices offset = errors.offset(take, f);
        add_head_space(offset);
        rms = errors.skin_rms(offset);
        largest = errors.skin_max(offset);
      }
      write_vertices_bin(mesh, dataset.mesh_path(id));
      nlohmann::json coefficients = nlohmann::json::object();
      for (size_t e = 0; e < expression.size(); ++e)
        if (expression[e] != g.expression[e] || std::find(driven.begin(), driven.end(), int(e)) != driven.end())
          coefficients[model.expression_names[e]] = expression[e];
      g.tracking_error = {{"id", id},
                          {"lag_source", {lag.first, lag.second}},
                          {"lag_weight", lag.weight},
                          {"expression", coefficients},
                          {"head_to_world", pose_json(g.dataset_pose)},
                          {"offset_rms_m", rms},     // over the skin (non-eyeball) vertices
                          {"offset_max_m", largest},
                          {"shape_misfit_rms_m", shape_rms}};  // likewise
    });

    studio.pool.parallel_for(0, int64_t(count) * n_cameras, [&](int64_t task) {
      const int i = static_cast<int>(task / n_cameras), c = static_cast<int>(task % n_cameras);
      const int f = first + i;
      const Surface head = studio.shader.surface(geometry[i].fine, geometry[i].lighting);
      const uint64_t noise = hash_of(uint64_t(o.seed), hash_string(take.c_str()), c, f);
      // One render through the lens-free camera gives the dataset's
      // undistorted image (alpha = exact coverage); the lens bends it into
      // the captured image.
      const ImageF pinhole = rasterize(dataset.rig.cameras[c], {head}, o.supersampling);
      const ImageF captured = resample_through_lens(pinhole, studio.lens[c]);
      const std::string name = frame_name(f);
      write_studio_image(capture_image(&captured, studio.backgrounds[c], noise, o.noise_sigma),
                  studio.root / "takes" / take / cameras[c].name / (name + ".png"));
      write_studio_image(alpha_image(captured), gt / "alpha" / cameras[c].name / (name + ".png"));
      write_studio_image(matte_image(pinhole, noise, o.noise_sigma), dataset.image_path(cameras[c].name, take + "_" + name));
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
      dataset_frames.push_back({take + "_" + frame_name(f), take, g.dataset_pose});
      if (errors.enabled()) tracking_error_frames.push_back(g.tracking_error);
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
