#include "studio_frame.h"

#include <cstdio>

#include "tega/core/mesh.h"
#include "tega/core/rig.h"
#include "tega/core/take.h"
#include "tega/core/thread_pool.h"
#include "tega/core/undistort.h"
#include "tega/mvs/frame_views.h"
#include "tega/mvs/view_selection.h"
#include "tega/synth/ground_truth_depth.h"
#include "tega/synth/virtual_studio.h"
#include "small_studio.h"
#include "test_support.h"

namespace fs = std::filesystem;

namespace tega::test {
namespace {

StudioFrame render_frame() {
  const TempDir dir;
  const fs::path root = dir / "capture";
  synth::render_virtual_studio(small_studio(7, 320, 240, 1), root);

  StudioFrame frame;
  ThreadPool pool(0);
  const Rig rig = read_rig_json(root / "rig.json");
  frame.views = mvs::FrameLoader(read_take(root / "takes" / "expressions"), rig, "rig.json").load(0, pool);
  const Mesh topology = read_obj(root / "ground_truth" / "head" / "fine_topology.obj");
  const Vertices fine = read_vertices_bin(root / "ground_truth" / "expressions" / "fine" / "000000.bin");
  std::vector<Camera> cameras;
  for (auto& view : frame.views) {
    const Image8 alpha = undistort_image(
        read_image_u8(root / "ground_truth" / "expressions" / "alpha" / view.camera.name / "000000.png"),
        rig.camera(view.camera.name));
    for (uint8_t a : alpha.pixels) view.mask.push_back(a > 0 ? 255 : 0);
    frame.true_depth.push_back(synth::render_depth(view.camera, fine, topology.faces));
    cameras.push_back(view.camera);
  }
  const Eigen::Vector3d focus = *mvs::rig_focus_point(cameras);
  const auto sources = mvs::select_source_views(cameras, focus, 4);
  for (size_t k = 0; k < cameras.size(); ++k) {
    const double centre = cameras[k].world_to_camera.apply(focus).z();
    frame.tasks.push_back({int(k), sources[k], float(centre - 0.25), float(centre + 0.25)});
  }
  return frame;
}

}  // namespace

const StudioFrame& studio_frame() {
  static const StudioFrame frame = render_frame();
  return frame;
}

DepthAgreement agreement(const mvs::DepthMap& map, const ImageF& truth, double tolerance_m) {
  int64_t head = 0, estimated = 0, within = 0;
  for (size_t i = 0; i < map.depth.size(); ++i) {
    if (truth.pixels[i] <= 0) continue;
    ++head;
    if (map.depth[i] <= 0) continue;
    ++estimated;
    within += std::abs(map.depth[i] - truth.pixels[i]) < tolerance_m;
  }
  return {double(within) / std::max<int64_t>(estimated, 1), double(estimated) / std::max<int64_t>(head, 1)};
}

}  // namespace tega::test
