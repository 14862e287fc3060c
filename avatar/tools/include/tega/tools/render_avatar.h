#pragma once
// `tega render`: a trained avatar rendered for dataset frames (reenactment)
// or any mesh sequence in the template topology (novel expressions), from
// dataset cameras, a turntable orbit or a rig file, at any resolution up to
// 4096 pixels a side (docs/render-eval-export.md#render).
//
//   OUT/<camera>/<frame>.png|.exr        the render
//   OUT/side_by_side/<camera>/<frame>.png  render | ground truth, when the
//                                        frame and camera have a dataset image
//   OUT/<camera>.mp4                     per camera over the frames (several frames)
//   OUT/turntable.mp4                    over the cameras (one frame, several cameras)
//   OUT/render.json                      what was rendered, and why a video is missing

#include <filesystem>
#include <string>
#include <vector>

#include "tega/core/camera.h"
#include "tega/core/dataset.h"
#include "tega/core/mesh.h"
#include "tega/trainer/trained_avatar.h"

namespace tega::tools {

constexpr int kMaxRenderSize = 4096;

struct RenderCamera {
  Camera camera;
  bool from_dataset = false;  // a rig camera of the dataset: its images are ground truth
};

struct RenderFrame {
  std::string id;                 // names the output files
  Vertices world_vertices;        // template topology, world space
  RigidTransform head_to_world;
  bool from_dataset = false;      // a dataset frame: its images are ground truth
};

// The camera at a new resolution. Only one of width/height (the other 0)
// keeps the aspect ratio; both rescale x and y separately. Pixel centres stay
// consistent (as Camera::scaled). Throws tega::Error beyond kMaxRenderSize.
Camera resized(const Camera& camera, int width, int height);

// `count` cameras on a circle about the reference cameras' mean "up" (-y)
// axis through `centre`, at their mean height above the centre and their
// mean distance from it, starting from their mean direction; each looks at `centre` with the
// intrinsics of `intrinsics` (named orbit000, orbit001, ...).
std::vector<Camera> orbit_cameras(const std::vector<Camera>& reference, const Eigen::Vector3d& centre, int count,
                                  const Camera& intrinsics);

// A camera at `position` looking at `target`, +y of the image pointing
// along -up as far as possible.
RigidTransform look_at(const Eigen::Vector3d& position, const Eigen::Vector3d& target, const Eigen::Vector3d& up);

// Dataset frames by id (throws tega::Error for an unknown one).
std::vector<RenderFrame> dataset_frames(const Dataset& dataset, const std::vector<std::string>& ids);

// Every .bin/.obj/.ply file of `directory`, in name order, as frames named
// after the file stem. Vertices are in world space, or in head space with
// `head_space` (then moved by `head_to_world`); every frame gets
// `head_to_world` as its head pose. Throws tega::Error naming the file for a
// wrong vertex count or an empty directory.
std::vector<RenderFrame> mesh_sequence(const std::filesystem::path& directory, int template_vertices,
                                       const RigidTransform& head_to_world, bool head_space);
// The files mesh_sequence() reads, in its order; and one of them as its frame.
std::vector<std::filesystem::path> mesh_files(const std::filesystem::path& directory);
RenderFrame mesh_frame(const std::filesystem::path& file, int template_vertices, const RigidTransform& head_to_world,
                       bool head_space);

struct RenderJob {
  std::vector<RenderCamera> cameras;
  std::vector<RenderFrame> frames;
  std::filesystem::path out;
  std::string format = "png";     // png or exr
  bool side_by_side = true;
  bool video = true;
  double fps = 30;
  bool replace_existing = false;
};

struct RenderSummary {
  int64_t images = 0, side_by_side = 0;
  std::vector<std::filesystem::path> videos;
  std::string video_note;  // why no video was written, when none was
};

// Writes the job's outputs into job.out atomically (a StagedDirectory).
// Throws tega::Error for an existing output without replace_existing, an
// unsupported format, or a ground-truth image that cannot be read.
RenderSummary render_avatar(trainer::TrainedAvatar& avatar, const Dataset& dataset, const RenderJob& job);

}  // namespace tega::tools
