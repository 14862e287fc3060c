#include "tega/tools/evaluate.h"
#include <ATen/core/grad_mode.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <optional>

#include "async_images.h"
#include "tega/core/error.h"
#include "tega/core/files.h"
#include "tega/core/progress.h"
#include "tega/tools/closeups.h"
#include "tega/tools/landmarks.h"
#include "tega/tools/metrics.h"
#include "tega/trainer/render.h"

namespace tega::tools {

namespace fs = std::filesystem;

const std::vector<std::string>& metric_names() {
  static const std::vector<std::string> names = [] {
    std::vector<std::string> out{"landmark_px",    "landmark_drift_px", "lpips",       "ssim",
                                 "psnr",           "l1",                "ssim_masked", "psnr_masked",
                                 "l1_masked",      "hf_psnr_masked",    "gradient_error_masked",
                                 "psnr_background"};
    out.insert(out.end(), closeup_metric_names().begin(), closeup_metric_names().end());
    return out;
  }();
  return names;
}

std::vector<SplitViews> evaluation_views(const Dataset& dataset, const std::string& split) {
  const auto cross = [&](const std::string& name, const DatasetSplit& frames, const DatasetSplit& cameras) {
    SplitViews s{name, {}};
    for (const auto& f : frames.frames)
      for (const auto& c : cameras.cameras)
        if (dataset.has_image(c, f)) s.views.push_back({f, c});  // the dataset's missing_images have no truth
    if (s.views.empty())
      throw Error(dataset.root / "dataset.json", "the " + name + " split has no view (no frame or no camera)");
    return s;
  };
  if (split == "test") return {cross("reenactment", dataset.test, dataset.train), cross("novel_view", dataset.train, dataset.test)};
  if (split == "train") return {cross("train", dataset.train, dataset.train)};
  throw Error("evaluation split '" + split + "': use test (reenactment and novel view) or train");
}

std::vector<SplitResult> evaluate_avatar(trainer::TrainedAvatar& avatar, const Dataset& dataset,
                                         const std::string& split, const Lpips* lpips,
                                         const LandmarkPredictor* landmark_predictor) {
  // Close-ups and the detector's face box need the 68 points of the markup, in its order.
  const bool markup = dataset.landmark_vertices.size() == kMarkupLandmarks;
  if (landmark_predictor && !markup)
    throw Error(dataset.root / "dataset.json",
                "the landmark predictor's face box needs the 68 landmark_vertices of the Multi-PIE markup; the "
                "dataset defines " + std::to_string(dataset.landmark_vertices.size()));
  const std::vector<SplitViews> splits = evaluation_views(dataset, split);
  const at::Device device = avatar.model.device();
  const at::Tensor background = at::tensor(avatar.options.background, at::kFloat).to(device);
  std::optional<LandmarkProbe> landmarks;
  if (!dataset.landmark_vertices.empty()) landmarks.emplace(dataset, avatar.model);
  std::optional<Lpips> lpips_here;
  if (lpips) lpips_here = lpips->to(device);

  std::vector<fs::path> files;
  for (const auto& s : splits)
    for (const EvalView& view : s.views) files.push_back(dataset.image_path(view.camera, view.frame));
  detail::ImagePrefetcher images(files);
  Progress progress("eval", static_cast<int64_t>(files.size()), "views");
  at::NoGradGuard no_grad;
  std::vector<SplitResult> results;
  for (const SplitViews& s : splits) {
    SplitResult result{s.name, {}};
    std::string current_frame;
    trainer::FrameInput input;
    Vertices vertices;
    at::Tensor reference_landmarks, avatar_landmarks;
    for (const EvalView& view : s.views) {
      if (view.frame != current_frame) {
        current_frame = view.frame;
        vertices = dataset.load_mesh(view.frame);
        input = avatar.model.frame_input(vertices, dataset.frame(view.frame).head_to_world);
        if (landmarks) {
          reference_landmarks = landmarks->reference(vertices);
          avatar_landmarks = landmarks->avatar(avatar.model, input, avatar.phase);
        }
      }
      const Camera& camera = dataset.rig.camera(view.camera);
      const fs::path file = dataset.image_path(view.camera, view.frame);
      const at::Tensor rgba = images.next().to(device);
      if (rgba.size(0) != camera.height || rgba.size(1) != camera.width)
        throw Error(file, "is " + std::to_string(rgba.size(1)) + "x" + std::to_string(rgba.size(0)) + ", camera " +
                              view.camera + " is " + std::to_string(camera.width) + "x" + std::to_string(camera.height));
      const at::Tensor target = trainer::composite_target(rgba, background);
      const at::Tensor mask = rgba.select(2, 3).gt(127);  // alpha > 0.5
      const at::Tensor rendered =
          trainer::render_view(avatar.model, input, camera, avatar.phase, background, avatar.options.antialiased)
              .clamp(0.0, 1.0);

      ViewResult v{view.camera, view.frame, {}};
      const ErrorMaps maps = error_maps(rendered, target);
      const MaskedMetrics head = masked_metrics(maps, mask);
      v.metrics["psnr"] = psnr(rendered, target);
      v.metrics["ssim"] = maps.ssim.mean().item<double>();
      v.metrics["l1"] = l1(rendered, target);
      v.metrics["psnr_masked"] = head.psnr;
      v.metrics["ssim_masked"] = head.ssim;
      v.metrics["l1_masked"] = l1(rendered, target, mask);
      v.metrics["hf_psnr_masked"] = head.hf_psnr;
      v.metrics["gradient_error_masked"] = head.gradient_error;
      v.metrics["psnr_background"] = masked_psnr(maps.squared_error, mask.logical_not());
      if (lpips_here) v.metrics["lpips"] = (*lpips_here)(rendered, target);
      if (landmarks) v.metrics["landmark_drift_px"] = landmark_drift_px(reference_landmarks, avatar_landmarks, camera);
      if (markup) {
        const std::vector<std::optional<Eigen::Vector2d>> projected = project_landmarks(reference_landmarks, camera);
        v.metrics.merge(closeup_metrics(maps, mask, projected));
        if (landmark_predictor) {
          const std::optional<Eigen::AlignedBox2d> box = landmark_detection_box(projected);
          v.metrics["landmark_px"] = box ? detected_landmark_error_px(*landmark_predictor, rendered, target, *box)
                                         : std::numeric_limits<double>::quiet_NaN();
        }
      }
      result.views.push_back(std::move(v));
      progress.advance();
    }
    results.push_back(std::move(result));
  }
  progress.finish();
  return results;
}

EvalNotes evaluation_notes(const Dataset& dataset, bool lpips, const fs::path& landmark_predictor) {
  EvalNotes notes;
  if (!lpips)
    notes.lpips = "LPIPS skipped: no VGG/LPIPS weight files were given (--lpips-vgg, --lpips-lin; "
                  "docs/render-eval-export.md#lpips-weights)";
  if (landmark_predictor.empty())
    notes.landmark_px = "landmark_px skipped: no landmark predictor was given (--landmark-predictor, a dlib 68-point "
                        "shape predictor; docs/render-eval-export.md#landmarks)";
  else
    notes.landmark_px = "landmark_px: mean distance in pixels over the 68 landmarks that the predictor " +
                        landmark_predictor.string() +
                        " finds on the render and on the ground truth, both in the same box (the tracked mesh's "
                        "landmark vertices projected, their bounding box grown by 15 %); NaN where a landmark "
                        "vertex is behind the camera";
  notes.landmark_drift_px =
      dataset.landmark_vertices.empty()
          ? "landmark_drift_px skipped: the dataset defines no landmark_vertices"
          : "landmark_drift_px: mean pixel distance between the tracked mesh's landmark vertices and the avatar's "
            "deformed landmark points (F + R_head D at the vertex's uv, d = 0), both projected; it measures how far "
            "the deformation field moves the landmarks off the tracked surface, a diagnostic of the field, not the "
            "paper's detector-based landmark error (landmark_px)";
  char closeup_note[512];
  std::snprintf(closeup_note, sizeof closeup_note,
                "closeup_eyes_* and closeup_mouth_*: psnr, ssim, hf_psnr and gradient_error inside the head mask "
                "within boxes around the eyes (two boxes) and the mouth at the dataset's resolution; a box is the "
                "bounding box of the part's projected landmark vertices, every side moved out by %.0f %% of its "
                "longer side, at least %d px a side, clipped to the image",
                100 * kCloseupMargin, kCloseupMinimumSide);
  notes.closeups = dataset.landmark_vertices.size() == kMarkupLandmarks
                       ? std::string(closeup_note)
                       : "close-ups skipped: the dataset's landmark_vertices are not the 68 of the Multi-PIE markup "
                         "(it defines " + std::to_string(dataset.landmark_vertices.size()) + ")";
  return notes;
}

namespace {

const char* const kDetailNote =
    "hf_psnr_masked: PSNR (peak 1) of the high-frequency band, the image minus its Gaussian blur (sigma 1.5 px); "
    "gradient_error_masked: mean absolute difference of the per-channel Sobel gradient magnitudes (intensity per "
    "pixel). Both inside the head mask: they score the fine detail (wrinkles, hair, sharp edges) that LPIPS and "
    "close-ups show and PSNR barely weighs";

const char* const kBackgroundNote =
    "psnr_background: PSNR (peak 1) outside the head mask (alpha <= 0.5), where the truth shows only the "
    "background: what a model draws there (floaters, haze, a silhouette grown too wide) counts here and barely "
    "in the masked metrics; NaN for a view whose matte is opaque everywhere";

nlohmann::json number(double v) {
  if (std::isnan(v)) return "nan";
  if (std::isinf(v)) return v > 0 ? "inf" : "-inf";
  return v;
}

nlohmann::json stats_json(const std::vector<const ViewResult*>& views) {
  nlohmann::json out = nlohmann::json::object();
  for (const auto& name : metric_names()) {
    std::vector<double> values;
    for (const ViewResult* v : views)
      if (const auto it = v->metrics.find(name); it != v->metrics.end()) values.push_back(it->second);
    if (values.empty()) continue;
    const Statistics s = statistics(values);
    out[name] = {{"mean", number(s.mean)}, {"std", number(s.std)}, {"count", s.count}};
    if (s.skipped > 0) out[name]["undefined"] = s.skipped;
  }
  return out;
}

nlohmann::json grouped(const SplitResult& split, const std::string ViewResult::*key) {
  std::map<std::string, std::vector<const ViewResult*>> groups;
  for (const ViewResult& v : split.views) groups[v.*key].push_back(&v);
  nlohmann::json out = nlohmann::json::object();
  for (const auto& [name, views] : groups) out[name] = {{"views", views.size()}, {"metrics", stats_json(views)}};
  return out;
}

const SplitResult* find_split(const ModelResult& model, const std::string& name) {
  for (const auto& s : model.splits)
    if (s.name == name) return &s;
  return nullptr;
}

struct MetricColumn {
  const char* title;
  int digits;
};

MetricColumn metric_column(const std::string& metric) {
  static const std::map<std::string, MetricColumn> columns{
      {"landmark_px", {"Landmark px ↓", 1}},  {"landmark_drift_px", {"Landmark drift px ↓", 1}},
      {"lpips", {"LPIPS ↓", 3}},
      {"ssim", {"SSIM ↑", 3}},                {"psnr", {"PSNR ↑", 2}},
      {"l1", {"L1 ↓", 4}},                    {"ssim_masked", {"SSIM ↑", 3}},
      {"psnr_masked", {"PSNR ↑", 2}},         {"l1_masked", {"L1 ↓", 4}},
      {"hf_psnr_masked", {"HF PSNR ↑", 2}},   {"gradient_error_masked", {"Gradient error ↓", 4}},
      {"psnr_background", {"PSNR ↑", 2}}};
  if (const auto it = columns.find(metric); it != columns.end()) return it->second;
  // closeup_<region>_<metric>: the region's table titles its columns as the masked metric's.
  for (const CloseupRegion& region : closeup_regions()) {
    const std::string prefix = "closeup_" + region.name + "_";
    if (metric.starts_with(prefix)) return columns.at(metric.substr(prefix.size()) + "_masked");
  }
  return columns.at(metric);
}

std::string cell(const SplitResult* split, const std::string& metric) {
  if (!split) return "—";
  std::vector<double> values;
  for (const ViewResult& v : split->views)
    if (const auto it = v.metrics.find(metric); it != v.metrics.end()) values.push_back(it->second);
  if (values.empty()) return "—";
  const Statistics s = statistics(values);
  const auto fmt = [&](double x) -> std::string {
    if (std::isnan(x)) return "nan";
    if (std::isinf(x)) return x > 0 ? "∞" : "-∞";
    const int digits = metric_column(metric).digits;
    char text[64];
    std::snprintf(text, sizeof text, "%.*f", digits, x);
    return text;
  };
  return fmt(s.mean) + " ± " + fmt(s.std);
}

std::string split_title(const std::string& name) {
  if (name == "reenactment") return "Test reenactment";
  if (name == "novel_view") return "Novel view";
  return "Train views";
}

std::string table(const std::vector<ModelResult>& models, const std::vector<std::string>& metrics) {
  std::vector<std::string> split_names;
  for (const auto& m : models)
    for (const auto& s : m.splits)
      if (std::find(split_names.begin(), split_names.end(), s.name) == split_names.end()) split_names.push_back(s.name);
  std::string header = "| model |", rule = "| --- |";
  for (const auto& split : split_names)
    for (const auto& metric : metrics) {
      header += " " + split_title(split) + " " + metric_column(metric).title + " |";
      rule += " --- |";
    }
  std::string out = header + "\n" + rule + "\n";
  for (const auto& m : models) {
    out += "| " + m.name + " |";
    for (const auto& split : split_names)
      for (const auto& metric : metrics) out += " " + cell(find_split(m, split), metric) + " |";
    out += "\n";
  }
  return out;
}

}  // namespace

nlohmann::json evaluation_json(const std::vector<ModelResult>& models, const EvalNotes& notes) {
  nlohmann::json doc = {{"format", "tega-eval"}, {"version", 1}};
  doc["notes"] = {{"lpips", notes.lpips.empty() ? "lpips: evaluated (lpips vgg v0.1)" : notes.lpips},
                  {"landmark_px", notes.landmark_px},
                  {"landmark_drift_px", notes.landmark_drift_px},
                  {"closeups", notes.closeups},
                  {"masked", "*_masked metrics are computed inside the head mask: the dataset image's alpha > 0.5"},
                  {"background", kBackgroundNote},
                  {"detail", kDetailNote},
                  {"statistics", "mean and population standard deviation over views; NaN values (an empty mask) are "
                                 "counted under 'undefined' and left out"}};
  for (const auto& m : models) {
    nlohmann::json model = {{"name", m.name}, {"run", m.run.string()}, {"iteration", m.iteration},
                            {"gaussians", m.gaussians}};
    for (const auto& split : m.splits) {
      std::vector<const ViewResult*> all;
      for (const auto& v : split.views) all.push_back(&v);
      nlohmann::json views = nlohmann::json::array();
      for (const auto& v : split.views) {
        nlohmann::json metrics = nlohmann::json::object();
        for (const auto& [name, value] : v.metrics) metrics[name] = number(value);
        views.push_back({{"camera", v.camera}, {"frame", v.frame}, {"metrics", metrics}});
      }
      model["splits"][split.name] = {{"views", split.views.size()},
                                     {"metrics", stats_json(all)},
                                     {"per_camera", grouped(split, &ViewResult::camera)},
                                     {"per_frame", grouped(split, &ViewResult::frame)},
                                     {"per_view", views}};
    }
    doc["models"].push_back(model);
  }
  return doc;
}

std::string evaluation_markdown(const std::vector<ModelResult>& models, const EvalNotes& notes) {
  std::string out = "# Evaluation (TeGA §5 protocol)\n\n";
  out += "Test reenactment: held-out frames from the training cameras. Novel view: training frames from the "
         "held-out cameras. Mean ± std over views.\n\n## Full image\n\n";
  out += table(models, {"landmark_px", "landmark_drift_px", "lpips", "ssim", "psnr", "l1"});
  out += "\n## Inside the head mask (alpha > 0.5)\n\n";
  out += table(models, {"ssim_masked", "psnr_masked", "l1_masked", "hf_psnr_masked", "gradient_error_masked"});
  out += "\n## Outside the head mask (alpha <= 0.5): the background\n\n";
  out += table(models, {"psnr_background"});
  for (const CloseupRegion& region : closeup_regions()) {
    const std::string prefix = "closeup_" + region.name + "_";
    out += "\n## Close-up: " + region.name + ", inside the head mask (" + prefix + "*)\n\n";
    out += table(models, {prefix + "ssim", prefix + "psnr", prefix + "hf_psnr", prefix + "gradient_error"});
  }
  out += "\n";
  if (!notes.lpips.empty()) out += "- " + notes.lpips + "\n";
  out += "- " + notes.landmark_px + "\n";
  out += "- " + notes.landmark_drift_px + "\n";
  out += "- " + notes.closeups + "\n";
  out += std::string("- ") + kDetailNote + "\n";
  out += std::string("- ") + kBackgroundNote + "\n";
  return out;
}

void write_evaluation(const std::vector<ModelResult>& models, const EvalNotes& notes, const fs::path& json_file) {
  if (json_file.has_parent_path()) fs::create_directories(json_file.parent_path());
  write_text_atomic(json_file, evaluation_json(models, notes).dump(2) + "\n");
  fs::path markdown = json_file;
  markdown.replace_extension(".md");
  write_text_atomic(markdown, evaluation_markdown(models, notes));
}

}  // namespace tega::tools
