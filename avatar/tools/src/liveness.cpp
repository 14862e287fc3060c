#include "tega/tools/liveness.h"

#include <ATen/ATen.h>
#include <ATen/core/grad_mode.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <map>
#include <set>
#include <utility>

#include "tega/core/error.h"
#include "tega/core/json_file.h"
#include "tega/core/mesh.h"
#include "tega/core/rig.h"

#include "image_tensors.h"
#include "tega/nn/losses.h"
#include "tega/trainer/render.h"

namespace tega::tools {
namespace {

double pearson(const std::vector<double>& x, const std::vector<double>& y) {
  const size_t n = x.size();
  if (n < 2) return std::nan("");
  double mx = 0, my = 0;
  for (size_t i = 0; i < n; ++i) mx += x[i] / double(n), my += y[i] / double(n);
  double sxy = 0, sxx = 0, syy = 0;
  for (size_t i = 0; i < n; ++i) {
    sxy += (x[i] - mx) * (y[i] - my);
    sxx += (x[i] - mx) * (x[i] - mx);
    syy += (y[i] - my) * (y[i] - my);
  }
  return sxx > 0 && syy > 0 ? sxy / std::sqrt(sxx * syy) : std::nan("");
}

double quantile_of(const at::Tensor& values, double q) {
  return values.numel() == 0 ? 0.0 : at::quantile(values.to(at::kFloat), q).item<double>();
}

// Mean distance (mm) of a tracked mesh from the neutral template, in head space.
double expression_mm(const Vertices& world, const RigidTransform& head_to_world, const Mesh& neutral) {
  double sum = 0;
  for (int v = 0; v < world.rows(); ++v) {
    const Eigen::Vector3d head = head_to_world.R.transpose() * (world.row(v).cast<double>().transpose() - head_to_world.t);
    sum += (head - neutral.positions.row(v).cast<double>().transpose()).norm();
  }
  return 1000.0 * sum / std::max<int64_t>(1, world.rows());
}

// The identity where the dataset's cameras stand where the truth's do (tega synth's own dataset),
// else the camera centres' best fit (a calibrated rig's world).
RigidTransform truth_to_dataset_world(const Rig& truth, const Rig& dataset) {
  bool same_world = true;
  for (const Camera& camera : dataset.cameras) {
    const auto match = std::find_if(truth.cameras.begin(), truth.cameras.end(),
                                    [&](const Camera& c) { return c.name == camera.name; });
    same_world = same_world && match != truth.cameras.end() && (match->center() - camera.center()).norm() < 1e-9;
  }
  return same_world ? RigidTransform{} : align_camera_centres(truth, dataset);
}

// The true coarse mesh and head pose of a dataset frame of a virtual-studio
// capture: ground_truth/<take>/frames.json and the coarse meshes it names
// (docs/virtual-studio.md#takes), for dataset frames named <take>_<frame>,
// in the dataset's topology and world. A dataset the raw chain built has
// neither: its meshes are the head model's, of which the studio's template
// keeps some vertices (head.json's source_vertex_runs; the model's see-through
// eye overlays are left out, and keep the dataset's own positions), and its
// rig is calibrated in a world of its own, which the camera centres tie to the
// truth's (align_camera_centres).
class TrueMeshes {
 public:
  TrueMeshes(const std::filesystem::path& capture, const Dataset& dataset)
      : root_(capture / "ground_truth"), vertices_(int(dataset.template_mesh.num_vertices())) {
    if (!std::filesystem::is_directory(root_))
      throw Error(capture, "no ground_truth/ folder: --truth takes a tega synth capture (with truth_apart, its "
                           "CAPTURE.truth/)");
    const std::filesystem::path head = root_ / "head" / "head.json";
    if (std::filesystem::exists(head)) {
      const nlohmann::json runs = read_json_file(head).value("source_vertex_runs", nlohmann::json::array());
      for (const auto& run : runs)
        for (int v = run.at(0).get<int>(); v <= run.at(1).get<int>(); ++v) model_vertex_.push_back(v);
    }
    to_dataset_ = truth_to_dataset_world(read_rig_json(capture / "rig.json"), dataset.rig);
  }

  // `dataset_vertices`: the frame's mesh in the dataset, which fills what the truth lacks.
  std::pair<Vertices, RigidTransform> frame(const DatasetFrame& f, const Vertices& dataset_vertices) {
    const std::filesystem::path file = root_ / f.sequence / "frames.json";
    const std::string prefix = f.sequence + "_";
    const std::string number = f.id.substr(std::min(prefix.size(), f.id.size()));
    if (f.sequence.empty() || f.id.rfind(prefix, 0) != 0 || number.size() != 6 ||
        number.find_first_not_of("0123456789") != std::string::npos)
      throw Error(root_, "dataset frame '" + f.id + "' is not <take>_<6-digit frame> of a virtual-studio take");
    const nlohmann::json& take = take_of(file);
    const int index = std::stoi(number);
    const auto frames = take.find("frames");
    if (frames == take.end() || !frames->is_array()) throw Error(file, "has no frames array");
    for (const auto& entry : *frames) {
      if (entry.value("index", -1) != index) continue;
      Eigen::Matrix<double, 3, 4> pose;
      try {
        for (int r = 0; r < 3; ++r)
          for (int c = 0; c < 4; ++c) pose(r, c) = entry.at("head_to_world").at(r).at(c).get<double>();
      } catch (const nlohmann::json::exception&) {
        throw Error(file, "frame " + number + ": head_to_world must be 3 rows of 4 numbers");
      }
      std::string coarse = take.value("coarse", "");
      const std::string slot = "{frame:06d}";
      if (coarse.find(slot) == std::string::npos) throw Error(file, "no coarse mesh pattern with " + slot);
      coarse.replace(coarse.find(slot), slot.size(), number);
      return {in_dataset(file.parent_path() / coarse, dataset_vertices),
              to_dataset_ * RigidTransform::from_matrix(pose)};
    }
    throw Error(file, "no frame " + number + " (dataset frame '" + f.id + "')");
  }

 private:
  Vertices in_dataset(const std::filesystem::path& mesh, const Vertices& dataset_vertices) const {
    const Vertices truth = read_vertices_bin(mesh);
    const auto moved = [&](int v) {
      return to_dataset_.apply(truth.row(v).transpose().cast<double>()).cast<float>().transpose().eval();
    };
    if (truth.rows() == vertices_) {
      Vertices out(truth.rows(), 3);
      for (int v = 0; v < truth.rows(); ++v) out.row(v) = moved(v);
      return out;
    }
    const bool mapped = int(model_vertex_.size()) == truth.rows() && !model_vertex_.empty() &&
                        *std::max_element(model_vertex_.begin(), model_vertex_.end()) < vertices_;
    if (!mapped)
      throw Error(mesh, "has " + std::to_string(truth.rows()) + " vertices, the dataset's meshes " +
                            std::to_string(vertices_) + ", and head.json's source_vertex_runs do not map one to "
                            "the other: --truth needs the studio that rendered the dataset's capture");
    Vertices out = dataset_vertices;
    for (int v = 0; v < truth.rows(); ++v) out.row(model_vertex_[size_t(v)]) = moved(v);
    return out;
  }

  const nlohmann::json& take_of(const std::filesystem::path& file) {
    auto found = takes_.find(file);
    return found != takes_.end() ? found->second : takes_[file] = read_json_file(file);
  }

  std::filesystem::path root_;
  int vertices_;
  std::vector<int> model_vertex_;  // the model's vertex of each of the studio template's
  RigidTransform to_dataset_;      // the truth's world to the dataset's
  std::map<std::filesystem::path, nlohmann::json> takes_;
};

// A frame's mean over Gaussians of the squared error (m²), without and with the field.
struct FrameSquares {
  double mesh = 0;
  std::optional<double> corrected;
};

// One split's errors against the truth: the whole error as sums of per-frame
// mean squared distances (m²), and each Gaussian's error vectors (head space)
// summed over frames, whose mean the frame-to-frame part leaves out.
class SplitErrors {
 public:
  FrameSquares add(const at::Tensor& mesh_error, const std::optional<at::Tensor>& corrected_error) {
    ++frames_;
    FrameSquares out{mesh_.add(mesh_error), std::nullopt};
    if (corrected_error) out.corrected = corrected_.add(*corrected_error);
    return out;
  }
  std::optional<double> undone() const { return share_undone(mesh_.squares, corrected_.squares); }
  std::optional<double> varying_mm() const {
    if (frames_ < 2) return std::nullopt;
    return 1000.0 * std::sqrt(mesh_.varying(frames_) / frames_);
  }
  std::optional<double> varying_undone() const {
    if (frames_ < 2 || !corrected_.sum.defined()) return std::nullopt;
    return share_undone(mesh_.varying(frames_), corrected_.varying(frames_));
  }

 private:
  struct Sums {
    double squares = 0;  // Σ over frames of the mean over Gaussians of |e|²
    at::Tensor sum;      // [N,3] double: Σ over frames of e
    double add(const at::Tensor& e) {  // returns the frame's mean over Gaussians of |e|²
      const double frame = e.pow(2).sum(1).mean().item<double>();
      squares += frame;
      sum = sum.defined() ? sum + e : e;
      return frame;
    }
    // Σ over frames of the mean over Gaussians of |e - ē|².
    double varying(int frames) const { return squares - (sum / frames).pow(2).sum(1).mean().item<double>() * frames; }
  };
  static std::optional<double> share_undone(double error, double corrected) {
    if (error <= 1e-18) return std::nullopt;
    return 1.0 - std::sqrt(std::max(corrected, 0.0) / error);
  }
  int frames_ = 0;
  Sums mesh_, corrected_;
};

// Each Gaussian's spread over frames of a per-frame value x [N,k]: the root
// mean square over frames of |x - x̄|, averaged over Gaussians.
class FrameSpread {
 public:
  void add(const at::Tensor& x) {
    const at::Tensor rows = x.to(at::kDouble).view({x.size(0), -1});
    sum_ = sum_.defined() ? sum_ + rows : rows;
    squares_ = squares_.defined() ? squares_ + rows.pow(2).sum(1) : rows.pow(2).sum(1);
    ++frames_;
  }
  double mean_over_gaussians() const {
    if (frames_ == 0) return 0.0;
    const at::Tensor mean = sum_ / double(frames_);
    return (squares_ / double(frames_) - mean.pow(2).sum(1)).clamp_min(0).sqrt().mean().item<double>();
  }

 private:
  at::Tensor sum_, squares_;
  int frames_ = 0;
};

// The network part a parameter belongs to, by its registered path.
std::string network_part(const std::string& name) {
  const std::string head = name.substr(0, name.find('.'));
  return "network." + (head == "unet" || head == "global" ? std::string("encoder") : head);
}

void clear_gradients(trainer::AvatarModel& model) {
  for (const auto& name : trainer::Gaussians::parameter_names()) model.gaussians.parameter(name).mutable_grad() = at::Tensor();
  for (auto& parameter : model.network->parameters()) parameter.mutable_grad() = at::Tensor();
}

std::vector<PartGradient> part_gradients(trainer::TrainedAvatar& avatar, const Dataset& dataset, int views) {
  trainer::AvatarModel& model = avatar.model;
  std::vector<std::pair<std::string, std::string>> pairs;  // (frame, camera) with an image
  for (const auto& frame : dataset.train.frames)
    for (const auto& camera : dataset.train.cameras)
      if (dataset.has_image(camera, frame)) pairs.emplace_back(frame, camera);
  if (pairs.empty() || views <= 0) return {};
  const size_t count = std::min<size_t>(pairs.size(), size_t(views));
  const at::Tensor background = at::tensor(avatar.options.background, at::kFloat).to(model.device());

  std::map<std::string, double> sums;
  const auto parameters = model.network->named_parameters(/*recurse=*/true);
  // Gaussians built in code rather than loaded may not track gradients.
  std::vector<bool> tracked;
  for (const auto& name : trainer::Gaussians::parameter_names()) {
    at::Tensor& p = model.gaussians.parameter(name);
    tracked.push_back(p.requires_grad());
    p.requires_grad_(true);
  }
  for (size_t i = 0; i < count; ++i) {
    const auto& [frame, camera_name] = pairs[i * pairs.size() / count];
    clear_gradients(model);

    const trainer::FrameInput input = model.frame_input(dataset.load_mesh(frame), dataset.frame(frame).head_to_world);
    const Camera& camera = dataset.rig.camera(camera_name);
    const at::Tensor rendered =
        trainer::render_view(model, input, camera, avatar.phase, background, avatar.options.antialiased);
    const at::Tensor target = trainer::composite_target(
        detail::read_rgba(dataset.image_path(camera_name, frame)).to(model.device()), background);
    const at::Tensor loss = avatar.options.loss.l1 * nn::l1_image_loss(rendered, target) +
                            avatar.options.loss.dssim * nn::dssim_loss(rendered, target);
    loss.backward();

    for (const auto& name : trainer::Gaussians::parameter_names()) {
      const at::Tensor& grad = model.gaussians.parameter(name).grad();
      sums["gaussians." + name] += grad.defined() ? grad.norm().item<double>() : 0.0;
    }
    std::map<std::string, double> squares;
    for (const auto& item : parameters) {
      const at::Tensor& grad = item.value().grad();
      squares[network_part(item.key())] += grad.defined() ? grad.pow(2).sum().item<double>() : 0.0;
    }
    for (const auto& [part, square] : squares) sums[part] += std::sqrt(square);
  }
  clear_gradients(model);
  for (size_t i = 0; i < tracked.size(); ++i)
    model.gaussians.parameter(trainer::Gaussians::parameter_names()[i]).requires_grad_(tracked[i]);

  std::vector<PartGradient> out;
  for (const auto& [part, sum] : sums) out.push_back({part, sum / double(count)});
  return out;
}

}  // namespace

Liveness inspect_avatar(trainer::TrainedAvatar& avatar, const Dataset& dataset, const LivenessOptions& options) {
  trainer::AvatarModel& model = avatar.model;
  const trainer::Gaussians& g = model.gaussians;
  Liveness out;
  out.gaussians = g.size();
  out.iteration = avatar.iteration;
  out.deformation = avatar.phase.deformation;
  out.shading = avatar.phase.shading;
  trainer::Phase without_field = avatar.phase;
  without_field.deformation = false;

  std::vector<double> expression, deformation, shading_change;
  FrameSpread deformation_spread, shading_spread;
  std::optional<TrueMeshes> truth;
  if (!options.truth.empty()) truth.emplace(options.truth, dataset);
  const std::set<std::string> held_out(dataset.test.frames.begin(), dataset.test.frames.end());
  SplitErrors train_errors, test_errors;
  {
    at::NoGradGuard no_grad;
    for (const DatasetFrame& f : dataset.frames) {
      const Vertices vertices = dataset.load_mesh(f.id);
      const trainer::FrameInput input = model.frame_input(vertices, f.head_to_world);
      FrameLiveness frame;
      frame.frame = f.id;
      frame.expression_mm = expression_mm(vertices, f.head_to_world, dataset.template_mesh);
      const at::Tensor placed = model.pose(input, without_field).means;
      const at::Tensor deformed = out.deformation ? model.pose(input, avatar.phase).means : placed;
      if (truth) {
        const auto [true_vertices, true_pose] = truth->frame(f, vertices);
        const at::Tensor target = model.pose(model.frame_input(true_vertices, true_pose), without_field).means;
        // Row vectors to head space: (world - t) R.
        const auto to_head = [&](const at::Tensor& error) { return error.matmul(input.head_rotation).to(at::kDouble); };
        std::optional<at::Tensor> corrected;
        if (out.deformation) corrected = to_head(deformed - target);
        SplitErrors& split = held_out.count(f.id) ? test_errors : train_errors;
        const FrameSquares squares = split.add(to_head(placed - target), corrected);
        frame.mesh_error_mm = 1000.0 * std::sqrt(squares.mesh);
        if (squares.corrected) frame.corrected_error_mm = 1000.0 * std::sqrt(*squares.corrected);
      }
      if (out.deformation) {
        const at::Tensor moved = (deformed - placed).norm(2, 1) * 1000.0;
        const at::Tensor moving = moved.index({moved > 1e-6});  // eyeballs stay put
        frame.deformation_mean_mm = moving.numel() ? moving.mean().item<double>() : 0.0;
        frame.deformation_p95_mm = quantile_of(moving, 0.95);
        // Head space, so that the head's motion is not counted as the field's.
        deformation_spread.add((deformed - placed).matmul(input.head_rotation) * 1000.0);
      }
      if (out.shading) {
        const at::Tensor s = model.network->shade(g.uvd, model.network->encode(input.displacement_texture)).to(at::kDouble);
        frame.shading_p01 = quantile_of(s, 0.01);
        frame.shading_p50 = quantile_of(s, 0.5);
        frame.shading_p99 = quantile_of(s, 0.99);
        shading_spread.add(s.unsqueeze(1));
        shading_change.push_back((s - 1.0).abs().mean().item<double>());
      }
      expression.push_back(frame.expression_mm);
      deformation.push_back(frame.deformation_mean_mm);
      out.frames.push_back(frame);
    }
    out.deformation_expression_r = out.deformation ? pearson(expression, deformation) : std::nan("");
    if (truth) {
      out.varying_error_mm_train = train_errors.varying_mm();
      out.varying_error_mm_test = test_errors.varying_mm();
    }
    if (truth && out.deformation) {
      out.error_undone_train = train_errors.undone();
      out.error_undone_test = test_errors.undone();
      out.varying_error_undone_train = train_errors.varying_undone();
      out.varying_error_undone_test = test_errors.varying_undone();
    }
    out.shading_expression_r = out.shading ? pearson(expression, shading_change) : std::nan("");
    out.deformation_frame_std_mm = deformation_spread.mean_over_gaussians();
    out.shading_frame_std = shading_spread.mean_over_gaussians();
    if (g.birth_triangle.defined() && !g.rigged && !g.bound_triangle.defined()) {
      const at::Tensor now = model.lookup().lookup(g.uvd.detach().slice(1, 0, 2)).triangle;
      out.off_birth_triangle = now.ne(g.birth_triangle).to(at::kDouble).mean().item<double>();
    }
  }
  out.gradients = part_gradients(avatar, dataset, options.gradient_views);
  return out;
}

namespace {

nlohmann::json number(double v) { return std::isfinite(v) ? nlohmann::json(v) : nlohmann::json(nullptr); }

nlohmann::json optional_number(const std::optional<double>& v) { return v ? number(*v) : nlohmann::json(nullptr); }

// Root mean square over frames of a per-frame RMS figure.
double rms_over_frames(const Liveness& l, std::optional<double> FrameLiveness::*figure) {
  double sum = 0;
  for (const auto& f : l.frames) sum += std::pow((f.*figure).value_or(0.0), 2) / double(l.frames.size());
  return std::sqrt(sum);
}

std::string fixed(double v, int digits) {
  if (!std::isfinite(v)) return "n/a";
  char text[64];
  std::snprintf(text, sizeof(text), "%.*f", digits, v);
  const std::string out = text;
  // A value that rounds to zero prints without a sign.
  return out[0] == '-' && out.find_first_not_of("-0.") == std::string::npos ? out.substr(1) : out;
}

std::string scientific(double v) {
  char text[64];
  std::snprintf(text, sizeof(text), "%.3g", v);
  return text;
}

}  // namespace

nlohmann::json liveness_json(const Liveness& l) {
  nlohmann::json frames = nlohmann::json::array();
  for (const auto& f : l.frames)
    frames.push_back({{"frame", f.frame},
                      {"expression_mm", f.expression_mm},
                      {"deformation_mean_mm", f.deformation_mean_mm},
                      {"deformation_p95_mm", f.deformation_p95_mm},
                      {"shading_p01", f.shading_p01},
                      {"shading_p50", f.shading_p50},
                      {"shading_p99", f.shading_p99},
                      {"mesh_error_mm", optional_number(f.mesh_error_mm)},
                      {"corrected_error_mm", optional_number(f.corrected_error_mm)}});
  nlohmann::json gradients = nlohmann::json::object();
  for (const auto& g : l.gradients) gradients[g.part] = g.mean_norm;
  return {{"format", "tega-inspect"},
          {"version", 1},
          {"gaussians", l.gaussians},
          {"iteration", l.iteration},
          {"deformation", l.deformation},
          {"shading", l.shading},
          {"deformation_expression_r", number(l.deformation_expression_r)},
          {"deformation_frame_std_mm", l.deformation ? number(l.deformation_frame_std_mm) : nlohmann::json(nullptr)},
          {"shading_frame_std", l.shading ? number(l.shading_frame_std) : nlohmann::json(nullptr)},
          {"shading_expression_r", number(l.shading_expression_r)},
          {"off_birth_triangle", optional_number(l.off_birth_triangle)},
          {"error_undone_train", optional_number(l.error_undone_train)},
          {"error_undone_test", optional_number(l.error_undone_test)},
          {"varying_error_mm_train", optional_number(l.varying_error_mm_train)},
          {"varying_error_mm_test", optional_number(l.varying_error_mm_test)},
          {"varying_error_undone_train", optional_number(l.varying_error_undone_train)},
          {"varying_error_undone_test", optional_number(l.varying_error_undone_test)},
          {"gradient_norms", gradients},
          {"frames", frames}};
}

std::string liveness_markdown(const Liveness& l, const std::string& name) {
  double deformation_mean = 0, deformation_p95 = 0, s_low = 1, s_high = 1;
  for (const auto& f : l.frames) {
    deformation_mean += f.deformation_mean_mm / double(l.frames.size());
    deformation_p95 = std::max(deformation_p95, f.deformation_p95_mm);
    s_low = std::min(s_low, f.shading_p01);
    s_high = std::max(s_high, f.shading_p99);
  }
  std::string out = "## " + name + " (iteration " + std::to_string(l.iteration) + ", " +
                    std::to_string(l.gaussians) + " Gaussians)\n\n";
  out += l.deformation ? "- deformation field: mean |Δμ| " + fixed(deformation_mean, 3) + " mm over frames, largest p95 " +
                             fixed(deformation_p95, 3) + " mm, per-Gaussian std over frames " +
                             fixed(l.deformation_frame_std_mm, 3) + " mm; r with the expression " +
                             fixed(l.deformation_expression_r, 2) + "\n"
                       : "- deformation field: off\n";
  out += l.shading ? "- dynamic shading: S from " + fixed(s_low, 3) + " to " + fixed(s_high, 3) +
                         " (p1..p99 over frames), per-Gaussian std over frames " + fixed(l.shading_frame_std, 4) +
                         "; r of mean |S - 1| with the expression " + fixed(l.shading_expression_r, 2) + "\n"
                   : "- dynamic shading: off\n";
  out += l.off_birth_triangle ? "- Gaussians off the triangle they were created on: " +
                                    fixed(100.0 * *l.off_birth_triangle, 2) + " %\n"
                              : "- triangle changes: not tracked (bound Gaussians, or a checkpoint without birth triangles)\n";
  if (!l.frames.empty() && l.frames.front().mesh_error_mm) {
    out += "- against the true meshes: the dataset's meshes put the Gaussians " +
           fixed(rms_over_frames(l, &FrameLiveness::mesh_error_mm), 3) + " mm (RMS) from where the true meshes would";
    if (l.error_undone_train || l.error_undone_test) {
      out += "; with the field " + fixed(rms_over_frames(l, &FrameLiveness::corrected_error_mm), 3) + " mm:";
      if (l.error_undone_train) out += " " + fixed(100.0 * *l.error_undone_train, 1) + " % of it undone on training frames";
      if (l.error_undone_train && l.error_undone_test) out += ",";
      if (l.error_undone_test) out += " " + fixed(100.0 * *l.error_undone_test, 1) + " % on held-out frames";
    }
    out += "\n";
    if (l.varying_error_mm_train || l.varying_error_mm_test) {
      out += "- its frame-to-frame part (each Gaussian's mean error over the split's frames removed; the rest the "
             "canonical Gaussians can absorb):";
      const auto split = [&](const std::optional<double>& mm, const std::optional<double>& undone, const char* name) {
        if (!mm) return std::string();
        std::string text = " " + fixed(*mm, 3) + " mm on " + name + " frames";
        if (undone) text += ", " + fixed(100.0 * *undone, 1) + " % of it undone";
        return text;
      };
      out += split(l.varying_error_mm_train, l.varying_error_undone_train, "training");
      if (l.varying_error_mm_train && l.varying_error_mm_test) out += ";";
      out += split(l.varying_error_mm_test, l.varying_error_undone_test, "held-out");
      out += "\n";
    }
  }
  out += "- mean gradient norm of L1 + D-SSIM per part:";
  for (const auto& g : l.gradients) out += " " + g.part + " " + scientific(g.mean_norm) + ";";
  out += "\n";
  return out;
}

}  // namespace tega::tools
