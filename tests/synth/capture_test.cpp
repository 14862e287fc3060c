// Tests on one small capture, rendered once: its images against its own
// ground truth, its motion, its dataset and (with OpenCV) its calibration take.

#include <gtest/gtest.h>
#include <unistd.h>

#include <cmath>
#include <fstream>
#include <nlohmann/json.hpp>

#include "tega/core/dataset.h"
#include "tega/core/error.h"
#include "tega/core/image.h"
#include "tega/core/mesh.h"
#include "tega/core/rig.h"
#include "tega/core/files.h"
#include "tega/core/take.h"
#include "tega/synth/virtual_studio.h"
#include "test_support.h"
#include "ground_truth_json.h"


namespace tega::synth {
namespace {

namespace fs = std::filesystem;

Options small_capture_options() {
  Options o;
  o.studio.cameras = 3;
  o.studio.width = 200;
  o.studio.height = 150;
  o.frames = 10;
  o.calibration_frames = 3;
  o.takes = {"expressions", "freestyle"};
  o.test_takes = {"freestyle"};
  o.test_cameras = 1;
  o.supersampling = 2;
  o.fine_subdivisions = 1;
  return o;
}

// Rendered on first use; removed when the test program exits.
const fs::path& capture() {
  struct Rendered {
    fs::path dir = fs::temp_directory_path() / ("tega-synth-capture-" + std::to_string(::getpid()));
    Rendered() { render_virtual_studio(small_capture_options(), dir, true); }
    ~Rendered() { tega::remove_tree(dir); }
  };
  static const Rendered rendered;
  return rendered.dir;
}

using test::pose_from_json;

// Pixels whose centre lies inside a projected triangle (either winding): an
// independent, plain rasterization of the ground-truth mesh.
std::vector<char> projected_mask(const Camera& cam, const Vertices& world, const Triangles& faces) {
  std::vector<Eigen::Vector2d> px(world.rows());
  for (int v = 0; v < world.rows(); ++v) px[v] = *cam.project(world.row(v).cast<double>().transpose());
  std::vector<char> mask(size_t(cam.width) * cam.height, 0);
  for (int f = 0; f < faces.rows(); ++f) {
    const Eigen::Vector2d a = px[faces(f, 0)], b = px[faces(f, 1)], c = px[faces(f, 2)];
    const auto cross = [](const Eigen::Vector2d& u, const Eigen::Vector2d& v) { return u.x() * v.y() - u.y() * v.x(); };
    const double area = cross(b - a, c - a);
    if (area == 0) continue;
    const int x0 = std::max(0, int(std::ceil(std::min({a.x(), b.x(), c.x()}))));
    const int x1 = std::min(cam.width - 1, int(std::floor(std::max({a.x(), b.x(), c.x()}))));
    const int y0 = std::max(0, int(std::ceil(std::min({a.y(), b.y(), c.y()}))));
    const int y1 = std::min(cam.height - 1, int(std::floor(std::max({a.y(), b.y(), c.y()}))));
    for (int y = y0; y <= y1; ++y)
      for (int x = x0; x <= x1; ++x) {
        const Eigen::Vector2d p(x, y);
        const double w0 = cross(b - p, c - p) / area, w1 = cross(c - p, a - p) / area, w2 = cross(a - p, b - p) / area;
        if (w0 >= 0 && w1 >= 0 && w2 >= 0) mask[size_t(y) * cam.width + x] = 1;
      }
  }
  return mask;
}

TEST(Capture, AlphaAgreesWithTheGroundTruthMeshProjectedThroughTheRig) {
  const fs::path root = capture();
  const Rig rig = read_rig_json(root / "rig.json");
  const Mesh fine = read_obj(root / "ground_truth/head/fine_topology.obj");
  for (const std::string take : {"expressions", "freestyle"}) {
    for (const char* frame : {"000000", "000005"}) {
      const Vertices world =
          read_vertices_bin(root / "ground_truth" / take / "fine" / (std::string(frame) + ".bin"), fine.num_vertices());
      for (const Camera& cam : rig.cameras) {
        const Image8 alpha = read_image_u8(root / "ground_truth" / take / "alpha" / cam.name / (std::string(frame) + ".png"));
        ASSERT_EQ(alpha.width, cam.width);
        const std::vector<char> projected = projected_mask(cam, world, fine.faces);
        int64_t both = 0, either = 0;
        for (int y = 0; y < cam.height; ++y)
          for (int x = 0; x < cam.width; ++x) {
            const bool a = alpha.at(x, y, 0) > 127, p = projected[size_t(y) * cam.width + x];
            both += a && p;
            either += a || p;
          }
        ASSERT_GT(either, 1000) << "the head should fill part of " << cam.name;
        EXPECT_GE(double(both) / either, 0.99) << take << " " << frame << " " << cam.name;
      }
    }
  }
}

TEST(Capture, AlphaDiffersFromCaptureOnlyByTheBackground) {
  // Where alpha is 0 the recorded image is the clean plate up to noise.
  const fs::path root = capture();
  const Image8 plate = read_image_u8(root / "takes/clean_plate/cam00/000000.png");
  const Image8 image = read_image_u8(root / "takes/expressions/cam00/000003.png");
  const Image8 alpha = read_image_u8(root / "ground_truth/expressions/alpha/cam00/000003.png");
  double background_diff = 0, foreground_diff = 0;
  int64_t n_bg = 0, n_fg = 0;
  for (int y = 0; y < image.height; ++y)
    for (int x = 0; x < image.width; ++x)
      for (int c = 0; c < 3; ++c) {
        const double d = std::abs(double(image.at(x, y, c)) - plate.at(x, y, c));
        if (alpha.at(x, y, 0) == 0) background_diff += d, ++n_bg;
        if (alpha.at(x, y, 0) == 255) foreground_diff += d, ++n_fg;
      }
  EXPECT_LT(background_diff / n_bg, 3.0);   // noise only (sigma ~1 grey level)
  EXPECT_GT(foreground_diff / n_fg, 10.0);  // the head
}

TEST(Capture, GroundTruthSequenceHasBlinksJawAndHeadMotion) {
  const nlohmann::json frames = read_json_file(capture() / "ground_truth/expressions/frames.json")["frames"];
  ASSERT_EQ(frames.size(), 10u);
  double blink_max = 0, blink_min = 1, jaw_max = 0, jaw_min = 1, max_turn_deg = 0;
  const RigidTransform first = pose_from_json(frames[0]["head_to_world"]);
  for (const auto& f : frames) {
    const double blink = f["expression"]["eyeBlink_L"], jaw = f["expression"]["jawOpen"];
    blink_max = std::max(blink_max, blink), blink_min = std::min(blink_min, blink);
    jaw_max = std::max(jaw_max, jaw), jaw_min = std::min(jaw_min, jaw);
    const RigidTransform pose = pose_from_json(f["head_to_world"]);
    max_turn_deg = std::max(max_turn_deg, Eigen::AngleAxisd(pose.R * first.R.transpose()).angle() * 180 / M_PI);
  }
  EXPECT_GT(blink_max, 0.9);
  EXPECT_LT(blink_min, 0.05);
  EXPECT_GT(jaw_max, 0.5);
  EXPECT_LT(jaw_min, 0.05);
  EXPECT_GT(max_turn_deg, 3.0);
}

TEST(Capture, GroundTruthCoarseMeshIsThePosedTemplate) {
  const fs::path root = capture();
  const Mesh templ = read_obj(root / "ground_truth/head/template.obj");
  const nlohmann::json frames = read_json_file(root / "ground_truth/expressions/frames.json")["frames"];
  // Frame 0 is neutral up to the head pose: the tracked mesh is the template, posed.
  for (const auto& [name, value] : frames[0]["expression"].items()) ASSERT_LT(double(value), 1e-3) << name;
  const RigidTransform pose = pose_from_json(frames[0]["head_to_world"]);
  const Vertices coarse = read_vertices_bin(root / "ground_truth/expressions/coarse/000000.bin", templ.num_vertices());
  double worst = 0;
  for (int v = 0; v < coarse.rows(); ++v)
    worst = std::max(worst, (pose.apply(templ.positions.row(v).cast<double>().transpose()) -
                             coarse.row(v).cast<double>().transpose()).norm());
  EXPECT_LT(worst, 1e-5);
}

TEST(Capture, DatasetValidatesWithHeldOutTakeAndCamera) {
  const Dataset d = read_dataset(capture() / "dataset");
  EXPECT_NO_THROW(validate_dataset(d));
  EXPECT_EQ(d.frames.size(), 20u);
  EXPECT_EQ(d.train.frames.size(), 10u);
  EXPECT_EQ(d.test.frames.size(), 10u);
  for (const auto& id : d.test.frames) EXPECT_EQ(d.frame(id).sequence, "freestyle");
  ASSERT_EQ(d.test.cameras.size(), 1u);
  EXPECT_EQ(d.train.cameras.size(), 2u);
  for (const auto& cam : d.train.cameras) EXPECT_NE(cam, d.test.cameras[0]);
  EXPECT_FALSE(d.eyeball_faces.empty());
  for (const auto& cam : d.rig.cameras) EXPECT_FALSE(cam.has_distortion());
}

TEST(Capture, WritesTheTakesItDescribes) {
  const fs::path root = capture();
  EXPECT_NO_THROW(tega::validate_capture(root));
  const nlohmann::json c = read_json_file(root / "capture.json");
  EXPECT_EQ(c["cameras"].size(), 3u);
  for (const auto& take : c["takes"]) {
    const nlohmann::json t = read_json_file(root / "takes" / std::string(take["name"]) / "take.json");
    EXPECT_EQ(t["kind"], take["kind"]);
    EXPECT_EQ(t["frames"], take["frames"]);
    for (int f = 0; f < int(t["frames"]); ++f)
      for (const auto& cam : t["cameras"]) {
        char name[16];
        std::snprintf(name, sizeof name, "%06d.png", f);
        EXPECT_TRUE(fs::exists(root / "takes" / std::string(take["name"]) / std::string(cam) / name));
      }
  }
}

TEST(Capture, RefusesToOverwriteAnExistingDirectoryUnlessAsked) {
  tega::test::TempDir tmp;
  Options o = small_capture_options();
  o.studio.cameras = 1;
  o.frames = 1;
  o.calibration_frames = 0;
  o.fine_subdivisions = 0;
  fs::create_directories(tmp / "out");
  try {
    render_virtual_studio(o, tmp / "out", false);
    FAIL() << "an existing directory must be an error";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find((tmp / "out").string()), std::string::npos) << e.what();
  }
  EXPECT_NO_THROW(render_virtual_studio(o, tmp / "out", true));
  EXPECT_TRUE(fs::exists(tmp / "out/capture.json"));
}

#ifndef TEGA_SYNTH_HAVE_OPENCV
TEST(Capture, CalibrationTakeIsSkippedWithoutOpenCv) {
  EXPECT_FALSE(fs::exists(capture() / "takes/calibration"));
  EXPECT_TRUE(read_json_file(capture() / "capture.json")["calibration_skipped"].get<bool>());
}
#endif

}  // namespace
}  // namespace tega::synth
