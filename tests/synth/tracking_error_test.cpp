// The tracking-error model of the dataset's meshes (Options::tracking_error):
// off, the dataset's meshes are the true coarse meshes; on, each error does
// what docs/virtual-studio.md#tracking-errors says, and nothing but the
// dataset's meshes (and its head_to_world with lag_pose) changes.

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <fstream>
#include <map>
#include <set>
#include <sstream>

#include "ground_truth_json.h"
#include "tega/core/dataset.h"
#include "tega/core/error.h"
#include "tega/core/mesh.h"
#include "tega/synth/tracking_error.h"
#include "tega/synth/virtual_studio.h"
#include "test_support.h"

namespace tega::synth {
namespace {

namespace fs = std::filesystem;
using test::pose_from_json;

constexpr int kFrames = 6;
const char* const kTake = "expressions";

std::string file_bytes(const fs::path& file) {
  std::ifstream in(file, std::ios::binary);
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

Options tiny_capture() {
  Options o;
  o.studio.cameras = 2;
  o.studio.width = 48;
  o.studio.height = 36;
  o.frames = kFrames;
  o.calibration_frames = 0;
  o.takes = {kTake};
  o.test_takes = {};
  o.test_cameras = 1;
  o.supersampling = 1;
  o.fine_subdivisions = 0;
  o.seed = 3;
  return o;
}

std::string frame_id(int f) {
  char name[16];
  std::snprintf(name, sizeof name, "%06d", f);
  return name;
}

Vertices truth_mesh(const fs::path& dir, int f) {
  return read_vertices_bin(dir / "ground_truth" / kTake / "coarse" / (frame_id(f) + ".bin"));
}
Vertices dataset_mesh(const fs::path& dir, int f) {
  return read_vertices_bin(dir / "dataset" / "meshes" / (std::string(kTake) + "_" + frame_id(f) + ".bin"));
}
RigidTransform truth_pose(const fs::path& dir, int f) {
  static std::map<fs::path, nlohmann::json> cache;
  auto& j = cache[dir];
  if (j.is_null()) j = read_json_file(dir / "ground_truth" / kTake / "frames.json");
  return pose_from_json(j["frames"][f]["head_to_world"]);
}

// Per vertex: 0 skin, 1 eyeball.
std::vector<char> eyeball_vertices(const Head& head) {
  std::vector<char> eye(head.model.num_vertices(), 0);
  for (int f : head.eyeball_faces)
    for (int k = 0; k < 3; ++k) eye[head.model.neutral.faces(f, k)] = 1;
  return eye;
}

// A capture rendered once per set of options, removed when the program exits.
struct RenderedCapture {
  tega::test::TempDir tmp;
  fs::path dir;
  explicit RenderedCapture(const Options& o) : dir(tmp / "capture") { render_virtual_studio(o, dir); }
};

const fs::path& without_errors() {
  static const RenderedCapture r(tiny_capture());
  return r.dir;
}

TEST(TrackingError, OffByDefaultTheDatasetMeshesAreTheTrueCoarseMeshes) {
  EXPECT_FALSE(Options{}.tracking_error.enabled());
  const fs::path& dir = without_errors();
  for (int f = 0; f < kFrames; ++f)
    EXPECT_EQ(file_bytes(dir / "dataset/meshes" / (std::string(kTake) + "_" + frame_id(f) + ".bin")),
              file_bytes(dir / "ground_truth" / kTake / "coarse" / (frame_id(f) + ".bin")))
        << f;
  EXPECT_FALSE(fs::exists(dir / "dataset/tracking_error.json"));
  EXPECT_FALSE(read_json_file(dir / "capture.json").contains("tracking_error"));
}

TEST(TrackingError, OffsetFieldHasTheRequestedRmsIsSmoothAndMovesEyeballsRigidly) {
  Options o = tiny_capture();
  o.tracking_error.offset_m = 0.003;
  const RenderedCapture r(o);
  const Head head = make_head(o);
  const std::vector<char> eye = eyeball_vertices(head);
  const Triangles& faces = head.model.neutral.faces;
  Eigen::MatrixXd previous;
  for (int f = 0; f < kFrames; ++f) {
    const Eigen::MatrixXd d = (dataset_mesh(r.dir, f) - truth_mesh(r.dir, f)).cast<double>();
    double sum2 = 0;
    int skin = 0;
    for (int v = 0; v < d.rows(); ++v)
      if (!eye[v]) sum2 += d.row(v).squaredNorm(), ++skin;
    EXPECT_NEAR(std::sqrt(sum2 / skin), 0.003, 0.003 * 0.01) << "frame " << f;
    // Smooth: neighbouring skin vertices (the skin's grid is about 8 mm) move
    // almost alike, and the field's slope is small everywhere (the neck's
    // cap has edges of 10 cm).
    double largest = 0, total = 0, slope = 0;
    int edges = 0;
    for (int t = 0; t < faces.rows(); ++t)
      for (int k = 0; k < 3; ++k) {
        const int a = faces(t, k), b = faces(t, (k + 1) % 3);
        if (eye[a] || eye[b]) continue;
        const double step = (d.row(a) - d.row(b)).norm();
        const double length = (head.model.neutral.positions.row(a) - head.model.neutral.positions.row(b)).norm();
        slope = std::max(slope, step / length);
        if (length > 0.01) continue;
        largest = std::max(largest, step), total += step, ++edges;
      }
    double peak = 0;  // the largest offset of a skin vertex
    for (int v = 0; v < d.rows(); ++v)
      if (!eye[v]) peak = std::max(peak, d.row(v).norm());
    EXPECT_LT(largest, 0.25 * peak) << "frame " << f;
    EXPECT_LT(total / edges, 0.1 * 0.003) << "frame " << f;
    EXPECT_LT(slope, 0.2) << "frame " << f;
    // Each eyeball moves rigidly (one translation, within float rounding).
    for (int t : head.eyeball_faces) {
      const int e = head.triangle_eye[t];
      const int v = faces(t, 0);
      for (int u : {faces(t, 1), faces(t, 2)}) EXPECT_LT((d.row(u) - d.row(v)).norm(), 1e-6) << e;
    }
    // A new, independent field every frame (period_frames 1).
    if (f > 0) EXPECT_GT((d - previous).rowwise().norm().maxCoeff(), 0.001) << "frame " << f;
    previous = d;
  }
}

TEST(TrackingError, LagOfOneFrameGivesThePreviousFramesExpressionInThisFramesPose) {
  Options o = tiny_capture();
  o.tracking_error.lag = 1;
  const RenderedCapture r(o);
  EXPECT_EQ(dataset_mesh(r.dir, 0), truth_mesh(r.dir, 0));  // clamped at the take's first frame
  double largest_change = 0;
  for (int f = 1; f < kFrames; ++f) {
    // The true mesh of frame f - 1, moved from its pose into frame f's.
    const RigidTransform move = truth_pose(r.dir, f) * truth_pose(r.dir, f - 1).inverse();
    const Vertices before = truth_mesh(r.dir, f - 1), now = truth_mesh(r.dir, f), lagged = dataset_mesh(r.dir, f);
    double largest_error = 0, change = 0;
    for (int v = 0; v < before.rows(); ++v) {
      const Eigen::Vector3d expected = move.apply(before.row(v).cast<double>().transpose());
      largest_error = std::max(largest_error, (expected - lagged.row(v).cast<double>().transpose()).norm());
      change = std::max(change, (expected - now.row(v).cast<double>().transpose()).norm());
    }
    EXPECT_LT(largest_error, 1e-5) << "frame " << f;
    largest_change = std::max(largest_change, change);
  }
  EXPECT_GT(largest_change, 1e-3) << "the expression hardly changes: the test shows nothing";
  // Only the expression lags: the dataset's poses are the true ones.
  const Dataset d = read_dataset(r.dir / "dataset");
  for (int f = 0; f < kFrames; ++f)
    EXPECT_TRUE(d.frame(std::string(kTake) + "_" + frame_id(f)).head_to_world.matrix().isApprox(
        truth_pose(r.dir, f).matrix(), 1e-12));
}

TEST(TrackingError, LaggedPoseGivesThePreviousFramesMeshAndPose) {
  Options o = tiny_capture();
  o.tracking_error.lag = 1;
  o.tracking_error.lag_pose = true;
  const RenderedCapture r(o);
  const Dataset d = read_dataset(r.dir / "dataset");
  for (int f = 1; f < kFrames; ++f) {
    EXPECT_EQ(dataset_mesh(r.dir, f), truth_mesh(r.dir, f - 1)) << f;
    EXPECT_TRUE(d.frame(std::string(kTake) + "_" + frame_id(f)).head_to_world.matrix().isApprox(
        truth_pose(r.dir, f - 1).matrix(), 1e-12));
  }
}

TEST(TrackingError, EyelidMisfitMovesTheEyelidsAndNotTheForehead) {
  Options o = tiny_capture();
  o.tracking_error.eyelid_misfit = 0.5;
  const RenderedCapture r(o);
  const Head head = make_head(o);
  const BlendshapeModel& model = head.model;
  std::vector<char> blink(model.num_vertices(), 0);
  for (const char* name : {"eyeBlink_L", "eyeBlink_R"}) {
    const int e = model.expression_index(name);
    ASSERT_GE(e, 0) << name;
    for (int v = 0; v < model.num_vertices(); ++v)
      if (model.expression_deltas[e].row(v).squaredNorm() > 0) blink[v] = 1;
  }
  double eyelid_moved = 0;
  int forehead = 0;
  for (int f = 0; f < kFrames; ++f) {
    const Vertices truth = truth_mesh(r.dir, f), mesh = dataset_mesh(r.dir, f);
    for (int v = 0; v < model.num_vertices(); ++v) {
      const double moved = (mesh.row(v) - truth.row(v)).norm();
      if (blink[v]) {
        eyelid_moved = std::max(eyelid_moved, moved);
        continue;
      }
      EXPECT_EQ(moved, 0.0) << "vertex " << v << " outside the blink shapes moved in frame " << f;
      const Eigen::Vector3d p = head.frame.to_face(model.neutral.positions.row(v).cast<double>().transpose());
      if (p.y() > 0.7 && p.z() > -1.0) ++forehead;
    }
  }
  EXPECT_GT(eyelid_moved, 1e-3);
  EXPECT_GT(forehead, 0) << "no forehead vertex was checked";
}

TEST(TrackingError, LipMisfitMovesOnlyWhatTheJawAndMouthShapesMove) {
  Options o = tiny_capture();
  o.tracking_error.lip_misfit = 0.3;
  const RenderedCapture r(o);
  const BlendshapeModel& model = make_head(o).model;
  std::vector<char> lip(model.num_vertices(), 0);
  for (size_t e = 0; e < model.expression_names.size(); ++e) {
    const std::string& name = model.expression_names[e];
    if (name.rfind("jaw", 0) != 0 && name.rfind("mouth", 0) != 0) continue;
    for (int v = 0; v < model.num_vertices(); ++v)
      if (model.expression_deltas[e].row(v).squaredNorm() > 0) lip[v] = 1;
  }
  double moved_most = 0;
  for (int f = 0; f < kFrames; ++f) {
    const Vertices truth = truth_mesh(r.dir, f), mesh = dataset_mesh(r.dir, f);
    for (int v = 0; v < model.num_vertices(); ++v) {
      const double moved = (mesh.row(v) - truth.row(v)).norm();
      if (lip[v]) moved_most = std::max(moved_most, moved);
      else EXPECT_EQ(moved, 0.0) << "vertex " << v << " outside the jaw and mouth shapes moved in frame " << f;
    }
  }
  EXPECT_GT(moved_most, 1e-3);
  // The record says which coefficients the meshes used.
  const nlohmann::json record = read_json_file(r.dir / "dataset/tracking_error.json");
  const nlohmann::json truth = read_json_file(r.dir / "ground_truth" / kTake / "frames.json");
  int differ = 0;
  for (int f = 0; f < kFrames; ++f)
    differ += record["frames"][f]["expression"]["jawOpen"] != truth["frames"][f]["expression"]["jawOpen"];
  EXPECT_GT(differ, 0);
}

// The dataset's mesh of each frame is off by the shape error of the frame's
// own expression, rotated with the head; the record says its size.
TEST(TrackingError, ShapeMisfitIsTheShapeErrorOfEachFramesExpression) {
  Options o = tiny_capture();
  o.tracking_error.shape_misfit = 0.3;
  const RenderedCapture r(o);
  const Head head = make_head(o);
  const BlendshapeModel& model = head.model;
  const TrackingError errors(head, o.tracking_error, uint64_t(o.seed));
  const nlohmann::json truth = read_json_file(r.dir / "ground_truth" / kTake / "frames.json");
  const nlohmann::json record = read_json_file(r.dir / "dataset/tracking_error.json");
  double largest = 0;
  for (int f = 0; f < kFrames; ++f) {
    std::vector<float> expression(model.expression_names.size(), 0.0f);
    for (const auto& [name, value] : truth["frames"][f]["expression"].items())
      expression[model.expression_index(name)] = value.get<float>();
    const Vertices expected = errors.shape_error(expression);
    const Eigen::MatrixXd d = (dataset_mesh(r.dir, f) - truth_mesh(r.dir, f)).cast<double>() * truth_pose(r.dir, f).R;
    EXPECT_LT((d - expected.cast<double>()).cwiseAbs().maxCoeff(), 1e-5) << "frame " << f;
    EXPECT_NEAR(record["frames"][f]["shape_misfit_rms_m"].get<double>(), errors.skin_rms(expected), 1e-9);
    largest = std::max(largest, d.rowwise().norm().maxCoeff());
  }
  EXPECT_GT(largest, 1e-3) << "the expressions hardly move the face: the test shows nothing";
}

// The tracker's model error: a shape's motion scaled along itself by a smooth
// gain, nothing where the shape does not move and on the eyeballs, linear in
// the coefficient, the same for the same subject (seed) every time.
TEST(TrackingError, ShapeMisfitScalesAShapesMotionByASmoothGainFixedPerSubject) {
  TrackingErrorOptions options;
  options.shape_misfit = 0.3;
  const Head head = make_procedural_head();
  const BlendshapeModel& model = head.model;
  const std::vector<char> eye = eyeball_vertices(head);
  const TrackingError errors(head, options, 3);
  const int jaw = model.expression_index("jawOpen");
  ASSERT_GE(jaw, 0);
  std::vector<float> open(model.expression_names.size(), 0.0f);
  EXPECT_EQ(errors.shape_error(open).cwiseAbs().maxCoeff(), 0.0f);
  open[jaw] = 1;
  const Eigen::MatrixXd full = errors.shape_error(open).cast<double>();
  open[jaw] = 0.5;
  EXPECT_LT((errors.shape_error(open).cast<double>() - 0.5 * full).cwiseAbs().maxCoeff(), 1e-7);
  const Eigen::MatrixXd delta = model.expression_deltas[jaw].cast<double>();
  std::vector<double> gain(model.num_vertices(), 0.0);
  for (int v = 0; v < model.num_vertices(); ++v) {
    const Eigen::Vector3d e = full.row(v).transpose(), m = delta.row(v).transpose();
    if (eye[v] || m.norm() == 0) {
      EXPECT_EQ(e.norm(), 0.0) << "vertex " << v;
      continue;
    }
    EXPECT_LE(e.cross(m).norm(), 1e-6 * e.norm() * m.norm()) << "vertex " << v << " is moved off its shape's direction";
    if (m.norm() > 1e-4) gain[v] = e.dot(m) / (0.3 * m.squaredNorm());
  }
  // Smooth: across the skin's short edges the gain changes little against its spread.
  double spread = 0, step = 0;
  int moved = 0, edges = 0;
  for (int v = 0; v < model.num_vertices(); ++v)
    if (gain[v] != 0) spread += gain[v] * gain[v], ++moved;
  const Triangles& faces = model.neutral.faces;
  for (int t = 0; t < faces.rows(); ++t)
    for (int k = 0; k < 3; ++k) {
      const int a = faces(t, k), b = faces(t, (k + 1) % 3);
      if (gain[a] == 0 || gain[b] == 0) continue;
      if ((model.neutral.positions.row(a) - model.neutral.positions.row(b)).norm() > 0.01) continue;
      step += std::abs(gain[a] - gain[b]), ++edges;
    }
  ASSERT_GT(moved, 10);
  ASSERT_GT(edges, 10);
  EXPECT_LT(step / edges, 0.1 * std::sqrt(spread / moved));

  // Another instance with the same seed draws the same gains; another seed others.
  const TrackingError again(head, options, 3);
  open[jaw] = 1;
  EXPECT_EQ(again.shape_error(open), errors.shape_error(open));
  const TrackingError other(head, options, 4);
  EXPECT_GT((other.shape_error(open) - errors.shape_error(open)).cwiseAbs().maxCoeff(), 1e-4);
}

TEST(TrackingError, BadOptionsAreRefusedByName) {
  Options o = tiny_capture();
  o.tracking_error.offset_m = -0.001;
  EXPECT_THROW(validate_options(o), Error);
  o = tiny_capture();
  o.tracking_error.lag = -1;
  EXPECT_THROW(validate_options(o), Error);
  o = tiny_capture();
  o.tracking_error.period_frames = 0;
  EXPECT_THROW(validate_options(o), Error);
  o = tiny_capture();
  o.tracking_error.shape_misfit = -0.1;
  EXPECT_THROW(validate_options(o), Error);
  EXPECT_NO_THROW(validate_options(tiny_capture()));
}

TEST(TrackingError, ImagesAndTruthAreIdenticalWithAndWithoutErrorsWhichAreRecorded) {
  Options o = tiny_capture();
  o.tracking_error.offset_m = 0.002;
  o.tracking_error.period_frames = 3;
  o.tracking_error.lag = 0.5;
  o.tracking_error.lag_pose = true;
  o.tracking_error.eyelid_misfit = 0.2;
  o.tracking_error.eyelid_gain = 0.8;
  o.tracking_error.lip_misfit = 0.1;
  o.tracking_error.lip_gain = 0.9;
  o.tracking_error.shape_misfit = 0.2;
  const RenderedCapture r(o);
  const fs::path& off = without_errors();
  int compared = 0, meshes_differ = 0;
  for (const auto& entry : fs::recursive_directory_iterator(off)) {
    if (!entry.is_regular_file()) continue;
    const fs::path rel = fs::relative(entry.path(), off);
    // dataset.json differs by the lagged poses (lag_pose).
    const bool dataset_meta = rel == "dataset/dataset.json";
    if (rel.string().rfind("dataset/meshes/", 0) == 0) {
      meshes_differ += file_bytes(entry.path()) != file_bytes(r.dir / rel);
      continue;
    }
    if (rel == "capture.json" || dataset_meta) continue;
    ASSERT_TRUE(fs::exists(r.dir / rel)) << rel;
    EXPECT_EQ(file_bytes(entry.path()), file_bytes(r.dir / rel)) << rel;
    ++compared;
  }
  EXPECT_GT(compared, 2 * kFrames * 2);  // at least the takes' and the dataset's images
  EXPECT_EQ(meshes_differ, kFrames);
  EXPECT_NO_THROW(validate_dataset(read_dataset(r.dir / "dataset")));

  const nlohmann::json record = read_json_file(r.dir / "dataset/tracking_error.json");
  EXPECT_EQ(record["options"]["offset_m"], 0.002);
  EXPECT_EQ(record["options"]["lag"], 0.5);
  ASSERT_EQ(record["frames"].size(), size_t(kFrames));
  for (const auto& frame : record["frames"]) EXPECT_NEAR(frame["offset_rms_m"].get<double>(), 0.002, 1e-6);
  EXPECT_EQ(read_json_file(r.dir / "capture.json")["tracking_error"], record["options"]);
}

}  // namespace
}  // namespace tega::synth
