// The calibration take: a ChArUco board moved through the capture volume,
// filmed by every camera, with its true poses as ground truth.

#include <cmath>

#include "lighting.h"
#include "studio.h"
#include "tega/core/files.h"
#include "tega/synth/charuco_board.h"
#include "tega/synth/random.h"
#include "tega/synth/rasterizer.h"

namespace tega::synth {
namespace {

// Cells of the board's grid of quads: small enough that straight triangle
// edges follow the lens distortion well below a tenth of a pixel.
constexpr int kCellsX = 48, kCellsY = 36;
constexpr float kPaperWhite = 0.9f, kInkBlack = 0.05f;

float bilinear(const ImageF& t, double x, double y) {
  x = std::clamp(x, 0.0, t.width - 1.0);
  y = std::clamp(y, 0.0, t.height - 1.0);
  const int x0 = std::min(static_cast<int>(x), t.width - 2), y0 = std::min(static_cast<int>(y), t.height - 2);
  const float fx = float(x - x0), fy = float(y - y0);
  return (t.at(x0, y0, 0) * (1 - fx) + t.at(x0 + 1, y0, 0) * fx) * (1 - fy) +
         (t.at(x0, y0 + 1, 0) * (1 - fx) + t.at(x0 + 1, y0 + 1, 0) * fx) * fy;
}

struct PosedBoard {
  Vertices positions, front_normals, back_normals;
};

}  // namespace

void render_calibration(const Studio& studio, const std::string& take) {
  const CharucoBoardSpec spec;
  const ImageF texture = charuco_texture(spec);
  const int frames = studio.options.calibration_frames;
  const auto poses = charuco_board_poses(spec, frames, uint64_t(studio.options.seed));
  const Mesh front = charuco_board_mesh(spec, kCellsX, kCellsY, false);
  const Mesh back = charuco_board_mesh(spec, kCellsX, kCellsY, true);

  std::vector<PosedBoard> posed(frames);
  for (int f = 0; f < frames; ++f) {
    const RigidTransform& pose = poses[f];
    PosedBoard& p = posed[f];
    p.positions = transformed(pose, front.positions);
    const Eigen::RowVector3f towards_front = (-pose.R.col(2)).cast<float>().transpose();
    p.front_normals = towards_front.replicate(front.num_vertices(), 1);
    p.back_normals = (-towards_front).replicate(front.num_vertices(), 1);
  }

  const auto& cameras = studio.rig.cameras;
  for (const auto& cam : cameras) std::filesystem::create_directories(studio.root / "takes" / take / cam.name);
  const int n_cameras = static_cast<int>(cameras.size());
  studio.pool.parallel_for(0, int64_t(frames) * n_cameras, [&](int64_t task) {
    const int f = static_cast<int>(task / n_cameras), c = static_cast<int>(task % n_cameras);
    const PosedBoard& p = posed[f];
    Surface printed{&p.positions, &p.front_normals, &front.faces, &front.uvs, &front.uv_faces,
                    [&](const SurfaceSample& s) -> Eigen::Vector3f {
                      const float g = bilinear(texture, s.uv.x() * texture.width - 0.5,
                                               (1 - s.uv.y()) * texture.height - 0.5);
                      const float albedo = kInkBlack + (kPaperWhite - kInkBlack) * g;
                      return lit(Eigen::Vector3f::Constant(albedo), s.normal, s.to_camera, 0.0f, 1.0f);
                    }};
    Surface unprinted{&p.positions, &p.back_normals, &back.faces, nullptr, nullptr,
                      [](const SurfaceSample& s) -> Eigen::Vector3f {
                        return lit(Eigen::Vector3f(0.35f, 0.33f, 0.3f), s.normal, s.to_camera, 0.0f, 1.0f);
                      }};
    const ImageF fg = rasterize(cameras[c], {printed, unprinted}, studio.options.supersampling);
    const uint64_t noise = hash_of(uint64_t(studio.options.seed), hash_string(take.c_str()), c, f);
    write_studio_image(capture_image(&fg, studio.backgrounds[c], noise, studio.options.noise_sigma), studio.root / "takes" / take / cameras[c].name / (frame_name(f) + ".png"));
    studio.progress.advance();
  });

  nlohmann::json gt = {{"take", take},
                       {"kind", "calibration"},
                       {"board",
                        {{"type", "charuco"},
                         {"squares_x", spec.squares_x},
                         {"squares_y", spec.squares_y},
                         {"square_m", spec.square_m},
                         {"marker_m", spec.marker_m},
                         {"dictionary", spec.dictionary},
                         {"margin_m", spec.margin_squares * spec.square_m},
                         {"coordinates", "OpenCV 4.6 CharucoBoard: x right, y down, z into the board; "
                                         "corner id = y * (squares_x - 1) + x at ((x + 1), (y + 1)) * square_m"}}},
                       {"frames", nlohmann::json::array()}};
  for (int f = 0; f < frames; ++f) gt["frames"].push_back({{"index", f}, {"board_to_world", pose_json(poses[f])}});
  std::filesystem::create_directories(studio.truth / "ground_truth" / take);
  write_text_atomic(studio.truth / "ground_truth" / take / "frames.json", gt.dump(2) + "\n");
  write_take_json(studio, take, "calibration", frames);
}

}  // namespace tega::synth
