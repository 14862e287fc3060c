#pragma once
// Per-frame multi-view stereo meshing of a capture's takes (`tega mvs`,
// docs/mvs.md): for every frame, the views undistorted and masked, PatchMatch
// depth and normal maps, fusion into an oriented point cloud, a screened
// Poisson surface trimmed where unsupported, written as
// MESHES/<take>/<frame>.ply (metres, world space). Frames are independent;
// each one's outputs are written atomically, and a rerun skips frames already
// done with the same options and rig.

#include <filesystem>
#include <string>
#include <vector>

#include "tega/core/mesh.h"
#include "tega/mvs/fusion.h"
#include "tega/mvs/masks.h"
#include "tega/mvs/patch_match.h"
#include "tega/mvs/surface.h"

namespace tega {
class ThreadPool;
}

namespace tega::mvs {

struct Options {
  PatchMatchOptions patch_match;
  FusionOptions fusion;
  SurfaceOptions surface;
  MaskOptions mask;
  double subject_radius_m = 0.3;         // depths searched: the rig's focus point +- this
  std::vector<double> depth_range_m;     // [min, max] along each camera's axis; overrides subject_radius_m
  int min_views = 3;                     // a frame needs the subject in this many views
  std::string device = "auto";           // cpu | cuda | auto (cuda when available)
  int threads = 0;                       // 0: one per hardware thread
  bool write_workspace = false;          // also MESHES/colmap/<frame>/, a COLMAP dense workspace

  template <class V>
  void visit(V& v) {
    v("patch_match", patch_match, "PatchMatch depth and normal estimation.");
    v("fusion", fusion, "Fusion of the depth maps into an oriented point cloud.");
    v("surface", surface, "Screened Poisson surface reconstruction and trimming.");
    v("mask", mask, "Subject masks from the clean plate.");
    v("subject_radius_m", subject_radius_m, "Depths searched: the point the rig aims at, plus or minus this (metres).");
    v("depth_range_m", depth_range_m, "[min, max] depth in metres along each camera's axis; overrides subject_radius_m.");
    v("min_views", min_views, "A frame needs the subject seen by at least this many cameras.");
    v("device", device, "Where depth estimation and fusion run: cpu, cuda, or auto (cuda when a GPU is available).");
    v("threads", threads, "CPU worker threads (0: one per hardware thread).");
    v("write_workspace", write_workspace, "Also write each frame's COLMAP dense workspace under colmap/<frame>/.");
  }
};

Device resolve_device(const std::string& name);  // "auto" -> cuda when available, else cpu

struct FrameTimings {
  double load_s = 0, depth_s = 0, fusion_s = 0, surface_s = 0, write_s = 0;
};

struct FrameReconstruction {
  std::vector<int> map_views;       // the views that got a depth map (indices into the frame's views)
  std::vector<DepthMap> depth_maps;
  std::vector<std::vector<int>> source_views;  // per depth map, its sources (view indices)
  OrientedPointCloud cloud;
  Mesh mesh;
  FrameTimings timings;
};

// One frame from its views (undistorted, masked where masks are known).
// `label` names the frame in errors ("frame 12"). Throws tega::Error when
// fewer than options.min_views views see the subject, naming them.
FrameReconstruction reconstruct_views(const std::vector<StereoView>& views, const Options& options, Device device,
                                      const std::string& label, ThreadPool& pool);

struct MvsRequest {
  std::filesystem::path capture;  // CAPTURE/ (capture.json, rig.json, takes/)
  std::vector<std::string> takes; // empty: every performance take
  std::filesystem::path out;      // MESHES/: MESHES/<take>/<frame>.ply
  std::filesystem::path rig;      // empty: the capture's rig
  int first_frame = 0, end_frame = -1;  // [first, end); -1: to the take's end
};

struct MvsSummary {
  int takes = 0, frames_done = 0, frames_skipped = 0;  // skipped: already done with these options and rig
  Device device = Device::cpu;
};

// Every frame of the request; frames already in `out` with the same options
// and rig are kept. Errors name the take, the frame, the camera or the file.
MvsSummary reconstruct_capture(const MvsRequest& request, const Options& options);

// An ordinary calibrated photo set: one image per camera of the rig, named
// <camera>.<png|jpg|jpeg|tif|tiff> in `images` (COLMAP's image folder with a
// COLMAP text model as the rig works as it is). No clean plate: every pixel
// is searched, between the rig's focus point +- subject_radius_m or in
// depth_range_m. Writes the mesh (PLY) and, when `workspace` is not empty,
// a COLMAP dense workspace there.
struct PhotoRequest {
  std::filesystem::path images;
  std::filesystem::path rig;        // rig.json, or a COLMAP text model directory (cameras.txt, images.txt)
  double rig_metres_per_unit = 1.0; // COLMAP models: their unit in metres
  std::filesystem::path out;        // the mesh, .ply
  std::filesystem::path workspace;  // optional
};
FrameTimings reconstruct_photos(const PhotoRequest& request, const Options& options);

// Fusion and meshing of a COLMAP dense workspace's depth and normal maps
// (COLMAP's `patch_match_stereo` output, or tega's): the mesh (PLY) to `out`.
FrameTimings mesh_workspace(const std::filesystem::path& workspace, const std::filesystem::path& out,
                            const Options& options, const std::string& type = "geometric");

}  // namespace tega::mvs
