#include "tega/trainer/trainer.h"

#include <ATen/ATen.h>
#include <ATen/core/grad_mode.h>
#include <ATen/CPUGeneratorImpl.h>
#include <ATen/Parallel.h>
#include <ATen/record_function.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <limits>
#include <nlohmann/json.hpp>
#include <optional>
#include <set>
#include <sstream>

#include "tega/core/error.h"
#include "tega/core/files.h"
#include "tega/core/interrupt.h"
#include "tega/core/log.h"
#include "tega/core/options.h"
#include "tega/core/progress.h"
#include "tega/core/thread_pool.h"
#include "tega/nn/losses.h"
#include "tega/nn/module_io.h"
#include "tega/nn/vgg_loss.h"
#include "tega/splat/rasterize.h"
#include "tega/trainer/avatar_model.h"
#include "tega/trainer/checkpoint.h"
#include "tega/trainer/data_parallel.h"
#include "tega/trainer/densifier.h"
#include "tega/trainer/gradient_average.h"
#include "tega/trainer/render.h"
#include "tega/trainer/schedules.h"
#include "tega/trainer/step_profiler.h"
#include "tega/trainer/view_loader.h"

#include "step_readout.h"

namespace tega::trainer {
namespace fs = std::filesystem;

namespace {

constexpr const char* kCheckpoint = "checkpoint.safetensors";
// The checkpoint before the latest: what a resume falls back on when the
// latest cannot be read (a disk error, a copy cut short).
constexpr const char* kPreviousCheckpoint = "checkpoint.previous.safetensors";
constexpr const char* kOptions = "options.yaml";
constexpr const char* kMetrics = "metrics.csv";
// Training frames below which the run warns: with 10 expressions the field of
// the virtual-studio studies learnt them by heart, with 30 it generalised
// (docs/training.md, "How many expressions the deformation field needs").
constexpr size_t kExpressionsTheFieldNeeds = 30;

struct MetricRow {
  int64_t iteration;
  double loss, psnr;
  int64_t gaussians;
  double seconds;
};

std::vector<View> views_of(const Dataset& d, const std::vector<std::string>& frames,
                           const std::vector<std::string>& cameras) {
  std::vector<View> views;
  for (const auto& cam : cameras) {
    const auto names = d.rig.camera_names();
    const int c = static_cast<int>(std::find(names.begin(), names.end(), cam) - names.begin());
    for (const auto& id : frames) {
      if (!d.has_image(cam, id)) continue;  // left out by the dataset's producer (missing_images)
      const int f = static_cast<int>(
          std::find_if(d.frames.begin(), d.frames.end(), [&](const DatasetFrame& x) { return x.id == id; }) -
          d.frames.begin());
      views.push_back({c, f});
    }
  }
  return views;
}

void write_metrics(const fs::path& file, const std::vector<MetricRow>& rows) {
  std::ostringstream out;
  out << "iteration,loss,psnr,gaussians,seconds\n";
  for (const auto& r : rows) out << r.iteration << ',' << r.loss << ',' << r.psnr << ',' << r.gaussians << ',' << r.seconds << '\n';
  write_text_atomic(file, out.str());
}

std::vector<MetricRow> read_metrics(const fs::path& file, int64_t up_to_iteration) {
  std::vector<MetricRow> rows;
  std::ifstream in(file);
  std::string line;
  std::getline(in, line);  // header
  while (std::getline(in, line)) {
    MetricRow r{};
    char comma;
    std::istringstream fields(line);
    fields >> r.iteration >> comma >> r.loss >> comma >> r.psnr >> comma >> r.gaussians >> comma >> r.seconds;
    if (fields && r.iteration <= up_to_iteration) rows.push_back(r);
  }
  return rows;
}

double exponential(double from, double to, double t) { return from * std::pow(to / from, std::clamp(t, 0.0, 1.0)); }

// One training run: the model, its optimizer and everything a checkpoint holds.
class Run {
 public:
  Run(const fs::path& dataset_dir, const fs::path& run_dir, const TrainOptions& options, const RunControl& control,
      DataParallel& parallel)
      : options_(options),
        parallel_(parallel),
        run_dir_(run_dir),
        device_(options.device),
        dataset_(read_dataset(dataset_dir)),
        model_((validate_dataset(dataset_), dataset_), options, device_),
        generator_(at::make_generator<at::CPUGeneratorImpl>(static_cast<uint64_t>(options.seed))),
        profiler_(options.profile, device_),
        poisoned_iterations_(control.poisoned_iterations.begin(), control.poisoned_iterations.end()) {
    validate_train_options(options_);
    train_views_ = views_of(dataset_, dataset_.train.frames, dataset_.train.cameras);
    heldout_views_ = views_of(dataset_, dataset_.train.frames, dataset_.test.cameras);
    if (!options_.loss.vgg_weights.empty()) {
      vgg_.emplace(nn::VggPerceptualLoss::load(options_.loss.vgg_weights).to(device_));
    } else {
      logging::info("perceptual (VGG) loss: off (no loss.vgg_weights configured)");
    }
    background_ = at::tensor(options_.background, at::kFloat).to(device_);

    if (control.resume) {
      restore_latest();
    } else {
      const at::TensorOptions floats = at::TensorOptions(at::kFloat).device(device_);
      // The cap bounds the count at every step, so that a capped run (the
      // paper's "Ours (200K Gaussians)") never holds more than its cap.
      const int64_t initial = std::min(options_.initial_gaussians, options_.densify.max_gaussians);
      if (initial < options_.initial_gaussians && options_.binding != "rigged")
        logging::info("initial_gaussians %lld exceeds densify.max_gaussians: sampling %lld",
                      static_cast<long long>(options_.initial_gaussians), static_cast<long long>(initial));
      model_.gaussians = options_.binding == "rigged"
                             ? initialise_rigged_gaussians(model_.lookup(), floats)
                             : initialise_gaussians(model_.lookup(), initial, model_.metres_per_uv(),
                                                    options_.binding == "triangle", options_.network.texture_size,
                                                    static_cast<uint64_t>(options_.seed), floats);
      register_parameters();
      stats_ = splat::MeanGradientStats::zeros(model_.gaussians.uvd);
      max_world_std_ = at::zeros({model_.gaussians.size()}, background_.options());
      save();  // what a NaN/Inf before the first periodic checkpoint rolls back to
    }
    logging::info("dataset %s: %zu frames, %zu cameras; %zu training views, template %d vertices; %lld Gaussians",
                  dataset_dir.c_str(), dataset_.frames.size(), dataset_.rig.cameras.size(), train_views_.size(),
                  dataset_.template_mesh.num_vertices(), static_cast<long long>(model_.gaussians.size()));
    if (options_.deformation_field && dataset_.train.frames.size() < kExpressionsTheFieldNeeds)
      logging::warn(
          "dataset %s: %zu training frame%s: the deformation field may learn their expressions by heart and break "
          "on new ones; on the virtual studio it needed about %zu (docs/training.md#how-many-expressions-the-"
          "deformation-field-needs)",
          dataset_dir.c_str(), dataset_.train.frames.size(), dataset_.train.frames.size() == 1 ? "" : "s",
          kExpressionsTheFieldNeeds);
    if (!dataset_.missing_images.empty())
      logging::warn("dataset %s: %zu images are missing (dataset.json: missing_images); training skips them",
                    dataset_dir.c_str(), dataset_.missing_images.size());
  }

  TrainSummary train(int64_t stop_at) {
    const int64_t last = stop_at > 0 ? std::min(stop_at, options_.iterations) : options_.iterations;
    // Each process its own views: the same order from another seed.
    const uint64_t view_seed = static_cast<uint64_t>(options_.seed) + 1000003ull * static_cast<uint64_t>(parallel_.rank());
    ViewLoader loader(dataset_, train_views_, view_seed, options_.loader_threads,
                      options_.prefetch, /*pin_memory=*/device_.is_cuda());
    loader.seek(iteration_);
    const auto start = std::chrono::steady_clock::now();
    auto first_done = start;
    const int64_t first = iteration_;
    auto rate_start = start;  // the progress line's rate counts from here (a roll-back restarts it)
    int64_t rate_first = first;
    double window_loss = 0, window_psnr = 0;
    int window = 0;
    TrainSummary summary;
    std::optional<StepValues> failed;
    // Adds a finished step's values to the log window, or notes a failed step.
    const auto take = [&](const std::optional<StepValues>& values) {
      if (!values) return;
      if (!failure(*values).empty()) {
        if (!failed) failed = values;
        return;
      }
      window_loss += values->loss;
      window_psnr += -10.0 * std::log10(std::max(values->mse, 1e-12));
      ++window;
    };
    while (iteration_ < last) {
      profiler_.section("data");
      const LoadedView view = loader.next();
      step(view, take);
      ++iteration_;
      if (iteration_ == first + 1) first_done = std::chrono::steady_clock::now();
      // Together, or a process would wait for the others' gradients forever.
      const bool interrupted = parallel_.alone() ? InterruptGuard::requested() : interrupt_agreed_;
      const bool log_due = iteration_ % options_.log_every == 0 || iteration_ == last || interrupted;
      const bool checkpoint_due = iteration_ % options_.checkpoint_every == 0 && iteration_ < last;
      if (log_due || checkpoint_due) take(agreed(readout_.pop()));
      if (failed) {
        roll_back(*failed);
        failed.reset();
        loader.seek(iteration_);
        rate_first = iteration_;
        rate_start = std::chrono::steady_clock::now();
        window_loss = window_psnr = 0;
        window = 0;
        continue;
      }
      if (log_due) {
        const auto now = std::chrono::steady_clock::now();
        const double seconds = std::chrono::duration<double>(now - start).count();
        const double rate = static_cast<double>(iteration_ - rate_first) /
                            std::max(std::chrono::duration<double>(now - rate_start).count(), 1e-9);
        summary.final_loss = window_loss / window;
        summary.train_psnr = window_psnr / window;
        metrics_.push_back({iteration_, summary.final_loss, summary.train_psnr, model_.gaussians.size(), seconds});
        // On several processes a step is one view each: the views a second compare with one GPU's it/s.
        char views[48] = "";
        if (!parallel_.alone()) std::snprintf(views, sizeof views, " (%.1f views/s)", rate * parallel_.world());
        if (parallel_.leads())
          logging::info("it %lld/%lld  loss %.5f  psnr %.2f  gaussians %lld  %.2f it/s%s  ETA %s",
                      static_cast<long long>(iteration_), static_cast<long long>(options_.iterations),
                      summary.final_loss, summary.train_psnr, static_cast<long long>(model_.gaussians.size()), rate,
                      views,
                      Progress::format_duration(static_cast<double>(options_.iterations - iteration_) / rate).c_str());
        window_loss = window_psnr = 0;
        window = 0;
      }
      if (interrupted) {
        logging::warn("interrupted at iteration %lld of %lld: saving a checkpoint (--resume continues)",
                      static_cast<long long>(iteration_), static_cast<long long>(options_.iterations));
        summary.interrupted = true;
        break;
      }
      if (checkpoint_due) save();
    }
    profiler_.stop();
    const auto loop_done = std::chrono::steady_clock::now();
    summary.steady_iterations = std::max<int64_t>(iteration_ - first - 1, 0);
    summary.steady_seconds = std::chrono::duration<double>(loop_done - first_done).count();
    save();
    summary.checkpoint_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - loop_done).count();
    summary.iterations = iteration_;
    summary.gaussians = model_.gaussians.size();
    summary.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    // An interrupted run (a scheduler's time limit, say) has seconds left, not the held-out renders' time.
    check_replicas_agree();  // before the first process alone renders the held-out views
    summary.heldout_psnr = summary.interrupted || !parallel_.leads() ? std::numeric_limits<double>::quiet_NaN() : heldout_psnr();
    summary.checkpoint = run_dir_ / kCheckpoint;
    if (profiler_.enabled()) {
      summary.milliseconds_per_step = profiler_.mean_milliseconds(iteration_ - first);
      for (const auto& [name, ms] : summary.milliseconds_per_step) {
        logging::info("profile: %18s %8.2f ms/it", name.c_str(), ms);
      }
    }
    return summary;
  }

 private:
  Phase phase() const {
    Phase p;
    const bool warm = iteration_ >= at_fraction(options_.warmup, options_.iterations);
    p.deformation = warm && options_.deformation_field;
    p.shading = warm && options_.dynamic_shading;
    p.sh_degree = static_cast<int>(std::min<int64_t>(
        options_.sh_degree, iteration_ / period(options_.sh_degree_interval, options_.iterations)));
    return p;
  }

  const FrameInput& frame_input(int frame) {
    auto it = frames_.find(frame);
    if (it == frames_.end()) {
      const auto& f = dataset_.frames[frame];
      it = frames_.emplace(frame, model_.frame_input(dataset_.load_mesh(f.id), f.head_to_world)).first;
    }
    return it->second;
  }

  // Forward, backward and update on one view. The step's loss, MSE and
  // finite check are queued in readout_; the previous step's go to `take`
  // once this step's work is queued (step_readout.h says why).
  template <class Take>
  void step(const LoadedView& loaded, Take&& take) {
    RECORD_FUNCTION("tega::step", std::vector<c10::IValue>());
    const Camera& camera = dataset_.rig.cameras[loaded.view.camera];
    const Phase p = phase();
    update_learning_rates();

    profiler_.section("networks+jacobians");
    const FrameInput& frame = frame_input(loaded.view.frame);
    PosedGaussians posed = model_.pose(frame, p);
    // Queued before the rasterizer, whose tile count waits for the GPU: the
    // smoothness term's many small ops then launch while the fields' large
    // kernels run, and autograd reaches their gradients behind the
    // rasterizer's (after the image losses, they left the GPU idle ~10 ms a
    // step at 4M Gaussians).
    const at::Tensor smoothness = smoothness_term(p, posed);

    profiler_.section("rasterization");
    splat::RasterOutput raster;
    {
      RECORD_FUNCTION("tega::rasterization", std::vector<c10::IValue>());
      splat::RasterSettings settings = raster_settings(camera, options_.antialiased);
      settings.sh_degree = posed.sh_degree;
      raster = splat::rasterize(posed.means, posed.covariances, posed.sh, posed.opacities, background_,
                                {raster_camera(camera)}, settings, &stats_);
    }

    profiler_.section("losses");
    const at::Tensor rendered = raster.rgb[0].permute({2, 0, 1});
    const at::Tensor target = composite_target(loaded.rgba.to(device_, at::kByte, /*non_blocking=*/true), background_);
    at::Tensor loss;
    {
      RECORD_FUNCTION("tega::image_losses", std::vector<c10::IValue>());
      loss = options_.loss.l1 * nn::l1_image_loss(rendered, target) +
             options_.loss.dssim * nn::dssim_loss(rendered, target);
      if (options_.loss.pyramid_l1 > 0)
        loss = loss + options_.loss.pyramid_l1 * nn::pyramid_l1_loss(rendered, target, options_.loss.pyramid_levels);
    }
    const double vgg_weight = schedules::vgg_weight(options_.loss, iteration_, options_.iterations);
    if (vgg_ && vgg_weight > 0) loss = loss + vgg_weight * (*vgg_)(rendered.unsqueeze(0), target.unsqueeze(0));
    if (smoothness.defined()) loss = loss + smoothness;
    if (model_.gaussians.rigged) loss = loss + rig_regularisers();
    if (poisoned_iterations_.erase(iteration_ + 1)) loss = loss * std::numeric_limits<double>::quiet_NaN();
    const at::Tensor mse = (rendered.detach() - target).pow(2).mean();

    profiler_.section("backward");
    adam_.zero_grad();
    if (!parallel_.alone()) gradient_average_.arm(gradient_buckets());
    loss.backward();
    if (!parallel_.alone()) {
      RECORD_FUNCTION("tega::gradient_all_reduce", std::vector<c10::IValue>());
      gradient_average_.finish();
    }
    // A NaN/Inf is reported one step late: the step that made it has updated
    // the parameters by then, but nothing is saved before its check (the loop
    // takes the last step's values before every save, and the checkpoint
    // writer refuses non-finite tensors).
    take(agreed(readout_.pop()));
    readout_.push(loss, mse, all_finite(loss), posed.largest_deformation, iteration_ + 1, loaded.view);

    profiler_.section("optimizer");
    {
      RECORD_FUNCTION("tega::optimizer", std::vector<c10::IValue>());
      adam_.step();
      // A Gaussian's size in metres depends on the frame each process posed: bound it in their
      // mean, the same in every process, or the replicas would drift apart.
      at::Tensor world_std_per_scale = posed.world_std_per_scale;
      if (!parallel_.alone()) {
        world_std_per_scale = world_std_per_scale.detach().clone();
        parallel_.average({world_std_per_scale});
      }
      clamp_world_size(model_.gaussians, world_std_per_scale, options_.min_std, options_.max_std);
      at::NoGradGuard no_grad;
      const at::Tensor world_std = (model_.gaussians.log_scale.exp() * world_std_per_scale).amax(1);
      max_world_std_ = at::max(max_world_std_, world_std);
    }

    profiler_.section("densification");
    densify_if_due(camera);
  }

  // The parameters in the order backward finishes their gradients, for the average started during
  // it (gradient_average.h): first the Gaussians' tensors the rasterizer's backward reaches at once
  // (sh_rest last: the first SH degrees leave it without a gradient), then in one bucket uvd, which
  // the fields read, and the fields.
  std::vector<std::vector<at::Tensor>> gradient_buckets() {
    static const std::vector<std::string> kReachedFirst{"opacity_logit", "sh_dc", "rotation", "log_scale", "sh_rest"};
    std::vector<std::vector<at::Tensor>> buckets;
    for (const std::string& name : kReachedFirst) buckets.push_back({adam_.group(name).parameter});
    std::vector<at::Tensor> rest;
    for (const auto& g : adam_.groups())
      if (std::find(kReachedFirst.begin(), kReachedFirst.end(), g.name) == kReachedFirst.end())
        rest.push_back(g.parameter);
    buckets.push_back(std::move(rest));
    return buckets;
  }

  // The weighted Jacobian smoothness loss on random uvd samples, or undefined
  // when the field or the term is off.
  at::Tensor smoothness_term(const Phase& p, const PosedGaussians& posed) {
    const double weight = schedules::smoothness_weight(options_.loss, iteration_, options_.iterations);
    if (!p.deformation || options_.loss.smoothness_samples <= 0 || weight == 0) return {};
    RECORD_FUNCTION("tega::smoothness", std::vector<c10::IValue>());
    const at::Tensor samples = to_device(
        nn::sample_smoothness_uvd(options_.loss.smoothness_samples, at::TensorOptions(at::kFloat), generator_));
    const at::Tensor jacobians = model_.network->deform(samples, posed.latents, true).jacobian;
    return weight * nn::jacobian_smoothness_loss(jacobians, nn::Reduction::mean);
  }

  // GaussianAvatars' position and scale regularisers, in local units: they
  // keep a rigged Gaussian near its triangle and no larger than it, so that
  // it does not swing when the triangle turns.
  at::Tensor rig_regularisers() const {
    const auto& l = options_.loss;
    const Gaussians& g = model_.gaussians;
    const at::Tensor position = at::relu(g.uvd.norm(2, 1) - l.rig_position_threshold).mean();
    const at::Tensor scale = at::relu(g.log_scale.exp() - l.rig_scale_threshold).norm(2, 1).mean();
    return l.rig_position * position + l.rig_scale * scale;
  }

  // A host tensor on the training device without waiting for the GPU (a
  // blocking copy waits for every queued kernel).
  at::Tensor to_device(const at::Tensor& host) const {
    if (!device_.is_cuda()) return host.to(device_);
    return host.pin_memory().to(device_, /*non_blocking=*/true);
  }

  // Whether the loss and every gradient are finite, as a 0-d bool tensor on the
  // device. One pass over each gradient: its smallest and largest element,
  // NaN where one is (aminmax propagates NaN), ±Inf where one is.
  at::Tensor all_finite(const at::Tensor& loss) const {
    std::vector<at::Tensor> extremes{loss.detach().reshape({})};
    for (const auto& g : adam_.groups()) {
      if (!g.parameter.grad().defined() || g.parameter.grad().numel() == 0) continue;
      const auto [lowest, highest] = at::aminmax(g.parameter.grad());
      extremes.insert(extremes.end(), {lowest, highest});
    }
    return at::isfinite(at::stack(extremes)).all();
  }

  // What went wrong in a step ("" if nothing): a NaN/Inf, or a deformation
  // field that ran away.
  std::string failure(const StepValues& values) const {
    if (!values.finite) return "the loss or a gradient is NaN/Inf";
    const LargestDeformation& d = values.largest_deformation;
    if (options_.max_deformation > 0 && !(d.metres <= options_.max_deformation))
      return "the deformation field moved a Gaussian " + format_number(d.metres) + " m, more than max_deformation (" +
             format_number(options_.max_deformation) + " m): Gaussian " + std::to_string(d.gaussian) + " at uv (" +
             format_number(d.u) + ", " + format_number(d.v) + "), template triangle " + std::to_string(d.triangle);
    return "";
  }

  // A failed step rolls the run back to its last checkpoint and lowers every
  // learning rate, once; a second one stops training (nothing from a failed
  // step is ever saved: the loop checks each step before it saves).
  // A step's values as every process sees them: the loss and MSE averaged over the processes, a
  // failure in one a failure in all; and whether any was asked to stop. One host all-reduce a step.
  std::optional<StepValues> agreed(std::optional<StepValues> values) {
    if (parallel_.alone()) return values;
    const bool bad = values && !failure(*values).empty();
    const std::vector<double> sums = parallel_.host_sum({values ? values->loss : 0.0, values ? values->mse : 0.0,
                                                         bad ? 1.0 : 0.0, InterruptGuard::requested() ? 1.0 : 0.0});
    interrupt_agreed_ = sums[3] > 0;
    if (!values) return values;
    values->loss = sums[0] / parallel_.world();
    values->mse = sums[1] / parallel_.world();
    if (sums[2] > 0 && !bad) values->finite = false;
    return values;
  }

  // The processes' parameters must be equal after the same averaged steps; a difference would
  // mean that they trained apart (a step one of them skipped).
  void check_replicas_agree() {
    if (parallel_.alone()) return;
    double checksum = 0;
    for (const auto& g : adam_.groups()) checksum += g.parameter.detach().to(at::kDouble).abs().sum().item<double>();
    const double mean = parallel_.host_sum({checksum})[0] / parallel_.world();
    const bool differs = std::abs(checksum - mean) > 1e-9 * std::max(1.0, std::abs(mean));
    const double differing = parallel_.host_sum({differs ? 1.0 : 0.0})[0];
    if (differing > 0)
      throw Error("data-parallel training: the " + std::to_string(parallel_.world()) +
                  " processes ended with different parameters (checksums around " + std::to_string(mean) + ")");
    if (parallel_.leads())
      logging::info("%d processes trained one model: their parameters agree (checksum %.9g)", parallel_.world(), mean);
  }

  void roll_back(const StepValues& values) {
    const std::string what = "iteration " + std::to_string(values.iteration) + ": " + failure(values) + " (camera " +
                             dataset_.rig.cameras[values.view.camera].name + ", frame " +
                             dataset_.frames[values.view.frame].id + ")";
    if (rolled_back_) {
      throw Error(what + " again after a roll-back with the learning rates x" + format_number(learning_rate_scale_) +
                  "; training stopped, the last checkpoint (iteration " + std::to_string(saved_iteration_) +
                  ") is intact");
    }
    const double scale = learning_rate_scale_ * options_.rollback_learning_rate_factor;
    logging::warn("%s; rolling back to the checkpoint of iteration %lld, learning rates x%s from there", what.c_str(),
                  static_cast<long long>(saved_iteration_), format_number(scale).c_str());
    restore_latest();
    learning_rate_scale_ = scale;
    rolled_back_ = true;
    readout_.pop();  // the pending step ran on the bad parameters
  }

  static std::string format_number(double x) {
    std::ostringstream out;
    out << x;
    return out.str();
  }

  void update_learning_rates() {
    const double t = static_cast<double>(iteration_) / static_cast<double>(std::max<int64_t>(1, options_.iterations - 1));
    const auto& lr = options_.learning_rates;
    const double s = learning_rate_scale_ * learning_rate_factor(parallel_.world());
    adam_.group("uvd").learning_rate = s * exponential(lr.position, lr.position_final, t);
    adam_.group("log_scale").learning_rate = s * lr.scale;
    adam_.group("rotation").learning_rate = s * lr.rotation;
    adam_.group("sh_dc").learning_rate = s * lr.sh_dc;
    adam_.group("sh_rest").learning_rate = s * lr.sh_rest;
    adam_.group("opacity_logit").learning_rate = s * lr.opacity;
    const double network_lr = s * exponential(lr.network, lr.network_final, t);
    for (auto& name : network_groups_) adam_.group(name).learning_rate = network_lr;
  }

  void densify_if_due(const Camera& camera) {
    const auto& d = options_.densify;
    const int64_t it = iteration_ + 1;  // this step's number, 1-based
    if (!d.enabled || it < at_fraction(d.start, options_.iterations) || it > at_fraction(d.stop, options_.iterations)) {
      return;
    }
    if (it % period(d.interval, options_.iterations) == 0) {
      // 3DGS's threshold is on gradients w.r.t. normalised device coordinates;
      // the rasterizer reports them per pixel.
      const double pixels_per_ndc = 0.5 * std::max(camera.width, camera.height);
      parallel_.sum({stats_.grad_norm_sum, stats_.visible_count});  // every process's views count
      DensifyStats stats{stats_.grad_norm_sum * pixels_per_ndc, stats_.visible_count, max_world_std_};
      gradient_average_.forget();
      const DensifyResult r = densify(model_.gaussians, adam_, stats, d, model_.lookup(),
                                      options_.network.texture_size, generator_);
      logging::debug("densify at %lld: cloned %lld, split %lld, pruned %lld -> %lld Gaussians",
                     static_cast<long long>(it), static_cast<long long>(r.cloned), static_cast<long long>(r.split),
                     static_cast<long long>(r.pruned), static_cast<long long>(model_.gaussians.size()));
      stats_ = splat::MeanGradientStats::zeros(model_.gaussians.uvd);
      max_world_std_ = at::zeros({model_.gaussians.size()}, background_.options());
    }
    // As 3DGS, only while densification goes on: a reset at its stop (the
    // run's last step, where GaussianAvatars' densification ends) would
    // leave the opacities no iterations to recover.
    if (it < at_fraction(d.stop, options_.iterations) && it % period(d.opacity_reset_interval, options_.iterations) == 0) {
      reset_opacity(model_.gaussians, adam_);
    }
  }

  void register_parameters() {
    const int views_a_step = options_.momentum_per_view ? parallel_.world() : 1;
    adam_ = Adam(moment_decay(Adam::kBeta1, views_a_step), moment_decay(Adam::kBeta2, views_a_step));
    const auto& lr = options_.learning_rates;
    auto& g = model_.gaussians;
    // Position learning rates are in metres: uv, d and rigged local units convert.
    const double uv = 1.0 / model_.metres_per_uv(), local = 1.0 / model_.mean_triangle_scale();
    const std::vector<double> per_metre = g.rigged ? std::vector<double>{local, local, local} : std::vector<double>{uv, uv, 1.0};
    adam_.add("uvd", g.uvd, lr.position, at::tensor(per_metre, g.uvd.options().requires_grad(false)).view({1, 3}));
    adam_.add("log_scale", g.log_scale, lr.scale);
    adam_.add("rotation", g.rotation, lr.rotation);
    adam_.add("sh_dc", g.sh_dc, lr.sh_dc);
    adam_.add("sh_rest", g.sh_rest, lr.sh_rest);
    adam_.add("opacity_logit", g.opacity_logit, lr.opacity);
    network_groups_.clear();
    for (const auto& item : model_.network->named_parameters(true)) {
      network_groups_.push_back("network." + item.key());
      adam_.add(network_groups_.back(), item.value(), lr.network);
    }
  }

  void save() {
    Checkpoint c;
    for (const auto& [name, tensor] : model_.gaussians.tensors()) c.tensors[name] = tensor.detach();
    for (const auto& [name, tensor] : nn::module_tensors(*model_.network, "network.")) c.tensors[name] = tensor.detach();
    for (const auto& [name, tensor] : adam_.state()) c.tensors[name] = tensor;
    c.tensors["densify.gradient_norm_sum"] = stats_.grad_norm_sum;
    c.tensors["densify.visible_count"] = stats_.visible_count;
    c.tensors["densify.max_world_std"] = max_world_std_;
    c.tensors["trainer.iteration"] = at::tensor({iteration_}, at::kLong);
    c.tensors["trainer.rng_state"] = generator_.get_state();
    c.tensors["trainer.learning_rate_scale"] = at::tensor({learning_rate_scale_}, at::kDouble);
    c.tensors["trainer.rolled_back"] = at::tensor({int64_t{rolled_back_}}, at::kLong);
    c.metadata["options"] = options_to_yaml(options_);
    c.metadata[kTextureMetadataKey] = kTextureWithoutEyeballs;
    c.metadata[kUvLayoutMetadataKey] = kUvLayoutChartsApartPacked;
    if (parallel_.leads()) {
      // Kept until this one is written whole: killed in between, the run
      // resumes from it.
      if (fs::exists(run_dir_ / kCheckpoint)) fs::rename(run_dir_ / kCheckpoint, run_dir_ / kPreviousCheckpoint);
      write_checkpoint(run_dir_ / kCheckpoint, c);
      write_metrics(run_dir_ / kMetrics, metrics_);
    }
    parallel_.barrier();  // a roll-back reads it in every process
    saved_iteration_ = iteration_;
  }

  // The latest checkpoint or, where it is missing or cannot be read, the one
  // before it, with a warning.
  void restore_latest() {
    const fs::path latest = run_dir_ / kCheckpoint, previous = run_dir_ / kPreviousCheckpoint;
    std::string why = latest.string() + ": is missing";
    if (fs::exists(latest)) {
      try {
        return restore(read_checkpoint(latest), latest);
      } catch (const Error& e) {
        if (!fs::exists(previous)) throw;
        why = e.what();
      }
    }
    if (!fs::exists(previous)) throw Error(run_dir_, "has no checkpoint to resume from");
    logging::warn("%s; resuming from the checkpoint before it, %s", why.c_str(), previous.c_str());
    restore(read_checkpoint(previous), previous);
  }

  void restore(const Checkpoint& c, const fs::path& file) {
    check_uv_layout(c, file, model_, dataset_.template_mesh, options_.binding == "rigged");
    gradient_average_.forget();
    model_.gaussians = gaussians_from_tensors(c.tensors, device_, options_.binding == "rigged",
                                               model_.lookup().num_triangles());
    nn::load_module_tensors(*model_.network, c.tensors, file, "network.");
    register_parameters();
    adam_.load_state(c.tensors);
    const auto tensor = [&](const char* name) {
      auto it = c.tensors.find(name);
      if (it == c.tensors.end()) throw Error(file, std::string("has no tensor '") + name + "'");
      return it->second.to(device_);
    };
    stats_.grad_norm_sum = tensor("densify.gradient_norm_sum");
    stats_.visible_count = tensor("densify.visible_count");
    max_world_std_ = tensor("densify.max_world_std");
    generator_.set_state(tensor("trainer.rng_state").cpu());
    // Absent from checkpoints written before roll-backs existed.
    const auto scale = c.tensors.find("trainer.learning_rate_scale");
    learning_rate_scale_ = scale == c.tensors.end() ? 1.0 : scale->second.item<double>();
    const auto rolled_back = c.tensors.find("trainer.rolled_back");
    rolled_back_ = rolled_back != c.tensors.end() && rolled_back->second.item<int64_t>() != 0;
    iteration_ = saved_iteration_ = c.iteration();
    metrics_ = read_metrics(run_dir_ / kMetrics, iteration_);
    logging::info("resumed %s at iteration %lld", file.c_str(), static_cast<long long>(iteration_));
  }

  double heldout_psnr() {
    if (heldout_views_.empty()) return 0.0;
    at::NoGradGuard no_grad;
    double total = 0;
    for (const View& v : heldout_views_) {
      const Camera& camera = dataset_.rig.cameras[v.camera];
      const auto& f = dataset_.frames[v.frame];
      const at::Tensor rendered = render_view(model_, frame_input(v.frame), camera, phase(), background_,
                                              options_.antialiased);
      const Image8 image = read_image_u8(dataset_.image_path(camera.name, f.id));
      const at::Tensor rgba =
          at::from_blob(const_cast<uint8_t*>(image.pixels.data()), {image.height, image.width, 4}, at::kByte);
      const at::Tensor target = composite_target(rgba.to(device_), background_);
      total += -10.0 * std::log10(std::max((rendered - target).pow(2).mean().item<double>(), 1e-12));
    }
    return total / static_cast<double>(heldout_views_.size());
  }

  TrainOptions options_;
  DataParallel& parallel_;
  fs::path run_dir_;
  at::Device device_;
  Dataset dataset_;
  AvatarModel model_;
  Adam adam_;
  GradientAverage gradient_average_{parallel_};
  std::vector<std::string> network_groups_;
  at::Generator generator_;
  splat::MeanGradientStats stats_;
  at::Tensor max_world_std_;
  at::Tensor background_;
  std::optional<nn::VggPerceptualLoss> vgg_;
  std::map<int, FrameInput> frames_;
  std::vector<View> train_views_, heldout_views_;
  std::vector<MetricRow> metrics_;
  StepProfiler profiler_;
  int64_t iteration_ = 0;
  int64_t saved_iteration_ = 0;
  double learning_rate_scale_ = 1.0;  // lowered by a roll-back
  bool rolled_back_ = false;
  std::set<int64_t> poisoned_iterations_;
  StepReadout readout_;
  bool interrupt_agreed_ = false;  // a process was asked to stop, as of the last agreed step
};

}  // namespace

TrainSummary train(const fs::path& dataset, const fs::path& run, TrainOptions options, const RunControl& control) {
  at::set_num_threads(options.cpu_threads > 0 ? options.cpu_threads : default_thread_count());
  DataParallel parallel(control.parallel, at::Device(options.device));
  const bool has_checkpoint = fs::exists(run / kCheckpoint) || fs::exists(run / kPreviousCheckpoint);
  if (control.resume) {
    if (!has_checkpoint) throw Error(run, "has no checkpoint to resume from");
  } else if (has_checkpoint && !control.overwrite) {
    throw Error(run, "already holds a run (pass --resume to continue it, or --force to start over)");
  }
  parallel.barrier();  // every process has looked before the first one clears
  if (parallel.leads()) {
    if (!control.resume) {
      // The run they belonged to is over (--force).
      fs::remove(run / kCheckpoint);
      fs::remove(run / kPreviousCheckpoint);
    }
    fs::create_directories(run);
    write_text_atomic(run / kOptions, options_to_yaml(options));
  }

  // The networks' initial weights come from libtorch's global generator: the same in every process.
  at::manual_seed(static_cast<uint64_t>(options.seed));
  InterruptGuard interrupt;
  Run training(dataset, run, options, control, parallel);
  TrainSummary summary = training.train(control.stop_at);
  if (!parallel.leads()) return summary;

  const nlohmann::json report = {{"dataset", fs::absolute(dataset).string()},
                                 {"iterations", summary.iterations},
                                 {"gaussians", summary.gaussians},
                                 {"final_loss", summary.final_loss},
                                 {"train_psnr", summary.train_psnr},
                                 {"heldout_psnr", summary.heldout_psnr},
                                 {"seconds", summary.seconds},
                                 {"steady_iterations", summary.steady_iterations},
                                 {"steady_seconds", summary.steady_seconds},
                                 {"checkpoint_seconds", summary.checkpoint_seconds},
                                 {"interrupted", summary.interrupted},
                                 {"checkpoint", kCheckpoint}};
  write_text_atomic(run / "run.json", report.dump(2));
  return summary;
}

}  // namespace tega::trainer
