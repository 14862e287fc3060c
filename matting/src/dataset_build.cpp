#include "tega/matting/dataset_build.h"

#include <algorithm>
#include <cstdio>
#include <optional>

#include "clean_plate.h"
#include "opencv_threads.h"
#include "tega/core/dataset.h"
#include "tega/core/dataset_gaps.h"
#include "tega/core/downsample.h"
#include "tega/core/error.h"
#include "tega/core/files.h"
#include "tega/core/image_header.h"
#include "tega/core/log.h"
#include "tega/core/options.h"
#include "tega/core/progress.h"
#include "tega/core/rig.h"
#include "tega/core/take.h"
#include "tega/core/take_images.h"
#include "tega/core/thread_pool.h"
#include "tega/core/tracked.h"
#include "tega/core/undistort.h"
#include "tega/matting/dataset_image.h"
#include "tega/matting/matte.h"

namespace tega::matting {
namespace fs = std::filesystem;

namespace {

constexpr const char* kMattesDone = "mattes.json";

void check_options(const DatasetBuildOptions& o) {
  const auto fail = [](const std::string& what) { throw Error("dataset build options: " + what); };
  if (o.downsample < 1) fail("downsample must be 1 or more");
  if (o.frames < 0) fail("frames must be 0 (all) or positive");
  if (o.test_camera_count < 1) fail("test_camera_count must be 1 or more");
  if (o.png_compression < 0 || o.png_compression > 9) fail("png_compression must be in 0 .. 9");
  if (o.image_format != "png" && o.image_format != "zst")
    fail("image_format must be png or zst, not '" + o.image_format + "'");
  check_missing_image_limits(o.missing_images, "dataset build");
}

constexpr const char* kRemedy =
    "repair or recover the take's images (a camera that stopped recording, a disk that filled), or build from "
    "takes or frames that have them (options frames, test_takes)";

bool contains(const std::vector<std::string>& names, const std::string& name) {
  return std::find(names.begin(), names.end(), name) != names.end();
}

std::string frame_name(int frame) {
  char name[16];
  std::snprintf(name, sizeof name, "%06d", frame);
  return name;
}

// A tracked frame the dataset may take: enough cameras recorded it.
struct Candidate {
  const TakeInfo* take;
  TrackedFrame tracked;
  std::string id() const { return take->name + "_" + frame_name(tracked.frame); }
};

fs::path matte_path(const fs::path& mattes, const Candidate& frame, const std::string& camera) {
  return mattes / frame.take->name / camera / (frame_name(frame.tracked.frame) + ".png");
}

std::string view_name(const Candidate& frame, const std::string& camera) {
  return "camera " + camera + ", frame " + frame.id();
}

struct Inputs {
  CaptureInfo capture;
  fs::path rig_file;
  Rig rig;  // the capture's cameras, in the rig's order, with their distortion
  std::vector<TakeInfo> takes;
  TrackedSubject subject;
  std::vector<Candidate> candidates;
  std::optional<TakeInfo> clean_plate;  // matting here: the empty studio's take, if any
  std::string fingerprint;  // what the images depend on besides the options: the resume key
};

// The cameras the capture records, as the rig has them; each must divide by the factor.
Rig capture_rig(const CaptureInfo& capture, const fs::path& rig_file, int downsample) {
  const Rig full = read_rig_json(rig_file);
  Rig rig;
  for (const Camera& camera : full.cameras)
    if (contains(capture.cameras, camera.name)) rig.cameras.push_back(camera);
  for (const auto& name : capture.cameras)
    if (!full.contains(name)) throw Error(rig_file, "has no camera " + name + ", which the capture records");
  for (const Camera& camera : rig.cameras)
    if (camera.width % downsample != 0 || camera.height % downsample != 0)
      throw Error(rig_file, "camera " + camera.name + " is " + std::to_string(camera.width) + "x" +
                                std::to_string(camera.height) + ", which downsample " + std::to_string(downsample) +
                                " does not divide");
  return rig;
}

// Triangles of the template whose three corners are eyeball vertices.
std::vector<int32_t> eyeball_faces(const Mesh& mesh, const std::vector<int>& eyeball_vertices) {
  std::vector<bool> on_eyeball(static_cast<size_t>(mesh.num_vertices()), false);
  for (const int v : eyeball_vertices) on_eyeball[static_cast<size_t>(v)] = true;
  std::vector<int32_t> faces;
  for (Eigen::Index f = 0; f < mesh.faces.rows(); ++f)
    if (on_eyeball[mesh.faces(f, 0)] && on_eyeball[mesh.faces(f, 1)] && on_eyeball[mesh.faces(f, 2)])
      faces.push_back(static_cast<int32_t>(f));
  return faces;
}

Inputs read_inputs(const DatasetBuildRequest& request, const DatasetBuildOptions& options) {
  Inputs in;
  in.capture = read_capture(request.capture);
  in.rig_file = in.capture.rig_file(request.rig);
  in.rig = capture_rig(in.capture, in.rig_file, options.downsample);
  in.subject = read_tracked_subject(request.tracked);
  if (!in.subject.neutral.has_uvs())
    throw Error(request.tracked / "identity.json", "names a neutral mesh without UVs; the dataset's template needs them");

  const bool matting_here = request.mattes.empty();
  in.fingerprint = "capture: " + fs::absolute(request.capture).string() + "\nrig: " + read_text_file(in.rig_file) +
                   "\ntracked: " + fs::absolute(request.tracked).string() +
                   "\nmattes: " + (matting_here ? "made here" : fs::absolute(request.mattes).string()) + "\n";
  if (matting_here) {
    in.clean_plate = clean_plate_take(in.capture, options.matte);
    for (const Camera& camera : in.rig.cameras)
      if (in.clean_plate && !in.clean_plate->has_image(camera.name, 0))
        throw Error(in.clean_plate->image_path(camera.name, 0), "is missing: camera " + camera.name + " has no clean plate");
  }
  const std::vector<std::string> names = in.capture.performance_takes({}, "to build a dataset from");
  in.takes.reserve(names.size());  // candidates point into it
  int incomplete = 0;
  for (const auto& name : names) {
    const TakeInfo& take = in.takes.emplace_back(read_take(in.capture.root / "takes" / name));
    if (!matting_here) {
      const fs::path mattes_done = request.mattes / name / kMattesDone;
      if (!fs::exists(mattes_done))
        throw Error(mattes_done, "is missing: take " + name + " was not matted to its end (run tega matte)");
      in.fingerprint += name + " mattes: " + read_text_file(mattes_done) + "\n";
    }
    std::vector<TrackedFrame> tracked = read_tracked_take(request.tracked, name);
    in.fingerprint += name + " tracked: " + read_text_file(request.tracked / name / "track.json") + "\n";
    for (auto& frame : tracked) {
      if (!frame.tracked()) continue;
      if (frame.frame < 0 || frame.frame >= take.frames)
        throw Error(frame.mesh, "is tracked frame " + std::to_string(frame.frame) + " of take " + name + ", which has " +
                                    std::to_string(take.frames) + " frames");
      const auto recorded = std::count_if(in.rig.cameras.begin(), in.rig.cameras.end(),
                                          [&](const Camera& c) { return take.has_image(c.name, frame.frame); });
      if (recorded > 0 && static_cast<double>(recorded) >=
                              options.missing_images.min_camera_fraction_per_frame * in.rig.cameras.size())
        in.candidates.push_back({&take, std::move(frame)});
      else
        ++incomplete;
    }
  }
  if (incomplete > 0)
    logging::warn("dataset build: %d tracked frame(s) left out before sampling: too few cameras recorded them "
                  "(take.json: missing; missing_images.min_camera_fraction_per_frame)",
                  incomplete);
  if (in.candidates.empty())
    throw Error(request.tracked, "has no tracked frame that enough cameras recorded (take.json: missing; "
                                 "missing_images.min_camera_fraction_per_frame): nothing to build a dataset from");
  return in;
}

std::vector<std::string> held_out_takes(const Inputs& in, const DatasetBuildOptions& options) {
  std::vector<std::string> performance;
  for (const auto& take : in.takes) performance.push_back(take.name);
  for (const auto& name : options.test_takes)
    if (!contains(performance, name))
      throw Error(in.capture.root / "capture.json", "has no performance take '" + name + "' (named in test_takes)");
  if (!options.test_takes.empty()) return options.test_takes;
  if (performance.size() < 2) return {};
  return {performance.back()};
}

void choose_cameras(Dataset& dataset, const Inputs& in, const DatasetBuildOptions& options) {
  for (const auto& name : options.test_cameras)
    if (!in.rig.contains(name))
      throw Error(in.rig_file, "has no camera '" + name + "' of the capture (named in test_cameras)");
  dataset.test.cameras =
      options.test_cameras.empty() ? spread_test_cameras(in.rig, options.test_camera_count) : options.test_cameras;
  for (const Camera& camera : in.rig.cameras)
    if (!contains(dataset.test.cameras, camera.name) || in.rig.cameras.size() == 1)
      dataset.train.cameras.push_back(camera.name);
  if (dataset.train.cameras.empty()) throw Error(in.rig_file, "test_cameras hold out every camera; none is left to train on");
}

// Everything that can be checked cheaply, before the heavy work: each image
// exists (returned: why each, frame-major, cannot be used; empty when it
// can), and so does the matte of each that does (`mattes` empty: none is
// read), with the captured size.
std::vector<std::string> check_views(const std::vector<const Candidate*>& frames, const Inputs& in,
                                     const fs::path& mattes, ThreadPool& pool) {
  const size_t n = in.rig.cameras.size();
  std::vector<std::string> unusable(frames.size() * n);
  pool.parallel_for(0, static_cast<int64_t>(frames.size() * n), [&](int64_t i) {
    const Candidate& f = *frames[static_cast<size_t>(i) / n];
    const Camera& camera = in.rig.cameras[static_cast<size_t>(i) % n];
    const fs::path image = f.take->image_path(camera.name, f.tracked.frame);
    if (!f.take->has_image(camera.name, f.tracked.frame)) {
      unusable[i] = image.string() + ": was not recorded (take.json: missing)";
      return;
    }
    if (!fs::exists(image)) {
      unusable[i] = image.string() + ": is missing (" + view_name(f, camera.name) + ")";
      return;
    }
    if (mattes.empty()) return;
    const fs::path matte = matte_path(mattes, f, camera.name);
    if (!fs::exists(matte)) throw Error(matte, "is missing (the matte of " + view_name(f, camera.name) + "; run tega matte)");
    check_matte(matte, read_image_header(matte), camera.width, camera.height);
  });
  return unusable;
}

}  // namespace

DatasetBuildSummary build_dataset(const DatasetBuildRequest& request, const DatasetBuildOptions& options) {
  check_options(options);
  const Inputs in = read_inputs(request, options);

  const std::vector<std::string> test_takes = held_out_takes(in, options);
  std::vector<const Candidate*> frames;
  for (const size_t i : evenly_spaced_indices(in.candidates.size(), options.frames))
    frames.push_back(&in.candidates[i]);

  ThreadPool pool(options.threads);
  const std::vector<std::string> unusable = check_views(frames, in, request.mattes, pool);

  Dataset dataset;
  dataset.image_extension = "." + options.image_format;
  dataset.template_mesh = in.subject.neutral;
  dataset.eyeball_faces = eyeball_faces(in.subject.neutral, in.subject.eyeball_vertices);
  dataset.landmark_vertices.assign(in.subject.landmark_vertices.begin(), in.subject.landmark_vertices.end());
  for (const Camera& camera : in.rig.cameras)
    dataset.rig.cameras.push_back(without_distortion(camera).scaled(1.0 / options.downsample));
  choose_cameras(dataset, in, options);
  for (const Candidate* f : frames) {
    dataset.frames.push_back({f->id(), f->take->name, f->tracked.head_to_world});
    (contains(test_takes, f->take->name) ? dataset.test : dataset.train).frames.push_back(f->id());
  }
  const size_t n = in.rig.cameras.size();
  for (size_t i = 0; i < unusable.size(); ++i) {
    if (unusable[i].empty()) continue;
    logging::warn("dataset build: leaving out %s", unusable[i].c_str());
    dataset.missing_images.push_back({in.rig.cameras[i % n].name, frames[i / n]->id(), unusable[i]});
  }
  {
    // Before the heavy work: a capture missing too much fails now.
    Dataset planned = dataset;
    apply_missing_image_limits(planned, options.missing_images, request.capture, kRemedy);
  }

  DatasetBuildOptions resume_options = options;
  resume_options.threads = resume_options.matte.threads = 0;  // the output does not depend on them
  StagedDirectory staged(request.out, request.replace_existing, options_to_yaml(resume_options) + in.fingerprint);
  dataset.root = staged.path();

  const int vertices = dataset.template_mesh.num_vertices();
  fs::create_directories(dataset.mesh_path("x").parent_path());
  pool.parallel_for(0, static_cast<int64_t>(frames.size()), [&](int64_t i) {
    const Candidate& f = *frames[static_cast<size_t>(i)];
    const fs::path target = dataset.mesh_path(f.id());
    if (!fs::exists(target)) write_vertices_bin(read_vertices_bin(f.tracked.mesh, vertices), target);
  });

  const int64_t total = static_cast<int64_t>(frames.size() * in.rig.cameras.size());
  Progress progress("dataset build", total, "images");
  const OpenCvSingleThreaded one_opencv_thread;
  int kept = 0;
  for (size_t c = 0; c < in.rig.cameras.size(); ++c) {
    const Camera& captured = in.rig.cameras[c];
    const std::string& camera = captured.name;
    fs::create_directories(dataset.image_path(camera, "x").parent_path());
    std::vector<const Candidate*> to_write;
    for (const Candidate* f : frames) {
      if (!dataset.has_image(camera, f->id())) {
        progress.advance();
      } else if (fs::exists(dataset.image_path(camera, f->id()))) {
        ++kept;
        progress.advance();
      } else {
        to_write.push_back(f);
      }
    }
    if (to_write.empty()) continue;
    // Once per camera: at 6144 x 4096 the maps take a second to make.
    const DatasetResampler resampler(captured, options.downsample);
    // Everything happens at the dataset's size: the full-size photo is never made.
    const int downsample = options.downsample;
    std::optional<CameraMatting> matting;
    if (request.mattes.empty())
      matting.emplace(recorded_camera_at_dataset_size(captured, downsample),
                      in.clean_plate ? read_recorded_rgb(*in.clean_plate, camera, 0, captured.width, captured.height,
                                                         downsample)
                                     : Image8(),
                      options.matte);
    // Why each image cannot be used (undecodable, the wrong size); empty when it can.
    std::vector<std::string> unreadable(to_write.size());
    pool.parallel_for(0, static_cast<int64_t>(to_write.size()), [&](int64_t i) {
      const Candidate& f = *to_write[static_cast<size_t>(i)];
      Image8 rgb;
      try {
        rgb = read_recorded_rgb(*f.take, camera, f.tracked.frame, captured.width, captured.height, downsample);
      } catch (const Error& e) {
        unreadable[static_cast<size_t>(i)] = e.what();
        progress.advance();
        return;
      }
      const Image8 matte =
          matting ? matting->matte(rgb, read_vertices_bin(f.tracked.mesh, vertices), dataset.template_mesh.faces)
                  : box_downsample(read_matte(matte_path(request.mattes, f, camera), captured.width, captured.height,
                                              view_name(f, camera)),
                                   downsample);
      const Image8 rgba = resampler.rgba(rgb, matte);
      const PixelView view{rgba.pixels.data(), rgba.width, rgba.height, 4, 8, static_cast<size_t>(rgba.width) * 4};
      if (options.image_format == "zst") write_zstd_view(view, dataset.image_path(camera, f.id()), 1);
      else write_png_view(view, dataset.image_path(camera, f.id()), options.png_compression);
      progress.advance();
    });
    for (size_t i = 0; i < to_write.size(); ++i) {
      if (unreadable[i].empty()) continue;
      logging::warn("dataset build: leaving out %s", unreadable[i].c_str());
      dataset.missing_images.push_back({camera, to_write[i]->id(), unreadable[i]});
    }
  }
  progress.finish();

  drop_frames_lacking_images(dataset, options.missing_images, request.capture, kRemedy, "dataset build");
  write_dataset_manifest(dataset);
  validate_dataset(read_dataset(staged.path()));
  staged.commit();

  DatasetBuildSummary summary;
  summary.dataset = staged.final_path();
  summary.train_frames = static_cast<int>(dataset.train.frames.size());
  summary.test_frames = static_cast<int>(dataset.test.frames.size());
  summary.train_cameras = dataset.train.cameras;
  summary.test_cameras = dataset.test.cameras;
  summary.images = static_cast<int>(dataset.frames.size() * n - dataset.missing_images.size());
  summary.images_kept = kept;
  summary.missing_images = static_cast<int>(dataset.missing_images.size());
  summary.dropped_frames = static_cast<int>(dataset.dropped_frames.size());
  return summary;
}

}  // namespace tega::matting
