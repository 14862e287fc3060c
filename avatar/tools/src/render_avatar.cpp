#include "tega/tools/render_avatar.h"
#include <ATen/core/grad_mode.h>

#include <algorithm>
#include <cmath>
#include <set>
#include <nlohmann/json.hpp>

#include "async_images.h"
#include "image_tensors.h"
#include "tega/core/error.h"
#include "tega/core/files.h"
#include "tega/core/image.h"
#include "tega/core/progress.h"
#include "tega/trainer/render.h"
#include "tega/tools/video.h"

namespace tega::tools {

namespace fs = std::filesystem;

Camera resized(const Camera& camera, int width, int height) {
  if (width < 0 || height < 0) throw Error("a render size cannot be negative");
  if (width == 0 && height == 0) return camera;
  const double sx = width > 0 ? double(width) / camera.width : double(height) / camera.height;
  const double sy = height > 0 ? double(height) / camera.height : sx;
  Camera out = camera;
  out.width = width > 0 ? width : static_cast<int>(std::lround(sx * camera.width));
  out.height = height > 0 ? height : static_cast<int>(std::lround(sy * camera.height));
  if (out.width < 1 || out.height < 1 || out.width > kMaxRenderSize || out.height > kMaxRenderSize)
    throw Error("camera " + camera.name + ": a render of " + std::to_string(out.width) + "x" +
                std::to_string(out.height) + " is outside 1.." + std::to_string(kMaxRenderSize) + " pixels a side");
  // Pixel x of the old image covers [x - 0.5, x + 0.5]: x' = s (x + 0.5) - 0.5.
  out.K(0, 0) = sx * camera.K(0, 0);
  out.K(0, 1) = sx * camera.K(0, 1);
  out.K(0, 2) = sx * (camera.K(0, 2) + 0.5) - 0.5;
  out.K(1, 1) = sy * camera.K(1, 1);
  out.K(1, 2) = sy * (camera.K(1, 2) + 0.5) - 0.5;
  return out;
}

RigidTransform look_at(const Eigen::Vector3d& position, const Eigen::Vector3d& target, const Eigen::Vector3d& up) {
  const Eigen::Vector3d z = (target - position).normalized();
  Eigen::Vector3d x = (-up).cross(z);
  if (x.norm() < 1e-9) x = z.unitOrthogonal();  // looking straight along the up axis
  x.normalize();
  const Eigen::Vector3d y = z.cross(x);
  RigidTransform t;
  t.R.row(0) = x;
  t.R.row(1) = y;
  t.R.row(2) = z;
  t.t = -t.R * position;
  return t;
}

std::vector<Camera> orbit_cameras(const std::vector<Camera>& reference, const Eigen::Vector3d& centre, int count,
                                  const Camera& intrinsics) {
  if (reference.empty()) throw Error("an orbit needs reference cameras");
  if (count < 1) throw Error("an orbit needs at least one camera");
  Eigen::Vector3d up = Eigen::Vector3d::Zero(), mean_offset = Eigen::Vector3d::Zero();
  double distance = 0;
  for (const Camera& c : reference) {
    up -= c.world_to_camera.R.row(1).transpose();
    mean_offset += c.center() - centre;
    distance += (c.center() - centre).norm();
  }
  if (up.norm() < 1e-9) throw Error("the reference cameras have no common up direction for an orbit");
  up.normalize();
  distance /= reference.size();
  mean_offset /= reference.size();
  // The references' mean height above the centre, and the circle's radius
  // that puts every camera at their mean distance.
  const double height = std::clamp(mean_offset.dot(up), -distance, distance);
  const double radius = std::sqrt(distance * distance - height * height);
  Eigen::Vector3d forward = mean_offset - mean_offset.dot(up) * up;
  if (forward.norm() < 1e-9) forward = up.unitOrthogonal();
  forward.normalize();
  const Eigen::Vector3d side = up.cross(forward);

  std::vector<Camera> cameras;
  for (int i = 0; i < count; ++i) {
    const double angle = 2 * M_PI * i / count;
    const Eigen::Vector3d offset = radius * (std::cos(angle) * forward + std::sin(angle) * side) + height * up;
    Camera c = intrinsics;
    char name[32];
    std::snprintf(name, sizeof name, "orbit%03d", i);
    c.name = name;
    c.distortion = {};
    c.world_to_camera = look_at(centre + offset, centre, up);
    cameras.push_back(c);
  }
  return cameras;
}

std::vector<RenderFrame> dataset_frames(const Dataset& dataset, const std::vector<std::string>& ids) {
  std::vector<RenderFrame> frames;
  for (const auto& id : ids) {
    const DatasetFrame& f = dataset.frame(id);
    frames.push_back({f.id, dataset.load_mesh(f.id), f.head_to_world, true});
  }
  return frames;
}

std::vector<fs::path> mesh_files(const fs::path& directory) {
  if (!fs::is_directory(directory)) throw Error(directory, "is not a directory of meshes");
  std::vector<fs::path> files;
  for (const auto& entry : fs::directory_iterator(directory)) {
    const std::string ext = entry.path().extension().string();
    if (entry.is_regular_file() && (ext == ".bin" || ext == ".obj" || ext == ".ply")) files.push_back(entry.path());
  }
  if (files.empty()) throw Error(directory, "holds no .bin, .obj or .ply mesh");
  std::sort(files.begin(), files.end());
  return files;
}

RenderFrame mesh_frame(const fs::path& file, int template_vertices, const RigidTransform& head_to_world,
                       bool head_space) {
  RenderFrame frame;
  frame.id = file.stem().string();
  if (file.extension() == ".bin") {
    frame.world_vertices = read_vertices_bin(file, template_vertices);
  } else {
    frame.world_vertices = read_mesh(file).positions;
    if (frame.world_vertices.rows() != template_vertices)
      throw Error(file, "has " + std::to_string(frame.world_vertices.rows()) + " vertices; the template has " +
                            std::to_string(template_vertices));
  }
  if (head_space) {
    const Eigen::Matrix3f r = head_to_world.R.cast<float>();
    const Eigen::RowVector3f t = head_to_world.t.cast<float>().transpose();
    frame.world_vertices = ((frame.world_vertices * r.transpose()).rowwise() + t).eval();
  }
  frame.head_to_world = head_to_world;
  return frame;
}

std::vector<RenderFrame> mesh_sequence(const fs::path& directory, int template_vertices,
                                       const RigidTransform& head_to_world, bool head_space) {
  std::vector<RenderFrame> frames;
  for (const auto& file : mesh_files(directory))
    frames.push_back(mesh_frame(file, template_vertices, head_to_world, head_space));
  return frames;
}

namespace {

nlohmann::json camera_json(const Camera& c) {
  return {{"name", c.name},
          {"width", c.width},
          {"height", c.height},
          {"K", {{c.K(0, 0), c.K(0, 1), c.K(0, 2)}, {c.K(1, 0), c.K(1, 1), c.K(1, 2)}, {c.K(2, 0), c.K(2, 1), c.K(2, 2)}}},
          {"world_to_camera",
           {{c.world_to_camera.R(0, 0), c.world_to_camera.R(0, 1), c.world_to_camera.R(0, 2), c.world_to_camera.t.x()},
            {c.world_to_camera.R(1, 0), c.world_to_camera.R(1, 1), c.world_to_camera.R(1, 2), c.world_to_camera.t.y()},
            {c.world_to_camera.R(2, 0), c.world_to_camera.R(2, 1), c.world_to_camera.R(2, 2), c.world_to_camera.t.z()}}}};
}

}  // namespace

RenderSummary render_avatar(trainer::TrainedAvatar& avatar, const Dataset& dataset, const RenderJob& job) {
  if (job.format != "png" && job.format != "exr") throw Error("render format '" + job.format + "': use png or exr");
  const std::string ext = "." + job.format;
  if (!image_format_supported("render" + ext))
    throw Error("this build cannot write " + job.format + " images (EXR needs OpenImageIO); use --format png");
  if (job.cameras.empty() || job.frames.empty()) throw Error("nothing to render: no camera or no frame");
  // Names become file and directory names: two alike would overwrite each other.
  std::set<std::string> names;
  for (const RenderCamera& rc : job.cameras)
    if (!names.insert(rc.camera.name).second) throw Error("two render cameras are named " + rc.camera.name);
  names.clear();
  for (const RenderFrame& f : job.frames)
    if (!names.insert(f.id).second) throw Error("two render frames are named " + f.id);

  StagedDirectory staged(job.out, job.replace_existing);
  const at::Device device = avatar.model.device();
  const at::Tensor background = at::tensor(avatar.options.background, at::kFloat).to(device);
  RenderSummary summary;
  Progress progress("render", static_cast<int64_t>(job.frames.size() * job.cameras.size()), "images");
  detail::BackgroundImageWriter writer;  // after `staged`: its files are all written before that is dropped
  at::NoGradGuard no_grad;
  for (const RenderFrame& frame : job.frames) {
    const trainer::FrameInput input = avatar.model.frame_input(frame.world_vertices, frame.head_to_world);
    for (const RenderCamera& rc : job.cameras) {
      const Camera& camera = rc.camera;
      const at::Tensor rgb =
          trainer::render_view(avatar.model, input, camera, avatar.phase, background, avatar.options.antialiased);
      fs::create_directories(staged.path() / camera.name);
      writer.write(rgb, staged.path() / camera.name / (frame.id + ext));
      ++summary.images;

      const fs::path truth = dataset.image_path(camera.name, frame.id);
      if (job.side_by_side && rc.from_dataset && frame.from_dataset && dataset.has_image(camera.name, frame.id) &&
          fs::exists(truth)) {
        at::Tensor target = trainer::composite_target(detail::read_rgba(truth).to(device), background);
        if (target.size(1) != camera.height || target.size(2) != camera.width) {
          const std::vector<int64_t> size{camera.height, camera.width};
          target = at::upsample_bilinear2d(target.unsqueeze(0), size, /*align_corners=*/false).squeeze(0);
        }
        fs::create_directories(staged.path() / "side_by_side" / camera.name);
        writer.write(at::cat({rgb, target}, 2), staged.path() / "side_by_side" / camera.name / (frame.id + ".png"));
        ++summary.side_by_side;
      }
      progress.advance();
    }
  }
  writer.finish();
  progress.finish();

  if (!job.video) {
    summary.video_note = "video not asked for";
  } else if (!video_supported()) {
    summary.video_note = video_unsupported_reason();
  } else if (job.frames.size() > 1) {
    for (const RenderCamera& rc : job.cameras) {
      std::vector<fs::path> images;
      for (const RenderFrame& frame : job.frames) images.push_back(staged.path() / rc.camera.name / (frame.id + ext));
      const fs::path video = rc.camera.name + ".mp4";
      write_video(images, staged.path() / video, job.fps);
      summary.videos.push_back(job.out / video);
    }
  } else if (job.cameras.size() > 1) {
    std::vector<fs::path> images;
    for (const RenderCamera& rc : job.cameras) images.push_back(staged.path() / rc.camera.name / (job.frames[0].id + ext));
    write_video(images, staged.path() / "turntable.mp4", job.fps);
    summary.videos.push_back(job.out / "turntable.mp4");
  } else {
    summary.video_note = "one frame from one camera makes no video";
  }

  nlohmann::json report = {{"iteration", avatar.iteration}, {"format", job.format}, {"images", summary.images},
                           {"side_by_side", summary.side_by_side}};
  for (const RenderCamera& rc : job.cameras) report["cameras"].push_back(camera_json(rc.camera));
  for (const RenderFrame& frame : job.frames) report["frames"].push_back(frame.id);
  report["videos"] = nlohmann::json::array();
  for (const auto& v : summary.videos) report["videos"].push_back(v.filename().string());
  if (!summary.video_note.empty()) report["video_note"] = summary.video_note;
  write_text_atomic(staged.path() / "render.json", report.dump(2));
  staged.commit();
  return summary;
}

}  // namespace tega::tools
