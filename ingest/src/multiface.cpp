#include "tega/ingest/multiface.h"

#include <algorithm>
#include <set>

#include "tega/core/dataset.h"
#include "tega/core/dataset_gaps.h"
#include "tega/core/downsample.h"
#include "tega/core/error.h"
#include "tega/core/files.h"
#include "tega/core/image.h"
#include "tega/core/image_header.h"
#include "tega/core/log.h"
#include "tega/core/progress.h"
#include "tega/core/thread_pool.h"
#include "tega/core/undistort.h"
#include "tega/ingest/camera_selection.h"
#include "tega/ingest/matte.h"
#include "tega/ingest/multiface_capture.h"

namespace tega::ingest {
namespace fs = std::filesystem;

namespace {

void check_options(const IngestOptions& o) {
  const auto fail = [](const std::string& what) { throw Error("ingest options: " + what); };
  if (o.width <= 0 || o.height <= 0) fail("width and height must be positive");
  if (o.frames <= 0) fail("frames must be positive");
  if (o.test_frames < 0) fail("test_frames must be 0 (all) or positive");
  if (o.downsample < 1) fail("downsample must be 1 or more");
  if (o.width % o.downsample != 0 || o.height % o.downsample != 0)
    fail("downsample " + std::to_string(o.downsample) + " does not divide the image size " + std::to_string(o.width) +
         "x" + std::to_string(o.height));
  if (o.matte != "mesh" && o.matte != "none") fail("matte must be 'mesh' or 'none', not '" + o.matte + "'");
  if (o.matte_dilation_px < 0 || o.matte_feather_px < 0) fail("matte_dilation_px and matte_feather_px must be >= 0");
  if (!o.face_forward.empty() && o.face_forward.size() != 3) fail("face_forward must be empty or 3 numbers");
  check_missing_image_limits(o.missing_images, "ingest");
}

constexpr const char* kRemedy =
    "restore the capture's images (a download cut short?), or leave out the cameras or expressions that lack them "
    "(options cameras, expressions)";

std::vector<MultifaceFrame> sample_uniformly(const std::vector<MultifaceFrame>& all, int count) {
  std::vector<MultifaceFrame> picked;
  for (const size_t i : evenly_spaced_indices(all.size(), count)) picked.push_back(all[i]);
  return picked;
}

bool has_prefix(const std::string& name, const std::vector<std::string>& prefixes) {
  return std::any_of(prefixes.begin(), prefixes.end(), [&](const std::string& p) { return name.rfind(p, 0) == 0; });
}

struct FramePlan {
  std::vector<MultifaceFrame> train, test;
  MultifaceFrame template_frame;
};

FramePlan plan_frames(const MultifaceCapture& capture, const IngestOptions& o) {
  const fs::path list_file = capture.frame_list();
  const std::vector<MultifaceFrame> listed = read_frame_list(list_file);
  std::vector<std::string> sequences;  // in order of first appearance
  std::set<std::string> ids;
  for (const auto& f : listed) {
    if (!ids.insert(f.id()).second) throw Error(list_file, "lists frame '" + f.frame + "' of " + f.sequence + " twice");
    if (std::find(sequences.begin(), sequences.end(), f.sequence) == sequences.end()) sequences.push_back(f.sequence);
  }
  for (const auto& name : o.expressions)
    if (std::find(sequences.begin(), sequences.end(), name) == sequences.end())
      throw Error(list_file, "lists no expression '" + name + "' (named in the ingest options)");
  if (!o.expressions.empty()) {
    std::erase_if(sequences, [&](const std::string& s) {
      return std::find(o.expressions.begin(), o.expressions.end(), s) == o.expressions.end();
    });
  }

  std::set<std::string> held_out;
  for (const auto& s : sequences)
    if (has_prefix(s, o.test_expressions)) held_out.insert(s);
  if (held_out.empty()) {
    logging::warn("%s: no expression matches test_expressions; holding out the last one, %s", list_file.c_str(),
                  sequences.back().c_str());
    held_out.insert(sequences.back());
  }
  if (held_out.size() == sequences.size())
    throw Error(list_file, "every expression would be held out for testing; none is left to train on");

  std::vector<MultifaceFrame> train, test;
  for (const auto& f : listed) {
    if (std::find(sequences.begin(), sequences.end(), f.sequence) == sequences.end()) continue;
    (held_out.count(f.sequence) ? test : train).push_back(f);
  }
  FramePlan plan{sample_uniformly(train, o.frames), sample_uniformly(test, o.test_frames), listed.front()};
  const auto neutral = std::find_if(listed.begin(), listed.end(),
                                    [&](const MultifaceFrame& f) { return f.sequence == o.neutral_expression; });
  if (neutral != listed.end()) plan.template_frame = *neutral;
  return plan;
}

// The topology and UVs of the template OBJ with the template frame's
// head-space vertices: Multiface's tracked meshes are stored in head space,
// so the neutral frame as stored is the neutral in head space.
Mesh load_template(const MultifaceCapture& capture, const MultifaceFrame& frame, const IngestOptions& o) {
  const fs::path obj = o.template_obj.empty() ? capture.mesh_obj(frame) : fs::path(o.template_obj);
  if (!fs::exists(obj)) throw Error(obj, "is missing (the template: mesh topology and UVs)");
  Mesh mesh = read_obj(obj);
  if (!mesh.has_uvs()) throw Error(obj, "has no UVs; the dataset's template needs them");
  mesh.positions = read_tracked_vertices(capture, frame, mesh.num_vertices());
  return mesh;
}

Image8 rgb_of(const Image8& image, const fs::path& file) {
  if (image.channels == 3) return image;
  if (image.channels != 1 && image.channels != 4)
    throw Error(file, "has " + std::to_string(image.channels) + " channels; expected RGB");
  Image8 rgb(image.width, image.height, 3);
  for (int y = 0; y < image.height; ++y)
    for (int x = 0; x < image.width; ++x)
      for (int c = 0; c < 3; ++c) rgb.at(x, y, c) = image.at(x, y, image.channels == 1 ? 0 : c);
  return rgb;
}

void check_image_size(const ImageHeader& header, const fs::path& file, const IngestOptions& o) {
  if (header.width != o.width || header.height != o.height) {
    throw Error(file, "is " + std::to_string(header.width) + "x" + std::to_string(header.height) +
                          "; the capture's images are " + std::to_string(o.width) + "x" + std::to_string(o.height) +
                          " (options width, height)");
  }
}

}  // namespace

IngestSummary ingest_multiface(const fs::path& capture_root, const fs::path& out, const IngestOptions& options,
                               bool replace_existing) {
  check_options(options);
  const MultifaceCapture capture{capture_root};
  if (!fs::is_directory(capture_root)) throw Error(capture_root, "is not a directory (a Multiface capture)");

  // Everything cheap first, so that a broken capture fails before the heavy work.
  const FramePlan plan = plan_frames(capture, options);
  const Rig krt = read_krt(capture.krt(), options.width, options.height);
  const Mesh template_mesh = load_template(capture, plan.template_frame, options);

  std::vector<MultifaceFrame> frames = plan.train;
  frames.insert(frames.end(), plan.test.begin(), plan.test.end());
  std::vector<RigidTransform> poses;
  for (const auto& f : frames) {
    if (!fs::exists(capture.mesh_bin(f)) && !fs::exists(capture.mesh_obj(f)))
      throw Error(capture.mesh_bin(f), "is missing, and so is " + capture.mesh_obj(f).filename().string() +
                                           " (tracked mesh of frame " + f.id() + ")");
    poses.push_back(read_head_transform(capture.transform(f)));
  }

  const HeadFrame head = estimate_head_frame(krt, poses, options.face_forward);
  const CameraSplit cameras = select_cameras(krt, head, options, capture.krt());
  std::vector<std::string> used = cameras.train;
  used.insert(used.end(), cameras.test.begin(), cameras.test.end());

  // Why each image (frame-major) cannot be used; empty when it can. A wrong
  // size is an error rather than a gap: the options' width and height are
  // more likely wrong than one image.
  ThreadPool pool(options.threads);
  std::vector<std::string> unusable(frames.size() * used.size());
  pool.parallel_for(0, static_cast<int64_t>(unusable.size()), [&](int64_t i) {
    const fs::path image = capture.image(used[i % used.size()], frames[i / used.size()]);
    if (!fs::exists(image)) {
      unusable[i] = image.string() + ": is missing";
      return;
    }
    ImageHeader header;
    try {
      header = read_image_header(image);
    } catch (const Error& e) {
      unusable[i] = e.what();
      return;
    }
    check_image_size(header, image, options);
  });

  Dataset dataset;
  dataset.template_mesh = template_mesh;
  const double scale = 1.0 / options.downsample;
  for (const Camera& camera : krt.cameras)
    if (std::count(used.begin(), used.end(), camera.name))
      dataset.rig.cameras.push_back(without_distortion(camera).scaled(scale));
  for (size_t f = 0; f < frames.size(); ++f) dataset.frames.push_back({frames[f].id(), frames[f].sequence, poses[f]});
  for (const auto& f : plan.train) dataset.train.frames.push_back(f.id());
  for (const auto& f : plan.test) dataset.test.frames.push_back(f.id());
  dataset.train.cameras = cameras.train;
  dataset.test.cameras = cameras.test;
  for (size_t i = 0; i < unusable.size(); ++i) {
    if (unusable[i].empty()) continue;
    logging::warn("ingest multiface: leaving out %s", unusable[i].c_str());
    dataset.missing_images.push_back({used[i % used.size()], frames[i / used.size()].id(), unusable[i]});
  }
  {
    // Before the heavy work: a capture missing too much fails now.
    Dataset planned = dataset;
    apply_missing_image_limits(planned, options.missing_images, capture_root, kRemedy);
  }

  StagedDirectory staged(out, replace_existing);
  dataset.root = staged.path();

  // Tracked meshes: millimetres in head space -> metres in world space.
  std::vector<Vertices> world(frames.size());
  fs::create_directories(dataset.mesh_path(frames.front().id()).parent_path());
  pool.parallel_for(0, static_cast<int64_t>(frames.size()), [&](int64_t f) {
    Vertices v = read_tracked_vertices(capture, frames[f], template_mesh.num_vertices());
    const Eigen::Matrix3f R = poses[f].R.cast<float>();
    const Eigen::RowVector3f t = poses[f].t.cast<float>().transpose();
    world[f] = (v * R.transpose()).rowwise() + t;
    write_vertices_bin(world[f], dataset.mesh_path(frames[f].id()));
  });

  Progress progress("ingest multiface", static_cast<int64_t>(frames.size() * used.size()), "images");
  for (const Camera& output_camera : dataset.rig.cameras) {
    const Camera& captured_camera = krt.camera(output_camera.name);
    fs::create_directories(dataset.image_path(output_camera.name, frames.front().id()).parent_path());
    // Once per camera: the maps take as much memory as a float image.
    const UndistortionMaps maps = captured_camera.has_distortion() ? captured_camera.undistortion_maps()
                                                                   : UndistortionMaps{};
    // Why each frame's image cannot be decoded (a truncated or corrupt file); empty when it can.
    std::vector<std::string> undecodable(frames.size());
    pool.parallel_for(0, static_cast<int64_t>(frames.size()), [&](int64_t f) {
      const fs::path source = capture.image(output_camera.name, frames[f]);
      if (!dataset.has_image(output_camera.name, frames[f].id())) {
        progress.advance();
        return;
      }
      Image8 read;
      try {
        read = read_image_u8(source);
      } catch (const Error& e) {
        undecodable[f] = e.what();
        progress.advance();
        return;
      }
      check_image_size({read.width, read.height, read.channels, 8}, source, options);
      const Image8 captured = rgb_of(read, source);
      const Image8 rgb = captured_camera.has_distortion() ? undistort_image(captured, maps, options.downsample)
                                                          : box_downsample(captured, options.downsample);

      Image8 alpha(rgb.width, rgb.height, 1, 255);
      if (options.matte == "mesh") {
        alpha = soft_dilate(mesh_silhouette(output_camera, world[f], template_mesh.faces),
                            options.matte_dilation_px * scale, options.matte_feather_px * scale);
      }
      Image8 rgba(rgb.width, rgb.height, 4);
      for (int y = 0; y < rgb.height; ++y) {
        for (int x = 0; x < rgb.width; ++x) {
          for (int c = 0; c < 3; ++c) rgba.at(x, y, c) = rgb.at(x, y, c);
          rgba.at(x, y, 3) = alpha.at(x, y, 0);
        }
      }
      write_image(rgba, dataset.image_path(output_camera.name, frames[f].id()));
      progress.advance();
    });
    for (size_t f = 0; f < frames.size(); ++f) {
      if (undecodable[f].empty()) continue;
      logging::warn("ingest multiface: leaving out %s", undecodable[f].c_str());
      dataset.missing_images.push_back({output_camera.name, frames[f].id(), undecodable[f]});
    }
  }
  progress.finish();

  drop_frames_lacking_images(dataset, options.missing_images, capture_root, kRemedy, "ingest multiface");
  write_dataset_manifest(dataset);
  validate_dataset(read_dataset(staged.path()));
  staged.commit();

  IngestSummary summary;
  summary.dataset = staged.final_path();
  summary.train_frames = static_cast<int>(dataset.train.frames.size());
  summary.test_frames = static_cast<int>(dataset.test.frames.size());
  summary.images = static_cast<int>(dataset.frames.size() * used.size() - dataset.missing_images.size());
  summary.missing_images = static_cast<int>(dataset.missing_images.size());
  summary.dropped_frames = static_cast<int>(dataset.dropped_frames.size());
  summary.train_cameras = cameras.train;
  summary.test_cameras = cameras.test;
  return summary;
}

}  // namespace tega::ingest
