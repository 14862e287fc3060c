// bench/mvs: one frame of a virtual-studio take through multi-view stereo,
// each stage timed (load, depth, fusion, surface) and scored against the
// studio's ground truth: depth maps against rendered true depth, and (where
// tega_mvs_surface is built, Open3D) the mesh's accuracy and completeness over
// the face. With --take-frames N, then frames 0 to N - 1 pipelined as
// `tega mvs` runs a take (frame_pipeline.h): the seconds per frame of a take.
// The capture is rendered once into --capture and kept for the next run.
#include <CLI/CLI.hpp>
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <numeric>

#include "tega/core/log.h"
#include "tega/core/mesh.h"
#include "tega/core/thread_pool.h"
#include "tega/core/undistort.h"
#include "tega/mvs/colmap_workspace.h"
#include "tega/mvs/frame_pipeline.h"
#include "tega/mvs/frame_views.h"
#include "tega/mvs/fusion.h"
#include "tega/mvs/patch_match.h"
#include "tega/mvs/view_selection.h"
#include "tega/synth/ground_truth_depth.h"
#include "tega/synth/virtual_studio.h"
#ifdef TEGA_BENCH_HAVE_SURFACE
#include "tega/mvs/surface.h"
#include "tega/scoring/studio_truth.h"
#include "tega/scoring/surface_scores.h"
#endif
#ifdef TEGA_BENCH_HAVE_MVS
#include "tega/core/options.h"
#include "tega/mvs/masks.h"
#include "tega/mvs/reconstruction.h"
#endif

namespace fs = std::filesystem;
using namespace tega;
using Clock = std::chrono::steady_clock;

namespace {

double seconds_since(Clock::time_point start) { return std::chrono::duration<double>(Clock::now() - start).count(); }

// Renders again where the kept capture has fewer frames than asked for.
fs::path render_capture(const fs::path& root, int cameras, int width, int height, int frames) {
  if (fs::exists(root / "capture.json") && read_take(root / "takes" / "expressions").frames >= frames) return root;
  std::printf("rendering %d cameras at %dx%d, %d frames, into %s (once)...\n", cameras, width, height, frames,
              root.c_str());
  synth::Options o;
  o.studio.cameras = cameras;
  o.studio.width = width;
  o.studio.height = height;
  o.frames = frames;
  o.calibration_frames = 0;
  o.takes = {"expressions"};
  o.test_takes = {};
  o.test_cameras = 1;
  synth::render_virtual_studio(o, root, true);
  return root;
}

// Masks from the true coverage (builds without OpenCV have no clean-plate masks).
void mask_from_truth(std::vector<mvs::StereoView>& views, const fs::path& root, const Rig& rig, int frame,
                     ThreadPool& pool) {
  pool.parallel_for(0, int64_t(views.size()), [&](int64_t k) {
    mvs::StereoView& view = views[size_t(k)];
    char name[32];
    std::snprintf(name, sizeof name, "%06d.png", frame);
    const Image8 alpha = read_image_u8(root / "ground_truth" / "expressions" / "alpha" / view.camera.name / name);
    const Image8 undistorted = undistort_image(alpha, rig.camera(view.camera.name));
    view.mask.resize(undistorted.pixels.size());
    for (size_t i = 0; i < view.mask.size(); ++i) view.mask[i] = undistorted.pixels[i] > 0 ? 255 : 0;
  });
}

struct DepthScore {
  int64_t estimated = 0, covered = 0, within_1mm = 0, within_2mm = 0, covered_and_estimated = 0;
  std::vector<float> errors;
};

void score_depth(const mvs::DepthMap& map, const ImageF& truth, DepthScore& score) {
  for (size_t i = 0; i < map.depth.size(); ++i) {
    const float t = truth.pixels[i], d = map.depth[i];
    score.covered += t > 0;
    if (d <= 0) continue;
    ++score.estimated;
    if (t <= 0) continue;
    ++score.covered_and_estimated;
    const float e = std::abs(d - t);
    score.within_1mm += e < 0.001f;
    score.within_2mm += e < 0.002f;
    score.errors.push_back(e);
  }
}

#ifdef TEGA_BENCH_HAVE_SURFACE
// The mesh against the frame's true fine mesh, over the face.
void report_mesh(const Mesh& mesh, const fs::path& root, int frame) {
  const scoring::StudioTruth truth = scoring::load_studio_truth(root, "expressions", frame);
  scoring::EvaluationOptions eval;
  eval.tolerances_m = {0.001, 0.002, 0.003};
  const auto s = scoring::evaluate_surface(mesh, truth.fine, truth.face_region, eval);
  std::printf("mesh: %d vertices, %d faces; accuracy median %.3f mm, mean %.3f mm, p90 %.3f mm; completeness over the "
              "face %.1f %% at 1 mm, %.1f %% at 2 mm, %.1f %% at 3 mm\n",
              mesh.num_vertices(), mesh.num_faces(), 1000 * s.accuracy_median_m, 1000 * s.accuracy_mean_m,
              1000 * s.accuracy_p90_m, 100 * s.completeness[0], 100 * s.completeness[1], 100 * s.completeness[2]);
}
#endif

struct FrameTimes {
  double load_s = 0, depth_s = 0, fusion_s = 0, surface_s = 0;
};

void print_times(const FrameTimes& t, const char* indent) {
  std::printf("%s%-10s %8.2f\n%s%-10s %8.2f\n%s%-10s %8.2f\n%s%-10s %8.2f\n%s%-10s %8.2f\n", indent, "load", t.load_s,
              indent, "depth", t.depth_s, indent, "fusion", t.fusion_s, indent, "surface", t.surface_s, indent, "total",
              t.load_s + t.depth_s + t.fusion_s + t.surface_s);
}

struct PreparedFrame {
  std::vector<mvs::StereoView> views;
  std::vector<mvs::DepthMap> maps;
  mvs::OrientedPointCloud cloud;
  Mesh mesh;
  FrameTimes times;
};

// Every view gets a depth map, its depths searched 0.3 m either side of the rig's focus point.
std::vector<mvs::ViewTask> view_tasks(const std::vector<mvs::StereoView>& views, const mvs::PatchMatchOptions& pm) {
  std::vector<Camera> pinholes;
  for (const auto& v : views) pinholes.push_back(v.camera);
  const Eigen::Vector3d focus = *mvs::rig_focus_point(pinholes);
  const auto sources = mvs::select_source_views(pinholes, focus, pm.source_views);
  std::vector<mvs::ViewTask> tasks;
  for (size_t k = 0; k < views.size(); ++k) {
    const double centre = views[k].camera.world_to_camera.apply(focus).z();
    tasks.push_back({int(k), sources[k], float(centre - 0.3), float(centre + 0.3)});
  }
  return tasks;
}

#if defined(TEGA_BENCH_HAVE_MVS) && defined(TEGA_BENCH_HAVE_SURFACE)
// The views and depth maps of a frame's dense workspace (`tega mvs
// --workspace`), fused again: fusion tuned without making the depth maps.
mvs::OrientedPointCloud fuse_workspace(const fs::path& directory, const mvs::FusionOptions& options, ThreadPool& pool) {
  const mvs::DenseWorkspace workspace = mvs::read_dense_workspace(directory);
  std::vector<mvs::StereoView> views;
  std::vector<mvs::DepthMap> maps;
  std::vector<int> map_views;
  for (const auto& [name, image] : workspace.images) {
    mvs::StereoView view;
    view.camera = workspace.rig.camera(name);
    view.colour = image;
    views.push_back(std::move(view));
    if (const auto found = workspace.depth_maps.find(name); found != workspace.depth_maps.end()) {
      map_views.push_back(int(views.size()) - 1);
      maps.push_back(found->second);
    }
  }
  return mvs::fuse_depth_maps(views, map_views, maps, options, &pool);
}
#endif

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"Multi-view stereo time and accuracy on one virtual-studio frame."};
  int cameras = 13, width = 512, height = 384, frame = 0, threads = 0, window_radius = 0, window_step = 0,
      fusion_step = 0, iterations = 0, geometric_iterations = 0, pyramid_levels = -1, refine_passes = -1,
      refine_iterations = 0, poisson_depth = 0, surface_threads = 0, poisson_threads = 0, take_frames = 0;
  double voxel_size = 0;
  std::string cloud_file, workspace;
  bool verbose = false;
  std::string device = "cpu", capture = (fs::temp_directory_path() / "tega-mvs-bench").string(), out, config,
              meshes_out;
  app.add_option("--cameras", cameras, "Cameras.");
  app.add_option("--width", width, "Image width.");
  app.add_option("--height", height, "Image height.");
  app.add_option("--frame", frame, "Frame of the take.");
  app.add_option("--take-frames", take_frames,
                 "Then mesh frames 0 to N - 1 of the take pipelined, as tega mvs does, and print the seconds per frame.");
  app.add_option("--device", device, "cpu or cuda.");
  app.add_option("--threads", threads, "CPU threads (0 = all).");
  app.add_option("--capture", capture, "Where the rendered capture is kept between runs (suffixed with its size).");
  app.add_option("--out", out, "Write the fused cloud (fused.ply) here, and the mesh (mesh.ply) where it is made.");
#ifdef TEGA_BENCH_HAVE_SURFACE
  app.add_option("--meshes-out", meshes_out,
                 "Write the take's meshes as tega mvs lays them out (DIR/expressions/<frame>.ply), e.g. for bench/track.");
#endif
  app.add_option("--window-radius", window_radius, "PatchMatch window radius in pixels (default: the options').");
  app.add_option("--window-step", window_step, "PatchMatch window step in pixels (default: the options').");
  app.add_option("--fusion-step", fusion_step, "Fuse every n-th pixel and row (default: the options').");
  app.add_option("--iterations", iterations, "Photometric PatchMatch iterations (default: the options').");
  app.add_option("--geometric-iterations", geometric_iterations, "Geometric iterations (default: the options').");
  app.add_option("--pyramid-levels", pyramid_levels, "Coarse-to-fine levels (default: the options').");
  app.add_option("--refine-passes", refine_passes, "Geometric passes at each finer level (default: the options').");
  app.add_option("--refine-iterations", refine_iterations, "Iterations of those passes (default: the options').");
  app.add_option("--voxel-size", voxel_size, "Fusion voxel size in metres (default: the options').");
  app.add_flag("--verbose", verbose, "Log each stage's parts (debug level).");
#ifdef TEGA_BENCH_HAVE_MVS
  bool true_masks = false;
  app.add_flag("--true-masks", true_masks,
               "Mask the views by the true coverage, as builds without OpenCV (the GPU machine) must, not by the clean "
               "plate.");
  app.add_option("--config", config, "YAML whose `mvs` section sets the options.");
#endif
  app.add_option("--poisson-depth", poisson_depth, "Poisson octree depth (default: the options'; needs Open3D).");
  app.add_option("--surface-threads", surface_threads, "Threads of the surface stage (default: the options', else --threads).");
  app.add_option("--poisson-threads", poisson_threads, "Threads of Poisson itself (default: the options', 1).");
#ifdef TEGA_BENCH_HAVE_SURFACE
  app.add_option("--cloud", cloud_file,
                 "Mesh and score this fused cloud of the frame (e.g. one the GPU machine made) instead of making one.");
#ifdef TEGA_BENCH_HAVE_MVS
  app.add_option("--workspace", workspace,
                 "Fuse the frame's dense workspace that tega mvs --workspace wrote (MESHES/<take>/colmap/<frame>/) "
                 "again with these options, then mesh and score it: fusion tuned without making the depth maps.");
#endif
#endif
  CLI11_PARSE(app, argc, argv);
  init_logging(verbose ? 2 : 1);

  const fs::path root = render_capture(capture + "-" + std::to_string(cameras) + "-" + std::to_string(width) + "x" +
                                           std::to_string(height),
                                       cameras, width, height, std::max({2, frame + 1, take_frames}));
  ThreadPool pool(threads);
  const Rig rig = read_rig_json(root / "rig.json");
  const mvs::FrameLoader loader(read_take(root / "takes" / "expressions"), rig, (root / "rig.json").string());
#ifdef TEGA_BENCH_HAVE_MVS
  mvs::Options options;
  if (!config.empty()) load_options(options, config, "mvs");
  mvs::PatchMatchOptions pm = options.patch_match;
  mvs::FusionOptions fusion_options = options.fusion;
#ifdef TEGA_BENCH_HAVE_SURFACE
  mvs::SurfaceOptions surface_options = options.surface;
#endif
#else
  mvs::PatchMatchOptions pm;
  mvs::FusionOptions fusion_options;
#ifdef TEGA_BENCH_HAVE_SURFACE
  mvs::SurfaceOptions surface_options;
#endif
#endif
  if (fusion_step > 0) fusion_options.pixel_step = fusion_step;
  if (iterations > 0) pm.iterations = iterations;
  if (geometric_iterations > 0) pm.geometric_iterations = geometric_iterations;
  if (window_radius > 0) pm.window_radius = window_radius;
  if (window_step > 0) pm.window_step = window_step;
  if (pyramid_levels >= 0) pm.pyramid_levels = pyramid_levels;
  if (refine_passes >= 0) pm.refine_passes = refine_passes;
  if (refine_iterations > 0) pm.refine_iterations = refine_iterations;
  if (voxel_size > 0) fusion_options.voxel_size_m = voxel_size;
#ifdef TEGA_BENCH_HAVE_SURFACE
  if (poisson_depth > 0) surface_options.poisson_depth = poisson_depth;
  if (surface_threads > 0) surface_options.threads = surface_threads;
  if (poisson_threads > 0) surface_options.poisson_threads = poisson_threads;
#endif
  if (device == "cuda" && !mvs::cuda_device_available()) {
    std::fprintf(stderr, "mvs_bench: no CUDA device\n");
    return 1;
  }

#ifdef TEGA_BENCH_HAVE_SURFACE
  if (surface_options.threads == 0) surface_options.threads = pool.size();
#ifdef TEGA_BENCH_HAVE_MVS
  if (!workspace.empty()) {
    const auto start = Clock::now();
    const mvs::OrientedPointCloud cloud = fuse_workspace(workspace, fusion_options, pool);
    const double fusion_s = seconds_since(start);
    const Mesh mesh = mvs::reconstruct_surface(cloud, surface_options);
    report_mesh(mesh, root, frame);
    std::printf("%s: fused again into %d points in %.2f s, meshed in %.2f s\n", workspace.c_str(), cloud.size(),
                fusion_s, seconds_since(start) - fusion_s);
    return 0;
  }
#endif
  if (!cloud_file.empty()) {
    const mvs::OrientedPointCloud cloud = mvs::read_point_cloud_ply(cloud_file);
    const auto start = Clock::now();
    const Mesh mesh = mvs::reconstruct_surface(cloud, surface_options);
    const double surface_s = seconds_since(start);
    report_mesh(mesh, root, frame);
    std::printf("%s: %d points; surface (Poisson depth %d on %d threads, the rest on %d) %.2f s\n", cloud_file.c_str(),
                cloud.size(), surface_options.poisson_depth, surface_options.poisson_threads, surface_options.threads,
                surface_s);
    return 0;
  }
#endif
#ifdef TEGA_BENCH_HAVE_MVS
  const mvs::FrameLoader plate_loader(read_take(root / "takes" / "clean_plate"), rig, (root / "rig.json").string());
  const auto plates = plate_loader.load(0, pool);
  const char* mask_source = true_masks ? "true coverage" : "clean plate";
#else
  const char* mask_source = "true coverage";
#endif
  // A frame's first half (views, masks, depth maps), then its second (fusion
  // and surface): run one after the other for the split of one frame, and
  // pipelined across the frames of the take as `tega mvs` runs them (the load,
  // the depth maps, the rest).
  const mvs::Device depth_device = mvs::parse_device(device);
  const auto load = [&](int f) {
    PreparedFrame prepared;
    const auto start = Clock::now();
    prepared.views = loader.load(f, pool);
#ifdef TEGA_BENCH_HAVE_MVS
    if (!true_masks) {
      pool.parallel_for(0, int64_t(prepared.views.size()), [&](int64_t k) {
        prepared.views[size_t(k)].mask =
            mvs::subject_mask(prepared.views[size_t(k)].colour, plates[size_t(k)].colour, options.mask);
      });
    } else
#endif
      mask_from_truth(prepared.views, root, rig, f, pool);
    prepared.times.load_s = seconds_since(start);
    return prepared;
  };
  const auto prepare = [&](int, PreparedFrame prepared) {
    const std::vector<mvs::ViewTask> tasks = view_tasks(prepared.views, pm);
    const auto start = Clock::now();
    prepared.maps = mvs::estimate_depth_maps(prepared.views, tasks, pm, depth_device, &pool);
    prepared.times.depth_s = seconds_since(start);
    return prepared;
  };
  const auto finish = [&](PreparedFrame& prepared) {
    std::vector<int> map_views(prepared.views.size());
    std::iota(map_views.begin(), map_views.end(), 0);
    auto start = Clock::now();
    prepared.cloud = mvs::fuse_depth_maps(prepared.views, map_views, prepared.maps, fusion_options, &pool, depth_device);
    prepared.times.fusion_s = seconds_since(start);
#ifdef TEGA_BENCH_HAVE_SURFACE
    start = Clock::now();
    prepared.mesh = mvs::reconstruct_surface(prepared.cloud, surface_options);
    prepared.times.surface_s = seconds_since(start);
#endif
  };

  PreparedFrame one = prepare(frame, load(frame));
  finish(one);

  // Depth maps against the true fine mesh.
  const Mesh fine_topology = read_obj(root / "ground_truth" / "head" / "fine_topology.obj");
  char name[32];
  std::snprintf(name, sizeof name, "%06d.bin", frame);
  const Vertices fine = read_vertices_bin(root / "ground_truth" / "expressions" / "fine" / name);
  DepthScore score;
  for (size_t k = 0; k < one.views.size(); ++k)
    score_depth(one.maps[k], synth::render_depth(one.views[k].camera, fine, fine_topology.faces), score);
  std::sort(score.errors.begin(), score.errors.end());
  std::printf("mvs bench: %d cameras %dx%d, frame %d, depth on %s, %d threads, masks from the %s\n", cameras, width,
              height, frame, device.c_str(), pool.size(), mask_source);
  std::printf("depth maps: %lld pixels estimated; of those on the head: median error %.3f mm, %.1f %% within 1 mm, "
              "%.1f %% within 2 mm; %.1f %% of the head's pixels estimated\n",
              (long long)score.estimated, score.errors.empty() ? 0.0 : 1000 * score.errors[score.errors.size() / 2],
              100.0 * score.within_1mm / std::max<int64_t>(1, score.covered_and_estimated),
              100.0 * score.within_2mm / std::max<int64_t>(1, score.covered_and_estimated),
              100.0 * score.covered_and_estimated / std::max<int64_t>(1, score.covered));
  std::printf("fused cloud: %d points\n", one.cloud.size());
#ifdef TEGA_BENCH_HAVE_SURFACE
  report_mesh(one.mesh, root, frame);
  if (!out.empty()) {
    fs::create_directories(out);
    write_mesh(one.mesh, fs::path(out) / "mesh.ply");
  }
#endif
  if (!out.empty()) {
    fs::create_directories(out);
    mvs::write_point_cloud_ply(one.cloud, fs::path(out) / "fused.ply");
  }
  std::printf("one frame, stage by stage:\n%-10s %8s\n", "stage", "seconds");
  print_times(one.times, "");
  one = {};

  if (take_frames < 2) return 0;
  // The take: frame n + 1 gets its depth maps and frame n + 2 loads while
  // frame n is fused and meshed. Its rate is the time between frames finishing.
  std::vector<FrameTimes> times(static_cast<size_t>(take_frames));
  std::vector<double> finished_at(static_cast<size_t>(take_frames));
  std::vector<Mesh> meshes(static_cast<size_t>(take_frames));
  const auto take_start = Clock::now();
  mvs::for_each_frame_pipelined(0, take_frames, load, prepare, [&](int f, PreparedFrame prepared) {
    finish(prepared);
    times[size_t(f)] = prepared.times;
    meshes[size_t(f)] = std::move(prepared.mesh);
    finished_at[size_t(f)] = seconds_since(take_start);
  });
  std::printf("take of %d frames, pipelined (each stage's seconds include the other stages' use of the CPU):\n"
              "%-10s %8s %8s %8s %8s %10s\n",
              take_frames, "frame", "load", "depth", "fusion", "surface", "done at");
  for (int f = 0; f < take_frames; ++f) {
    const FrameTimes& t = times[size_t(f)];
    std::printf("%-10d %8.2f %8.2f %8.2f %8.2f %10.2f\n", f, t.load_s, t.depth_s, t.fusion_s, t.surface_s,
                finished_at[size_t(f)]);
  }
  std::printf("seconds per frame over the whole take: %.2f (%.2f s)\n", finished_at.back() / take_frames,
              finished_at.back());
  // Neither the first frame (nothing before it to overlap) nor the last
  // (nothing after it beside its fusion) shows the rate of a long take.
  if (take_frames >= 3)
    std::printf("seconds per frame in the steady state (frames 1 to %d): %.2f\n", take_frames - 2,
                (finished_at[size_t(take_frames - 2)] - finished_at.front()) / (take_frames - 2));
#ifdef TEGA_BENCH_HAVE_SURFACE
  for (int f = 0; f < take_frames; ++f) {
    std::printf("frame %d ", f);
    report_mesh(meshes[size_t(f)], root, f);
  }
  if (!meshes_out.empty()) {
    const fs::path folder = fs::path(meshes_out) / "expressions";
    fs::create_directories(folder);
    for (int f = 0; f < take_frames; ++f) {
      char name[32];
      std::snprintf(name, sizeof name, "%06d.ply", f);
      write_mesh(meshes[size_t(f)], folder / name);
    }
    std::printf("wrote the take's %d meshes under %s\n", take_frames, folder.c_str());
  }
#endif
  return 0;
}
