#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <memory>

#include "multiface_fixture.h"
#include "tega/core/dataset.h"
#include "tega/core/error.h"
#include "tega/core/image.h"
#include "tega/core/options.h"
#include "tega/core/undistort.h"
#include "tega/ingest/multiface.h"
#include "test_support.h"

namespace tega {
namespace {
namespace fs = std::filesystem;
using test::MultifaceFixture;

// One fixture for the suite: rendering it is the slow part.
class MultifaceIngest : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    directory_ = new test::TempDir();
    fixture_ = new MultifaceFixture(test::write_multiface_fixture(directory_->path() / "capture"));
  }
  static void TearDownTestSuite() {
    delete fixture_;
    delete directory_;
  }

  static ingest::IngestOptions small_options() {
    ingest::IngestOptions o;
    o.width = 168;
    o.height = 256;
    o.frames = 4;
    o.test_frames = 0;
    o.matte_dilation_px = 3;
    o.matte_feather_px = 2;
    o.threads = 2;
    return o;
  }

  // A copy of the capture that a test may damage.
  fs::path copy_of_capture() const {
    const fs::path copy = scratch_.path() / "capture";
    fs::copy(fixture_->root, copy, fs::copy_options::recursive);
    return copy;
  }

  static const MultifaceFixture& fixture() { return *fixture_; }
  fs::path out() const { return scratch_.path() / "dataset"; }

  test::TempDir scratch_;

 private:
  static test::TempDir* directory_;
  static MultifaceFixture* fixture_;
};
test::TempDir* MultifaceIngest::directory_ = nullptr;
MultifaceFixture* MultifaceIngest::fixture_ = nullptr;

double mean_abs_difference(const Image8& a, const Image8& b, const Image8& mask) {
  double sum = 0;
  int count = 0;
  for (int y = 0; y < a.height; ++y) {
    for (int x = 0; x < a.width; ++x) {
      if (!mask.at(x, y, 0)) continue;
      for (int c = 0; c < 3; ++c) sum += std::abs(int(a.at(x, y, c)) - int(b.at(x, y, c)));
      count += 3;
    }
  }
  return sum / count;
}

// Pixels at least `margin` pixels inside the coverage, where no edge blurs.
Image8 eroded(const Image8& coverage, int margin) {
  Image8 out(coverage.width, coverage.height, 1, 0);
  for (int y = margin; y < coverage.height - margin; ++y) {
    for (int x = margin; x < coverage.width - margin; ++x) {
      bool inside = true;
      for (int dy = -margin; dy <= margin && inside; ++dy)
        for (int dx = -margin; dx <= margin && inside; ++dx) inside = coverage.at(x + dx, y + dy, 0) != 0;
      out.at(x, y, 0) = inside ? 255 : 0;
    }
  }
  return out;
}

TEST_F(MultifaceIngest, WritesAValidDatasetWithTheDefaultCameraSelectionAndSplit) {
  const auto summary = ingest::ingest_multiface(fixture().root, out(), small_options());
  const Dataset d = read_dataset(out());
  validate_dataset(d);

  // The cameras behind and above the head are dropped; the 3 held out are
  // the ring cameras nearest to 45 degrees right, straight ahead and 45 left.
  const auto& ring = fixture().ring;
  EXPECT_EQ(d.test.cameras, (std::vector<std::string>{ring[1], ring[3], ring[5]}));
  EXPECT_EQ(d.train.cameras, (std::vector<std::string>{ring[0], ring[2], ring[4], ring[6]}));
  EXPECT_FALSE(d.rig.contains(fixture().behind));
  EXPECT_FALSE(d.rig.contains(fixture().above));
  EXPECT_EQ(summary.test_cameras, d.test.cameras);

  // Test frames: every frame of the held-out EXP_ROM sequence. Train frames:
  // 4 of the 6 others, uniformly spread, in frame_list order.
  std::vector<std::string> expected_test, expected_train;
  std::vector<std::string> trainable;
  for (const auto& f : fixture().frames)
    (f.sequence == MultifaceFixture::kTestExpression ? expected_test : trainable).push_back(f.id());
  expected_train = {trainable[0], trainable[2], trainable[3], trainable[5]};
  EXPECT_EQ(d.test.frames, expected_test);
  EXPECT_EQ(d.train.frames, expected_train);
  EXPECT_EQ(d.frame(expected_test[0]).sequence, MultifaceFixture::kTestExpression);
  EXPECT_EQ(expected_test[0], std::string(MultifaceFixture::kTestExpression) + "_" + fixture().frames[6].frame);
  EXPECT_TRUE(d.eyeball_faces.empty());  // Multiface meshes have no eyeballs
}

TEST_F(MultifaceIngest, ConvertsTheRigMeshesAndPosesToMetresAndWorldSpace) {
  ingest::ingest_multiface(fixture().root, out(), small_options());
  const Dataset d = read_dataset(out());

  for (const Camera& camera : d.rig.cameras) {
    const Camera& truth = fixture().rig.camera(camera.name);
    EXPECT_FALSE(camera.has_distortion());
    EXPECT_TRUE(camera.K.isApprox(truth.K, 1e-9));
    EXPECT_LT((camera.center() - truth.center()).norm(), 1e-6) << camera.name;  // metres, not millimetres
  }

  // The template: the first neutral frame in head space, with the OBJ's topology and UVs.
  const Mesh& head = fixture().head;
  ASSERT_EQ(d.template_mesh.num_vertices(), head.num_vertices());
  EXPECT_LT((d.template_mesh.positions - head.positions).cwiseAbs().maxCoeff(), 1e-6);
  EXPECT_EQ(d.template_mesh.faces, head.faces);
  EXPECT_EQ(d.template_mesh.uv_faces, head.uv_faces);
  EXPECT_EQ(d.template_mesh.uvs, head.uvs);

  for (const auto& frame : d.frames) {
    const RigidTransform& truth = fixture().poses.at(frame.id);
    EXPECT_LT((frame.head_to_world.R - truth.R).cwiseAbs().maxCoeff(), 1e-8) << frame.id;
    EXPECT_LT((frame.head_to_world.t - truth.t).norm(), 1e-8) << frame.id;
    const Vertices mesh = d.load_mesh(frame.id);
    EXPECT_LT((mesh - fixture().world(frame.id)).cwiseAbs().maxCoeff(), 2e-6) << frame.id;
  }
}

TEST_F(MultifaceIngest, ImagesAreUndistortedAndMattedByTheMeshSilhouette) {
  ingest::ingest_multiface(fixture().root, out(), small_options());
  const Dataset d = read_dataset(out());
  const std::string frame = d.train.frames[1];
  for (const std::string& name : {fixture().ring[3], fixture().ring[6]}) {
    const Camera& pinhole = d.rig.camera(name);
    const Image8 image = read_image_u8(d.image_path(name, frame));
    ASSERT_EQ(image.channels, 4);
    const Image8 expected = fixture().render(pinhole, frame);
    const Image8 captured = fixture().render(fixture().rig.camera(name), frame);
    const Image8 inside = eroded(fixture().coverage(pinhole, frame), 1);
    Image8 rgb(image.width, image.height, 3);
    for (int y = 0; y < image.height; ++y)
      for (int x = 0; x < image.width; ++x)
        for (int c = 0; c < 3; ++c) rgb.at(x, y, c) = image.at(x, y, c);
    // Undistorted: close to the pinhole rendering, where the captured image is not.
    const double undistorted_error = mean_abs_difference(rgb, expected, inside);
    EXPECT_LT(undistorted_error, 0.5 * mean_abs_difference(captured, expected, inside)) << name;

    // Matte: opaque on the head and within the dilation, clear far from it.
    const Image8 coverage = fixture().coverage(pinhole, frame);
    const Image8 near = eroded(coverage, 0);
    for (int y = 0; y < image.height; ++y) {
      for (int x = 0; x < image.width; ++x) {
        if (near.at(x, y, 0)) EXPECT_EQ(image.at(x, y, 3), 255) << name << " " << x << "," << y;
      }
    }
    EXPECT_EQ(image.at(0, 0, 3), 0);
    EXPECT_EQ(image.at(image.width - 1, image.height - 1, 3), 0);
  }
}

TEST_F(MultifaceIngest, MatteNoneIsOpaqueAndDownsampleHalvesCamerasAndImages) {
  ingest::IngestOptions options = small_options();
  options.matte = "none";
  ingest::ingest_multiface(fixture().root, out(), options);
  options.downsample = 2;
  const fs::path half = scratch_.path() / "half";
  ingest::ingest_multiface(fixture().root, half, options);
  const Dataset full = read_dataset(out());
  const Dataset small = read_dataset(half);
  validate_dataset(small);

  const std::string camera = full.train.cameras[0], frame = full.train.frames[0];
  EXPECT_EQ(small.rig.camera(camera).width, 84);
  EXPECT_EQ(small.rig.camera(camera).height, 128);
  EXPECT_TRUE(small.rig.camera(camera).K.isApprox(full.rig.camera(camera).scaled(0.5).K, 1e-12));
  const Image8 a = read_image_u8(full.image_path(camera, frame));
  const Image8 b = read_image_u8(small.image_path(camera, frame));
  int worst = 0;
  for (int y = 0; y < b.height; ++y) {
    for (int x = 0; x < b.width; ++x) {
      for (int c = 0; c < 3; ++c) {
        const int box = (a.at(2 * x, 2 * y, c) + a.at(2 * x + 1, 2 * y, c) + a.at(2 * x, 2 * y + 1, c) +
                         a.at(2 * x + 1, 2 * y + 1, c) + 2) / 4;
        worst = std::max(worst, std::abs(box - int(b.at(x, y, c))));
      }
      EXPECT_EQ(b.at(x, y, 3), 255);
    }
  }
  EXPECT_LE(worst, 1);  // box filter of the same undistorted image, rounded twice
}

TEST_F(MultifaceIngest, ExplicitCamerasExpressionsAndFaceForwardAreHonoured) {
  ingest::IngestOptions options = small_options();
  options.cameras = {fixture().ring[0], fixture().ring[3], fixture().behind};
  options.test_cameras = {fixture().behind};
  options.expressions = {MultifaceFixture::kNeutral, MultifaceFixture::kTestExpression};
  options.test_expressions = {"EXP_ROM"};
  ingest::ingest_multiface(fixture().root, out(), options);
  const Dataset d = read_dataset(out());
  EXPECT_EQ(d.train.cameras, (std::vector<std::string>{fixture().ring[0], fixture().ring[3]}));
  EXPECT_EQ(d.test.cameras, std::vector<std::string>{fixture().behind});
  for (const auto& id : d.train.frames) EXPECT_EQ(d.frame(id).sequence, MultifaceFixture::kNeutral);

  // The face looks along +z in the fixture's head space; -z makes the camera
  // behind the head the frontal one.
  ingest::IngestOptions backwards = small_options();
  backwards.face_forward = {0, 0, -1};
  backwards.test_camera_azimuths_deg = {0};
  const fs::path reversed = scratch_.path() / "reversed";
  ingest::ingest_multiface(fixture().root, reversed, backwards);
  EXPECT_EQ(read_dataset(reversed).test.cameras, std::vector<std::string>{fixture().behind});
}

// A broken capture fails naming the file at fault and leaves nothing at --out.
void expect_failure_naming(const fs::path& capture, const fs::path& out, const ingest::IngestOptions& options,
                           const fs::path& culprit) {
  try {
    ingest::ingest_multiface(capture, out, options);
    ADD_FAILURE() << "ingest succeeded";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find(culprit.string()), std::string::npos) << e.what();
  }
  EXPECT_FALSE(fs::exists(out));
  for (const auto& entry : fs::directory_iterator(out.parent_path()))
    EXPECT_EQ(entry.path().filename().string().find("dataset"), std::string::npos) << entry.path();
}

TEST_F(MultifaceIngest, AMalformedKrtFailsNamingIt) {
  const fs::path capture = copy_of_capture();
  std::string krt = read_text_file(capture / "KRT");
  krt.replace(krt.find('\n', krt.find('\n') + 1) + 1, 0, "0.0 1.0\n");  // a short line into K
  test::write_text(capture / "KRT", krt);
  expect_failure_naming(capture, out(), small_options(), capture / "KRT");
}

TEST_F(MultifaceIngest, AMissingMeshFailsNamingIt) {
  const fs::path capture = copy_of_capture();
  const ingest::MultifaceCapture layout{capture};
  const ingest::MultifaceFrame& frame = fixture().frames[7];  // a test frame
  fs::remove(layout.mesh_bin(frame));
  fs::remove(layout.mesh_obj(frame));
  expect_failure_naming(capture, out(), small_options(), layout.mesh_bin(frame));
}

TEST_F(MultifaceIngest, AnImageOfTheWrongSizeFailsNamingIt) {
  const fs::path capture = copy_of_capture();
  const ingest::MultifaceCapture layout{capture};
  const fs::path image = layout.image(fixture().ring[4], fixture().frames.back());
  write_image(Image8(100, 200, 3, 128), image);
  expect_failure_naming(capture, out(), small_options(), image);
}

TEST_F(MultifaceIngest, AMissingAndATruncatedImageAreLeftOutAndRecorded) {
  const fs::path capture = copy_of_capture();
  const ingest::MultifaceCapture layout{capture};
  const auto& ring = fixture().ring;
  // A train camera's image of a train frame deleted; a test camera's image
  // of a test frame cut short: its PNG header still reads, its pixels do not.
  const ingest::MultifaceFrame& train_frame = fixture().frames[2];
  const ingest::MultifaceFrame& test_frame = fixture().frames[7];
  const fs::path deleted = layout.image(ring[2], train_frame);
  const fs::path truncated = layout.image(ring[3], test_frame);
  fs::remove(deleted);
  fs::resize_file(truncated, fs::file_size(truncated) / 2);

  const auto summary = ingest::ingest_multiface(capture, out(), small_options());
  const Dataset d = read_dataset(out());
  validate_dataset(d);
  ASSERT_EQ(d.missing_images.size(), 2u);
  EXPECT_EQ(d.missing_images[0].camera, ring[2]);
  EXPECT_EQ(d.missing_images[0].frame, train_frame.id());
  EXPECT_NE(d.missing_images[0].reason.find(deleted.string() + ": is missing"), std::string::npos)
      << d.missing_images[0].reason;
  EXPECT_EQ(d.missing_images[1].camera, ring[3]);
  EXPECT_EQ(d.missing_images[1].frame, test_frame.id());
  EXPECT_NE(d.missing_images[1].reason.find(truncated.string()), std::string::npos) << d.missing_images[1].reason;
  EXPECT_TRUE(d.dropped_frames.empty());
  EXPECT_FALSE(fs::exists(d.image_path(ring[2], train_frame.id())));
  EXPECT_FALSE(fs::exists(d.image_path(ring[3], test_frame.id())));
  EXPECT_TRUE(fs::exists(d.image_path(ring[3], train_frame.id())));

  // The rest is all there: every frame, every other image.
  EXPECT_EQ(d.train.frames.size(), 4u);
  EXPECT_EQ(d.test.frames.size(), 3u);
  EXPECT_EQ(summary.missing_images, 2);
  EXPECT_EQ(summary.images, 7 * 7 - 2);
}

TEST_F(MultifaceIngest, AFrameMostCamerasLackIsDroppedWhole) {
  const fs::path capture = copy_of_capture();
  const ingest::MultifaceCapture layout{capture};
  const ingest::MultifaceFrame& frame = fixture().frames[0];  // a train frame
  for (int c = 0; c < 4; ++c) fs::remove(layout.image(fixture().ring[c], frame));  // 3 of 7 cameras left

  const auto summary = ingest::ingest_multiface(capture, out(), small_options());
  const Dataset d = read_dataset(out());
  validate_dataset(d);
  ASSERT_EQ(d.dropped_frames.size(), 1u);
  EXPECT_EQ(d.dropped_frames[0].frame, frame.id());
  EXPECT_NE(d.dropped_frames[0].reason.find("usable images from 3 of 7 cameras"), std::string::npos)
      << d.dropped_frames[0].reason;
  EXPECT_TRUE(d.missing_images.empty());
  EXPECT_EQ(d.train.frames.size(), 3u);
  EXPECT_EQ(std::count(d.train.frames.begin(), d.train.frames.end(), frame.id()), 0);
  EXPECT_FALSE(fs::exists(d.mesh_path(frame.id())));
  EXPECT_FALSE(fs::exists(d.image_path(fixture().ring[5], frame.id())));
  EXPECT_EQ(summary.dropped_frames, 1);
}

TEST_F(MultifaceIngest, ACaptureMissingTooMuchFailsSayingWhatAndLeavesNothing) {
  const fs::path capture = copy_of_capture();
  const ingest::MultifaceCapture layout{capture};
  const std::string dead = fixture().ring[4];
  for (const auto& frame : fixture().frames) fs::remove(layout.image(dead, frame));
  const std::string message = test::error_message([&] { ingest::ingest_multiface(capture, out(), small_options()); });
  EXPECT_NE(message.find(capture.string() + ": camera " + dead + " has no usable image of 7 of the 7 frames"),
            std::string::npos)
      << message;
  EXPECT_NE(message.find("option"), std::string::npos) << message;  // what to do
  EXPECT_NE(message.find("missing_images.max_missing_fraction_per_camera"), std::string::npos) << message;
  EXPECT_FALSE(fs::exists(out()));
  for (const auto& entry : fs::directory_iterator(out().parent_path()))
    EXPECT_EQ(entry.path().filename().string().find("dataset"), std::string::npos) << entry.path();

  // Leaving the camera out is what the message suggests, and it works.
  ingest::IngestOptions without = small_options();
  for (const auto& name : fixture().ring)
    if (name != dead) without.cameras.push_back(name);
  ingest::ingest_multiface(capture, out(), without);
  EXPECT_TRUE(read_dataset(out()).missing_images.empty());
}

TEST_F(MultifaceIngest, AnExistingDatasetIsKeptUnlessReplacing) {
  fs::create_directories(out());
  test::write_text(out() / "keep.txt", "mine");
  EXPECT_THROW(ingest::ingest_multiface(fixture().root, out(), small_options()), Error);
  EXPECT_TRUE(fs::exists(out() / "keep.txt"));
  ingest::ingest_multiface(fixture().root, out(), small_options(), true);
  EXPECT_FALSE(fs::exists(out() / "keep.txt"));
  EXPECT_TRUE(fs::exists(out() / "dataset.json"));
}

TEST(MultifaceIngestOptions, StudioConfigEqualsTheDefaults) {
  ingest::IngestOptions from_file;
  load_options(from_file, fs::path(TEGA_SOURCE_DIR) / "studio_configs" / "multiface.yaml", "ingest");
  EXPECT_EQ(options_to_yaml(from_file), options_to_yaml(ingest::IngestOptions{}));
  ingest::IngestOptions changed;
  load_options_from_string(changed, "ingest:\n  downsample: 2\n  matte: none\n", "ingest", "inline");
  EXPECT_EQ(changed.downsample, 2);
  EXPECT_EQ(changed.matte, "none");
}

TEST(MultifaceIngestOptions, BadOptionsAreRefusedBeforeAnyWork) {
  test::TempDir dir;
  ingest::IngestOptions options;
  options.matte = "alpha";
  EXPECT_THROW(ingest::ingest_multiface(dir.path(), dir / "out", options), Error);
  options = {};
  options.downsample = 3;  // 1334 is not a multiple of 3
  EXPECT_THROW(ingest::ingest_multiface(dir.path(), dir / "out", options), Error);
  EXPECT_FALSE(fs::exists(dir / "out"));
}

}  // namespace
}  // namespace tega
