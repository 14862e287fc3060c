#include "tega/mvs/reconstruction.h"

#include <chrono>
#include <cstdio>
#include <map>
#include <optional>
#include <nlohmann/json.hpp>

#include "tega/core/error.h"
#include "tega/core/files.h"
#include "tega/core/log.h"
#include "tega/core/options.h"
#include "tega/core/progress.h"
#include "tega/core/rig.h"
#include "tega/core/thread_pool.h"
#include "tega/core/undistort.h"
#include "tega/mvs/colmap_workspace.h"
#include "tega/core/take_images.h"
#include "tega/mvs/frame_pipeline.h"
#include "tega/mvs/frame_views.h"
#include "tega/mvs/view_selection.h"

namespace fs = std::filesystem;

namespace tega::mvs {
namespace {

using Clock = std::chrono::steady_clock;

double seconds_since(Clock::time_point start) {
  return std::chrono::duration<double>(Clock::now() - start).count();
}

std::string frame_name(int frame) {
  char name[16];
  std::snprintf(name, sizeof name, "%06d", frame);
  return name;
}

bool sees_subject(const StereoView& view, const MaskOptions& options) {
  if (view.mask.empty()) return true;
  int64_t inside = 0;
  for (uint8_t m : view.mask) inside += m != 0;
  return double(inside) >= options.min_view_share * double(view.mask.size());
}

std::string camera_list(const std::vector<StereoView>& views, const std::vector<int>& indices) {
  std::string names;
  for (int k : indices) names += (names.empty() ? "" : ", ") + views[k].camera.name;
  return names.empty() ? "none" : names;
}

}  // namespace

Device resolve_device(const std::string& name) {
  if (name == "auto") return cuda_device_available() ? Device::cuda : Device::cpu;
  return parse_device(name);
}

namespace {

// The first half of a frame: source views, depth ranges and the depth maps.
FrameReconstruction estimate_depth(const std::vector<StereoView>& views, const Options& options, Device device,
                                   const std::string& label, ThreadPool& pool) {
  std::vector<int> seeing;
  for (int k = 0; k < int(views.size()); ++k)
    if (sees_subject(views[k], options.mask)) seeing.push_back(k);
  if (int(seeing.size()) < options.min_views)
    throw Error(label + ": the subject is seen by " + std::to_string(seeing.size()) + " camera(s) (" +
                camera_list(views, seeing) + "); at least " + std::to_string(options.min_views) + " are needed");

  std::vector<Camera> cameras;
  for (int k : seeing) cameras.push_back(views[k].camera);
  const std::optional<Eigen::Vector3d> focus = rig_focus_point(cameras);
  const bool given_range = !options.depth_range_m.empty();
  if (!given_range && !focus)
    throw Error(label + ": the cameras do not aim at a common point (" + camera_list(views, seeing) +
                "); give depth_range_m");
  if (given_range && (options.depth_range_m.size() != 2 || !(options.depth_range_m[0] > 0) ||
                      !(options.depth_range_m[1] > options.depth_range_m[0])))
    throw Error("mvs: depth_range_m must be [min, max] with 0 < min < max");
  const auto ranked = focus ? select_source_views(cameras, *focus, options.patch_match.source_views)
                            : select_source_views_by_axes(cameras, options.patch_match.source_views);

  FrameReconstruction result;
  std::vector<ViewTask> tasks;
  for (size_t k = 0; k < seeing.size(); ++k) {
    if (ranked[k].empty()) {
      logging::warn("%s: %s shares no usable baseline with another camera; it gets no depth map", label.c_str(),
                    cameras[k].name.c_str());
      continue;
    }
    ViewTask task;
    task.reference = seeing[k];
    for (int s : ranked[k]) task.sources.push_back(seeing[s]);
    if (!given_range) {
      const double centre = cameras[k].world_to_camera.apply(*focus).z();
      task.depth_min = float(std::max(centre - options.subject_radius_m, 0.05 * centre));
      task.depth_max = float(centre + options.subject_radius_m);
    } else {
      task.depth_min = float(options.depth_range_m[0]);
      task.depth_max = float(options.depth_range_m[1]);
    }
    result.map_views.push_back(task.reference);
    result.source_views.push_back(task.sources);
    tasks.push_back(std::move(task));
  }

  const auto start = Clock::now();
  result.depth_maps = estimate_depth_maps(views, tasks, options.patch_match, device, &pool);
  result.timings.depth_s = seconds_since(start);
  return result;
}

// The second half: fusion and the surface.
void fuse_and_mesh(const std::vector<StereoView>& views, const Options& options, Device device, const std::string& label,
                   ThreadPool& pool, FrameReconstruction& result) {
  auto start = Clock::now();
  result.cloud = fuse_depth_maps(views, result.map_views, result.depth_maps, options.fusion, &pool, device);
  result.timings.fusion_s = seconds_since(start);
  if (result.cloud.size() < 100)
    throw Error(label + ": only " + std::to_string(result.cloud.size()) +
                " points survived fusion; the views do not agree on a surface (check the rig and the images)");

  start = Clock::now();
  SurfaceOptions surface = options.surface;
  if (surface.threads == 0) surface.threads = pool.size();
  result.mesh = reconstruct_surface(result.cloud, surface);
  result.timings.surface_s = seconds_since(start);
}

}  // namespace

FrameReconstruction reconstruct_views(const std::vector<StereoView>& views, const Options& options, Device device,
                                      const std::string& label, ThreadPool& pool) {
  FrameReconstruction result = estimate_depth(views, options, device, label, pool);
  fuse_and_mesh(views, options, device, label, pool, result);
  return result;
}

namespace {

// A COLMAP dense workspace of one frame, staged and renamed into place.
void write_frame_workspace(const std::vector<StereoView>& views, const FrameReconstruction& r, const fs::path& dir) {
  DenseWorkspace workspace;
  for (const auto& view : views) {
    workspace.rig.cameras.push_back(view.camera);
    workspace.images[view.camera.name] = view.colour;
  }
  for (size_t k = 0; k < r.map_views.size(); ++k) {
    const std::string& name = views[r.map_views[k]].camera.name;
    workspace.depth_maps[name] = r.depth_maps[k];
    for (int s : r.source_views[k]) workspace.source_views[name].push_back(views[s].camera.name);
  }
  workspace.fused = r.cloud;
  StagedDirectory staged(dir, true);
  write_dense_workspace(workspace, staged.path());
  staged.commit();
}

nlohmann::json frame_record(int frame, const std::vector<StereoView>& views, const FrameReconstruction& r,
                            const std::string& done_key) {
  nlohmann::json cameras = nlohmann::json::array();
  int64_t depth_pixels = 0;
  for (size_t k = 0; k < r.map_views.size(); ++k) {
    cameras.push_back(views[r.map_views[k]].camera.name);
    depth_pixels += r.depth_maps[k].valid_pixels();
  }
  const auto& t = r.timings;
  return {{"frame", frame},
          {"depth_map_cameras", cameras},
          {"depth_pixels", depth_pixels},
          {"points", r.cloud.size()},
          {"vertices", r.mesh.num_vertices()},
          {"faces", r.mesh.num_faces()},
          {"seconds", {{"load", t.load_s}, {"depth", t.depth_s}, {"fusion", t.fusion_s}, {"surface", t.surface_s},
                       {"write", t.write_s}}},
          {"made_with", done_key}};
}

bool frame_done(const fs::path& out, int frame, const std::string& done_key) {
  const fs::path record = out / (frame_name(frame) + ".json");
  if (!fs::exists(record) || !fs::exists(out / (frame_name(frame) + ".ply"))) return false;
  try {
    return nlohmann::json::parse(read_text_file(record)).value("made_with", "") == done_key;
  } catch (const std::exception&) {
    return false;  // unreadable: made again
  }
}

std::optional<TakeInfo> clean_plate_take(const CaptureInfo& capture) {
  for (const auto& take : capture.takes)
    if (take.kind == "clean_plate") return read_take(capture.root / "takes" / take.name);
  return std::nullopt;
}

}  // namespace

namespace {

struct TakeJob {
  const FrameLoader& loader;
  const std::map<std::string, Image8>& plates;  // camera -> undistorted clean plate
  fs::path out;
  int first, end;
  std::string done_key;  // options and rig: what a finished frame was made with
};

std::string frame_label(const TakeInfo& take, int frame) {
  return "take " + take.name + " frame " + std::to_string(frame);
}

// Runs `work`, naming the frame in the tega::Error it throws.
template <class Work>
auto naming_the_frame(const std::string& label, Work&& work) {
  try {
    return work();
  } catch (const Error& e) {
    const std::string message = e.what();
    throw Error(message.rfind(label, 0) == 0 ? message : label + ": " + message);
  }
}

// A frame's photos and masks; empty where an earlier run made it.
struct LoadedFrame {
  std::vector<StereoView> views;
  double load_s = 0;
  bool done_before = false;
};

// A frame with its depth maps; empty where an earlier run made it.
struct PreparedFrame {
  std::vector<StereoView> views;
  FrameReconstruction reconstruction;
  bool done_before = false;
};

// Frames in a pipeline (frame_pipeline.h): while this frame is fused, meshed
// and written, the next gets its depth maps, mostly on the GPU, and the one
// after loads. The stages share the pool.
void reconstruct_frames(const TakeJob& job, const Options& options, MvsSummary& summary, ThreadPool& pool) {
  const TakeInfo& take = job.loader.take();
  fs::create_directories(job.out);
  Progress progress("mvs " + take.name, job.end - job.first, "frames");
  const auto load = [&](int frame) {
    LoadedFrame loaded;
    if (frame_done(job.out, frame, job.done_key)) {
      loaded.done_before = true;
      return loaded;
    }
    return naming_the_frame(frame_label(take, frame), [&] {
      const auto start = Clock::now();
      loaded.views = job.loader.load(frame, pool);
      pool.parallel_for(0, int64_t(loaded.views.size()), [&](int64_t k) {
        StereoView& view = loaded.views[size_t(k)];
        const auto plate = job.plates.find(view.camera.name);
        if (plate != job.plates.end()) view.mask = subject_mask(view.colour, plate->second, options.mask);
      });
      loaded.load_s = seconds_since(start);
      return std::move(loaded);
    });
  };
  const auto prepare = [&](int frame, LoadedFrame loaded) {
    PreparedFrame prepared;
    prepared.done_before = loaded.done_before;
    if (prepared.done_before) return prepared;
    const std::string label = frame_label(take, frame);
    return naming_the_frame(label, [&] {
      prepared.views = std::move(loaded.views);
      prepared.reconstruction = estimate_depth(prepared.views, options, summary.device, label, pool);
      prepared.reconstruction.timings.load_s = loaded.load_s;
      return std::move(prepared);
    });
  };
  const auto finish = [&](int frame, PreparedFrame prepared) {
    if (prepared.done_before) {
      ++summary.frames_skipped;
      progress.advance();
      return;
    }
    const std::string label = frame_label(take, frame);
    const std::vector<StereoView>& views = prepared.views;
    FrameReconstruction& r = prepared.reconstruction;
    naming_the_frame(label, [&] {
      fuse_and_mesh(views, options, summary.device, label, pool, r);
      const auto start = Clock::now();
      if (options.write_workspace) write_frame_workspace(views, r, job.out / "colmap" / frame_name(frame));
      write_mesh(r.mesh, job.out / (frame_name(frame) + ".ply"));
      r.timings.write_s = seconds_since(start);
      // Written last: its presence marks the frame done.
      write_text_atomic(job.out / (frame_name(frame) + ".json"), frame_record(frame, views, r, job.done_key).dump(2));
    });
    const auto& t = r.timings;
    logging::info("%s: %zu depth maps, %d points, %d faces; load %.1f s, depth %.1f s, fusion %.1f s, surface %.1f s",
                  label.c_str(), r.depth_maps.size(), r.cloud.size(), r.mesh.num_faces(), t.load_s, t.depth_s,
                  t.fusion_s, t.surface_s);
    ++summary.frames_done;
    progress.advance();
  };
  for_each_frame_pipelined(job.first, job.end, load, prepare, finish);
  progress.finish();
}

// The defaults' matching windows are sized for 512 x 384: at a studio's 3072 x 2048 they span a
// sixth of the face they are meant to (docs/mvs.md#options), which nothing else would tell. A third
// is what the studio's settings span, the narrowest measured to gain.
void warn_of_small_windows(const Rig& rig, const PatchMatchOptions& patch_match) {
  int widest = 0;
  for (const Camera& camera : rig.cameras) widest = std::max(widest, camera.width);
  if (widest <= 384 * patch_match.window_radius) return;
  logging::warn("mvs: the cameras are %d pixels wide and patch_match.window_radius is %d: the windows cover under "
                "a third as much of the face as the defaults' at 512 x 384; scale window_radius and window_step "
                "with the image (8 and 4 at 3072 x 2048, as studio_configs/studio13-capture.yaml sets them; "
                "docs/mvs.md#options)",
                widest, patch_match.window_radius);
}

}  // namespace

MvsSummary reconstruct_capture(const MvsRequest& request, const Options& options) {
  const CaptureInfo capture = read_capture(request.capture);
  const fs::path rig_file = capture.rig_file(request.rig);
  const Rig rig = read_rig_json(rig_file);
  const std::vector<std::string> takes = capture.performance_takes(request.takes, "to mesh");

  MvsSummary summary;
  summary.device = resolve_device(options.device);
  ThreadPool pool(options.threads);
  std::map<std::string, Image8> plates;
  if (options.mask.use_clean_plate) {
    if (auto plate = clean_plate_take(capture)) {
      const FrameLoader plate_loader(*plate, rig, rig_file.string());
      for (auto& view : plate_loader.load(0, pool)) plates[view.camera.name] = std::move(view.colour);
    } else {
      logging::info("mvs: the capture has no clean plate; every pixel is searched");
    }
  }
  const std::string done_key = options_to_yaml(options) + "# rig\n" + read_text_file(rig_file);
  warn_of_small_windows(rig, options.patch_match);

  for (const auto& name : takes) {
    const FrameLoader loader(read_take(capture.root / "takes" / name), rig, rig_file.string());
    const TakeInfo& take = loader.take();
    if (take.kind != "performance")
      logging::warn("mvs: take %s is a %s take, not a performance", take.name.c_str(), take.kind.c_str());
    const int end = request.end_frame < 0 ? take.frames : std::min(request.end_frame, take.frames);
    if (request.first_frame >= take.frames)
      throw Error("mvs: take " + take.name + " has frames 0 to " + std::to_string(take.frames - 1) + "; asked for " +
                  std::to_string(request.first_frame) + " on");
    logging::info("mvs: take %s, frames %d to %d, %zu cameras, depth on %s", take.name.c_str(), request.first_frame,
                  end - 1, take.cameras.size(), summary.device == Device::cuda ? "cuda" : "cpu");
    reconstruct_frames({loader, plates, request.out / take.name, request.first_frame, end, done_key}, options, summary,
                       pool);
    ++summary.takes;
  }
  return summary;
}

FrameTimings reconstruct_photos(const PhotoRequest& request, const Options& options) {
  const Rig rig = fs::is_directory(request.rig) ? read_colmap_text(request.rig, request.rig_metres_per_unit)
                                                : read_rig_json(request.rig);
  ThreadPool pool(options.threads);
  const auto start = Clock::now();
  std::vector<StereoView> views(rig.cameras.size());
  pool.parallel_for(0, int64_t(rig.cameras.size()), [&](int64_t k) {
    const Camera& camera = rig.cameras[size_t(k)];
    fs::path file;
    for (const char* extension : {".png", ".jpg", ".jpeg", ".JPG", ".tif", ".tiff"})
      if (fs::exists(request.images / (camera.name + extension))) file = request.images / (camera.name + extension);
    if (file.empty()) throw Error(request.images, "has no image of camera " + camera.name + " (" + camera.name + ".png, .jpg or .tif)");
    const Image8 image = rgb_of(read_image_u8(file));
    if (image.width != camera.width || image.height != camera.height)
      throw Error(file, "is " + std::to_string(image.width) + "x" + std::to_string(image.height) + ", but camera " +
                            camera.name + " of the rig is " + std::to_string(camera.width) + "x" +
                            std::to_string(camera.height));
    StereoView& view = views[size_t(k)];
    view.camera = without_distortion(camera);
    view.colour = undistort_image(image, camera);
    view.grey = grey_of(view.colour);
  });
  const double load_s = seconds_since(start);
  FrameReconstruction r = reconstruct_views(views, options, resolve_device(options.device), request.images.string(), pool);
  r.timings.load_s = load_s;
  const auto write_start = Clock::now();
  if (!request.workspace.empty()) write_frame_workspace(views, r, request.workspace);
  write_mesh(r.mesh, request.out);
  r.timings.write_s = seconds_since(write_start);
  return r.timings;
}

FrameTimings mesh_workspace(const fs::path& workspace, const fs::path& out, const Options& options,
                            const std::string& type) {
  FrameTimings timings;
  auto start = Clock::now();
  const DenseWorkspace input = read_dense_workspace(workspace, type);
  std::vector<StereoView> views;
  std::vector<int> map_views;
  std::vector<DepthMap> maps;
  for (const auto& camera : input.rig.cameras) {
    const auto map = input.depth_maps.find(camera.name);
    if (map == input.depth_maps.end()) continue;
    StereoView view;
    view.camera = camera;
    view.colour = rgb_of(input.images.at(camera.name));
    view.grey = grey_of(view.colour);
    map_views.push_back(int(views.size()));
    maps.push_back(map->second);
    views.push_back(std::move(view));
  }
  if (views.size() < 2) throw Error(workspace, "has depth maps (" + type + ") for fewer than two views");
  timings.load_s = seconds_since(start);

  ThreadPool pool(options.threads);
  start = Clock::now();
  const OrientedPointCloud cloud =
      fuse_depth_maps(views, map_views, maps, options.fusion, &pool, resolve_device(options.device));
  timings.fusion_s = seconds_since(start);
  if (cloud.size() < 100)
    throw Error(workspace, "only " + std::to_string(cloud.size()) + " points survived fusion of its depth maps");
  start = Clock::now();
  SurfaceOptions surface = options.surface;
  if (surface.threads == 0) surface.threads = pool.size();
  write_mesh(reconstruct_surface(cloud, surface), out);
  timings.surface_s = seconds_since(start);
  return timings;
}

}  // namespace tega::mvs
