#include "tega/synth/virtual_studio.h"

#include <spdlog/spdlog.h>

#include <algorithm>
#include <chrono>
#include <optional>
#include <set>

#include "studio.h"
#include "tega/core/error.h"
#include "tega/core/files.h"
#include "tega/core/options.h"
#include "tega/synth/charuco_board.h"
#include "tega/synth/performance.h"
#include "tega/synth/studio_rig.h"
#include "tega/synth/tracking_error.h"

namespace tega::synth {
namespace {

void write_head_ground_truth(const std::filesystem::path& dir, const Head& head, const FineMeshMaker& maker) {
  std::filesystem::create_directories(dir);
  write_obj(head.model.neutral, dir / "template.obj");
  write_obj(maker.fine_topology(), dir / "fine_topology.obj");
  nlohmann::json wrinkles = nlohmann::json::array();
  for (const auto& w : head.wrinkles)
    wrinkles.push_back({{"name", w.name},
                        {"drivers", w.drivers},
                        {"centre", {w.centre.x(), w.centre.y()}},
                        {"sigma", {w.sigma.x(), w.sigma.y()}},
                        {"angle", w.angle},
                        {"period", w.period}});
  const auto vec = [](const Eigen::Vector3d& v) { return nlohmann::json{v.x(), v.y(), v.z()}; };
  const nlohmann::json j = {
      {"source", head.source},
      {"template", "template.obj"},
      {"fine_topology", "fine_topology.obj"},
      {"fine_note", "fine meshes: fine_topology.obj's faces and UVs; its triangles come in runs of "
                    "4^fine_subdivisions, one run per triangle of template.obj, in that order"},
      {"eyeball_faces", head.eyeball_faces},
      {"source_vertex_runs", head.source_vertex_runs},
      {"expressions", head.model.expression_names},
      {"eye_left", vec(head.frame.eye_left)},
      {"eye_right", vec(head.frame.eye_right)},
      {"interocular_m", head.frame.interocular},
      {"pivot", vec(head.pivot)},
      {"wrinkle_regions", wrinkles}};
  write_text_atomic(dir / "head.json", j.dump(2) + "\n");
}

}  // namespace

std::filesystem::path truth_directory(const std::filesystem::path& out) {
  std::filesystem::path dir = out;
  if (!dir.has_filename()) dir = dir.parent_path();  // "capture/" names capture
  return dir.string() + ".truth";
}

void validate_options(const Options& o) {
  make_studio_rig(o.studio);  // throws for a bad studio
  if (o.frames < 1) throw Error("frames must be at least 1");
  if (o.calibration_frames < 0) throw Error("calibration_frames must not be negative");
  if (o.supersampling < 1 || o.supersampling > 8) throw Error("supersampling must be in 1 .. 8");
  if (o.fine_subdivisions < 0 || o.fine_subdivisions > 4) throw Error("fine_subdivisions must be in 0 .. 4");
  if (o.takes.empty()) throw Error("takes must name at least one performance script");
  std::set<std::string> seen;
  for (const auto& t : o.takes) {
    if (!is_performance_script(t)) throw Error("takes: unknown performance script '" + t + "' (known: expressions, speech, freestyle)");
    if (!seen.insert(t).second) throw Error("takes: '" + t + "' is listed twice");
  }
  for (const auto& t : o.test_takes)
    if (!seen.count(t)) throw Error("test_takes: '" + t + "' is not one of takes");
  if (o.test_takes.size() >= o.takes.size()) throw Error("test_takes must leave at least one take for training");
  if (o.noise_sigma < 0 || o.wrinkle_depth_m < 0 || o.crease_darkening < 0)
    throw Error("noise_sigma, wrinkle_depth_m and crease_darkening must not be negative");
  validate_tracking_error_options(o.tracking_error);
  const SelfShadowOptions& shadows = o.self_shadowing;
  if (shadows.map_size < 64 || shadows.map_size > 8192) throw Error("self_shadowing.map_size must be in 64 .. 8192");
  if (!(shadows.softness_m >= 0 && shadows.softness_m <= 0.05))
    throw Error("self_shadowing.softness_m must be in 0 .. 0.05 metres");
  const ExpressionSpecularOptions& specular = o.expression_specular;
  for (const auto& [name, value] : {std::pair{"stretch_exponent", specular.stretch_exponent},
                                    std::pair{"crease_matte", specular.crease_matte},
                                    std::pair{"wet_lips", specular.wet_lips}})
    if (!(value >= 0 && value <= 10))
      throw Error(std::string("expression_specular.") + name + " must be in 0 .. 10");
}

Head make_head(const Options& o) {
  Head head = o.head.empty() ? make_procedural_head()
                             : load_head(o.head, o.head_metres_per_unit, o.head_eyeball_polygons);
  if (!o.head_identity.empty() || o.head_shape_detail_m > 0)
    make_subject(head, o.head_identity, o.head_shape_detail_m, uint64_t(o.seed));
  return head;
}

SynthSummary render_virtual_studio(const Options& o, const std::filesystem::path& out, bool replace_existing) {
  const auto start = std::chrono::steady_clock::now();
  validate_options(o);
  // The truth is committed before the capture, so a capture that exists always has its truth.
  std::optional<StagedDirectory> staged_truth;
  if (o.truth_apart) staged_truth.emplace(truth_directory(out), replace_existing);
  StagedDirectory staged(out, replace_existing);
  const std::filesystem::path root = staged.path();
  const std::filesystem::path truth = staged_truth ? staged_truth->path() : root;

  const Head head = make_head(o);
  const FineMeshMaker maker(head, {o.fine_subdivisions, o.wrinkle_depth_m, o.crease_darkening});
  const Rig rig = make_studio_rig(o.studio);
  const Appearance appearance(uint64_t(o.seed));
  const Backdrop backdrop(uint64_t(o.seed));
  const HeadShader shader(head, maker, appearance, o.self_shadowing, o.expression_specular);
  const TrackingError tracking_error(head, o.tracking_error, uint64_t(o.seed));
  ThreadPool pool(o.threads);
  spdlog::info("synth: {} head ({} vertices, {} fine triangles), {} cameras at {}x{}", head.source,
               head.model.num_vertices(), maker.fine_topology().num_faces(), rig.cameras.size(), o.studio.width,
               o.studio.height);

  const bool calibration = o.calibration_frames > 0 && charuco_texture_available();
  if (o.calibration_frames > 0 && !calibration)
    spdlog::warn("synth: built without OpenCV: the calibration take is skipped");
  const int n_cameras = static_cast<int>(rig.cameras.size());
  const int64_t total = n_cameras * (1 + (calibration ? o.calibration_frames : 0) +
                                     int64_t(o.frames) * static_cast<int64_t>(o.takes.size()));
  Progress progress("synth", total, "images");

  std::vector<ImageF> backgrounds(n_cameras);
  std::vector<PinholeLookup> lens(n_cameras);
  pool.parallel_for(0, n_cameras, [&](int64_t c) {
    backgrounds[c] = backdrop.render(rig.cameras[c]);
    lens[c] = pinhole_lookup(rig.cameras[c]);
  });
  const Studio studio{o,           root, truth, head, maker,    rig,     appearance,
                      shader,      backgrounds, lens, pool, progress, tracking_error};

  write_rig_json(rig, truth / "rig.json");
  write_head_ground_truth(truth / "ground_truth" / "head", head, maker);

  SynthSummary summary;
  summary.root = out;
  summary.head = head.source;
  summary.cameras = n_cameras;
  summary.width = o.studio.width;
  summary.height = o.studio.height;
  summary.calibration_skipped = o.calibration_frames > 0 && !calibration;

  render_clean_plate(studio);
  summary.takes.push_back({"clean_plate", "clean_plate", 1});
  if (calibration) {
    render_calibration(studio, "calibration");
    summary.takes.push_back({"calibration", "calibration", o.calibration_frames});
  }

  Dataset dataset;
  dataset.root = truth / "dataset";
  dataset.rig = rig;
  for (Camera& cam : dataset.rig.cameras) cam.distortion = {};  // its images are undistorted
  dataset.template_mesh = head.model.neutral;
  dataset.eyeball_faces = head.eyeball_faces;
  dataset.landmark_vertices = head.landmark_vertices;
  nlohmann::json tracking_error_frames = nlohmann::json::array();
  for (const auto& take : o.takes) {
    std::vector<DatasetFrame> frames;
    render_performance(studio, take, dataset, frames, tracking_error_frames);
    const bool test = std::find(o.test_takes.begin(), o.test_takes.end(), take) != o.test_takes.end();
    for (const auto& f : frames) (test ? dataset.test : dataset.train).frames.push_back(f.id);
    dataset.frames.insert(dataset.frames.end(), frames.begin(), frames.end());
    summary.takes.push_back({take, "performance", o.frames});
  }
  dataset.test.cameras = spread_test_cameras(rig, o.test_cameras);
  for (const auto& name : rig.camera_names())
    if (std::find(dataset.test.cameras.begin(), dataset.test.cameras.end(), name) == dataset.test.cameras.end() ||
        n_cameras == 1)
      dataset.train.cameras.push_back(name);
  write_dataset_manifest(dataset);
  // The dataset's meshes are not the truth: say so beside them, and in capture.json.
  nlohmann::json tracking_error_json;
  if (tracking_error.enabled()) {
    const TrackingErrorOptions& t = o.tracking_error;
    tracking_error_json = {{"offset_m", t.offset_m},           {"offset_scale", t.offset_scale},
                           {"offset_bumps", t.offset_bumps},   {"period_frames", t.period_frames},
                           {"lag", t.lag},                     {"lag_pose", t.lag_pose},
                           {"eyelid_misfit", t.eyelid_misfit}, {"eyelid_gain", t.eyelid_gain},
                           {"lip_misfit", t.lip_misfit},       {"lip_gain", t.lip_gain}};
    write_text_atomic(dataset.root / "tracking_error.json",
                      nlohmann::json{{"note", "meshes/ are perturbed by tega synth's tracking-error model "
                                              "(docs/virtual-studio.md#tracking-errors); the images and "
                                              "ground_truth/ are the true head's"},
                                     {"seed", o.seed},
                                     {"options", tracking_error_json},
                                     {"frames", tracking_error_frames}}
                              .dump(2) + "\n");
  }
  progress.finish();

  nlohmann::json takes = nlohmann::json::array();
  for (const auto& t : summary.takes) takes.push_back({{"name", t.name}, {"kind", t.kind}, {"frames", t.frames}});
  nlohmann::json capture = {
      {"format", "tega-capture"},
      {"version", 1},
      {"generator", std::string("tega synth ") + TEGA_VERSION},
      {"seed", o.seed},
      {"head", head.source},
      {"cameras", rig.camera_names()},
      {"width", o.studio.width},
      {"height", o.studio.height},
      {"takes", takes},
      {"calibration_skipped", summary.calibration_skipped},
      {"options", options_to_yaml(o)}};
  if (tracking_error.enabled())
    capture.update({{"dataset_meshes", "perturbed by tracking_error (dataset/tracking_error.json)"},
                    {"tracking_error", tracking_error_json}});
  // A raw capture names no rig: a stage that is not given the calibrated one
  // fails on the missing rig.json instead of reading the truth.
  if (!o.truth_apart) capture.update({{"rig", "rig.json"}, {"ground_truth", "ground_truth"}, {"dataset", "dataset"}});
  write_text_atomic(root / "capture.json", capture.dump(2) + "\n");
  if (staged_truth) staged_truth->commit();
  staged.commit();

  summary.images = total;
  summary.dataset_frames = static_cast<int>(dataset.frames.size());
  summary.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return summary;
}

}  // namespace tega::synth
