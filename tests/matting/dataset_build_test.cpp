// tega dataset build on a 13-camera virtual-studio capture, with the studio's
// ground truth as the tracked meshes and as the mattes, checked against the
// studio's own dataset (rendered without the lens, alpha = exact coverage).
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>

#include "cli_support.h"
#include "small_studio.h"
#include "tega/core/dataset.h"
#include "tega/core/downsample.h"
#include "tega/core/error.h"
#include "tega/core/files.h"
#include "tega/core/image.h"
#include "tega/core/take.h"
#include "tega/matting/dataset_build.h"
#include "tega/matting/matte.h"
#include "tega/scoring/tracking_scores.h"
#include "tega/synth/virtual_studio.h"
#include "test_support.h"

namespace fs = std::filesystem;

namespace tega::matting {
namespace {

constexpr int kFramesPerTake = 3;

// The studio's true alpha as `tega matte` would write it.
void write_true_mattes(const fs::path& capture, const fs::path& mattes) {
  for (const auto& take : read_capture(capture).performance_takes({}, "to matte")) {
    const fs::path alpha = capture / "ground_truth" / take / "alpha";
    for (const auto& camera : fs::directory_iterator(alpha)) {
      fs::create_directories(mattes / take / camera.path().filename());
      for (const auto& image : fs::directory_iterator(camera.path()))
        fs::copy_file(image.path(), mattes / take / camera.path().filename() / image.path().filename());
    }
    write_text_atomic(mattes / take / "mattes.json", "{\"take\": \"" + take + "\"}\n");
  }
}

class DatasetBuild : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    dir_ = new test::TempDir;
    synth::Options studio = test::small_studio(13, 512, 384, kFramesPerTake);
    studio.takes = {"expressions", "speech"};
    studio.test_takes = {"speech"};
    studio.test_cameras = 2;
    studio.write_fine_meshes = false;
    synth::render_virtual_studio(studio, capture());
    scoring::write_studio_truth_as_tracked(capture(), tracked());
    write_true_mattes(capture(), mattes());
  }
  static void TearDownTestSuite() { delete dir_; }

  static fs::path capture() { return *dir_ / "capture"; }
  static fs::path tracked() { return *dir_ / "tracked"; }
  static fs::path mattes() { return *dir_ / "mattes"; }

  // A build into a fresh directory of this test; inputs may be replaced.
  DatasetBuildSummary build(const DatasetBuildOptions& options, const std::string& name,
                            const fs::path& tracked_dir = {}, const fs::path& mattes_dir = {}) {
    DatasetBuildRequest request{capture(), tracked_dir.empty() ? tracked() : tracked_dir,
                                mattes_dir.empty() ? mattes() : mattes_dir, out_ / name};
    return build_dataset(request, options);
  }

  // A copy of the mattes to damage.
  fs::path mattes_copy() {
    const fs::path copy = out_ / "mattes";
    fs::copy(mattes(), copy, fs::copy_options::recursive);
    return copy;
  }

  static test::TempDir* dir_;
  test::TempDir out_;
};

test::TempDir* DatasetBuild::dir_ = nullptr;

std::string error_of(const std::function<void()>& f) {
  try {
    f();
  } catch (const Error& e) {
    return e.what();
  }
  return "(no error)";
}

struct ImageErrors {
  double alpha_mean = 0;      // mean |alpha - true alpha| / 255 over every pixel
  double colour_mean = 0;     // mean |rgb - true rgb| / 255 where both are opaque
  double opaque_pixels = 0;   // share of the image where both are opaque
};

ImageErrors compare(const Image8& built, const Image8& truth) {
  ImageErrors e;
  double alpha = 0, colour = 0;
  int64_t opaque = 0;
  const int64_t pixels = int64_t(built.width) * built.height;
  for (int y = 0; y < built.height; ++y) {
    for (int x = 0; x < built.width; ++x) {
      alpha += std::abs(built.at(x, y, 3) - truth.at(x, y, 3));
      if (built.at(x, y, 3) < 250 || truth.at(x, y, 3) < 250) continue;
      ++opaque;
      for (int c = 0; c < 3; ++c) colour += std::abs(built.at(x, y, c) - truth.at(x, y, c));
    }
  }
  e.alpha_mean = alpha / 255 / double(pixels);
  e.colour_mean = opaque ? colour / 255 / (3.0 * double(opaque)) : 0;
  e.opaque_pixels = double(opaque) / double(pixels);
  return e;
}

// The built dataset against the studio's own, at full and half size: every
// image's alpha and colour, and the rig.
void expect_matches_truth(const fs::path& built_root, const fs::path& truth_root, int downsample) {
  const Dataset built = read_dataset(built_root);
  validate_dataset(built);
  const Dataset truth = read_dataset(truth_root);
  ASSERT_EQ(built.frames.size(), truth.frames.size());
  ASSERT_EQ(built.rig.cameras.size(), truth.rig.cameras.size());
  for (size_t c = 0; c < built.rig.cameras.size(); ++c) {
    const Camera expected = truth.rig.cameras[c].scaled(1.0 / downsample);
    const Camera& got = built.rig.cameras[c];
    EXPECT_EQ(got.name, expected.name);
    EXPECT_EQ(got.width, expected.width);
    EXPECT_LT((got.K - expected.K).norm(), 1e-9) << got.name;
    EXPECT_FALSE(got.has_distortion());
  }
  double worst_alpha = 0, worst_colour = 0, sum_alpha = 0, sum_colour = 0;
  int images = 0;
  for (const auto& frame : built.frames) {
    EXPECT_LT((frame.head_to_world.t - truth.frame(frame.id).head_to_world.t).norm(), 1e-9) << frame.id;
    for (const auto& camera : built.rig.cameras) {
      const Image8 image = read_image_u8(built.image_path(camera.name, frame.id));
      const Image8 reference = box_downsample(read_image_u8(truth.image_path(camera.name, frame.id)), downsample);
      const ImageErrors e = compare(image, reference);
      ASSERT_GT(e.opaque_pixels, 0.02) << camera.name << " " << frame.id << ": the head should be in view";
      worst_alpha = std::max(worst_alpha, e.alpha_mean);
      worst_colour = std::max(worst_colour, e.colour_mean);
      sum_alpha += e.alpha_mean;
      sum_colour += e.colour_mean;
      ++images;
    }
  }
  std::printf("downsample %d, %d images: alpha error mean %.4f worst %.4f; colour error (opaque) mean %.4f worst %.4f\n",
              downsample, images, sum_alpha / images, worst_alpha, sum_colour / images, worst_colour);
  // Measured worst over the images: alpha 0.0007 (full size) and 0.0004
  // (half), colour 0.0028 and 0.0012: what the bilinear undistortion costs.
  // The same images shifted by a quarter pixel (a principal point scaled
  // without the half-pixel terms, at half size) score at least alpha 0.0014
  // and colour 0.0043 at half size, colour 0.0060 at full size; half a pixel
  // at full size, alpha 0.0015 and colour 0.0107.
  EXPECT_LT(worst_alpha, 0.001);
  EXPECT_LT(worst_colour, 0.004);
}

TEST_F(DatasetBuild, MatchesTheStudiosOwnDatasetAtFullAndHalfSize) {
  for (const int downsample : {1, 2}) {
    DatasetBuildOptions options;
    options.downsample = downsample;
    options.frames = 0;
    options.test_takes = {"speech"};
    const auto s = build(options, "x" + std::to_string(downsample));
    EXPECT_EQ(s.images, 2 * kFramesPerTake * 13);
    EXPECT_EQ(s.images_kept, 0);
    expect_matches_truth(s.dataset, capture() / "dataset", downsample);
  }
}

// Without tega matte's mattes, the build mattes each sampled image itself,
// at the dataset's size: at full size the very mattes tega matte makes, so
// the very same dataset; shrunk, mattes made from the shrunk photo, close to
// tega matte's shrunk and to the studio's true alpha.
TEST_F(DatasetBuild, MattesMadeHereAreTegaMattesAndMatchTheTruth) {
  DatasetBuildOptions options;
  options.frames = 0;
  options.test_takes = {"speech"};
  const fs::path made = out_ / "made_mattes";
  matte_capture({capture(), tracked(), made}, options.matte);
  const Dataset truth = read_dataset(capture() / "dataset");
  for (const int downsample : {1, 2}) {
    options.downsample = downsample;
    const std::string suffix = std::to_string(downsample);
    const auto two_stages = build_dataset({capture(), tracked(), made, out_ / ("two" + suffix)}, options);
    const auto one_pass = build_dataset({capture(), tracked(), {}, out_ / ("one" + suffix)}, options);
    ASSERT_EQ(one_pass.images, two_stages.images);
    const Dataset built = read_dataset(one_pass.dataset), reference = read_dataset(two_stages.dataset);
    validate_dataset(built);
    double worst_alpha = 0, worst_difference = 0;
    for (const auto& frame : built.frames) {
      for (const auto& camera : built.rig.cameras) {
        const Image8 image = read_image_u8(built.image_path(camera.name, frame.id));
        const Image8 tega_matte_image = read_image_u8(reference.image_path(camera.name, frame.id));
        if (downsample == 1)
          ASSERT_EQ(image.pixels, tega_matte_image.pixels) << camera.name << " " << frame.id;
        worst_difference = std::max(worst_difference, compare(image, tega_matte_image).alpha_mean);
        const Image8 true_image = box_downsample(read_image_u8(truth.image_path(camera.name, frame.id)), downsample);
        worst_alpha = std::max(worst_alpha, compare(image, true_image).alpha_mean);
      }
    }
    std::printf("mattes made here, downsample %d: worst image's alpha error %.4f, its difference from tega matte's %.4f\n",
                downsample, worst_alpha, worst_difference);
    EXPECT_LT(worst_alpha, 0.02) << downsample;  // the bound on a matte
    EXPECT_LT(worst_difference, 0.005) << downsample;
  }
}

TEST_F(DatasetBuild, ZstdImagesHoldThePngsPixels) {
  DatasetBuildOptions options;
  options.frames = 2;
  options.test_takes = {"speech"};
  const auto png = build(options, "png");
  options.image_format = "zst";
  const auto zst = build(options, "zst");
  const Dataset a = read_dataset(png.dataset), b = read_dataset(zst.dataset);
  validate_dataset(b);
  EXPECT_EQ(b.image_extension, ".zst");
  for (const auto& frame : b.frames) {
    for (const auto& camera : b.rig.cameras) {
      ASSERT_EQ(b.image_path(camera.name, frame.id).extension(), ".zst");
      EXPECT_EQ(read_image_u8(b.image_path(camera.name, frame.id)).pixels,
                read_image_u8(a.image_path(camera.name, frame.id)).pixels)
          << camera.name << " " << frame.id;
    }
  }
  options.image_format = "jpeg";
  EXPECT_NE(error_of([&] { build(options, "jpeg"); }).find("image_format must be png or zst"), std::string::npos);
}

TEST_F(DatasetBuild, SamplesFramesUniformlyAndSplitsAsConfigured) {
  DatasetBuildOptions options;
  options.frames = 4;  // of the 6 tracked frames: the middles of 4 equal parts
  options.test_cameras = {"cam03", "cam07"};
  const auto s = build(options, "sampled");
  const Dataset d = read_dataset(s.dataset);
  validate_dataset(d);
  std::vector<std::string> ids;
  for (const auto& f : d.frames) ids.push_back(f.id);
  EXPECT_EQ(ids, (std::vector<std::string>{"expressions_000000", "expressions_000002", "speech_000000",
                                           "speech_000002"}));
  EXPECT_EQ(d.frame("speech_000002").sequence, "speech");
  // test_takes empty: the last performance take is held out.
  EXPECT_EQ(d.test.frames, (std::vector<std::string>{"speech_000000", "speech_000002"}));
  EXPECT_EQ(d.train.frames, (std::vector<std::string>{"expressions_000000", "expressions_000002"}));
  EXPECT_EQ(d.test.cameras, (std::vector<std::string>{"cam03", "cam07"}));
  EXPECT_EQ(d.train.cameras.size(), 11u);
  EXPECT_EQ(d.rig.cameras.front().width, 256);
  EXPECT_FALSE(d.eyeball_faces.empty());

  options = {};
  options.test_takes = {"expressions"};
  options.test_camera_count = 3;
  const Dataset other = read_dataset(build(options, "counted").dataset);
  EXPECT_EQ(other.test.cameras, spread_test_cameras(other.rig, 3));
  EXPECT_EQ(other.test.frames.size(), size_t(kFramesPerTake));
  EXPECT_EQ(other.frame(other.test.frames.front()).sequence, "expressions");
}

TEST_F(DatasetBuild, AnInterruptedBuildContinuesWhereItStopped) {
  const fs::path damaged = mattes_copy();
  // A matte whose header reads but whose pixels do not: the build fails at
  // the last camera's image, after writing the others.
  const fs::path matte = damaged / "speech" / "cam12" / "000002.png";
  fs::resize_file(matte, fs::file_size(matte) / 2);
  DatasetBuildOptions options;
  options.frames = 0;
  EXPECT_NE(error_of([&] { build(options, "resumed", {}, damaged); }).find(matte.string()), std::string::npos);
  EXPECT_FALSE(fs::exists(out_ / "resumed"));
  ASSERT_TRUE(fs::exists(out_ / "resumed.partial"));

  fs::copy_file(mattes() / "speech" / "cam12" / "000002.png", matte, fs::copy_options::overwrite_existing);
  const auto resumed = build(options, "resumed", {}, damaged);
  EXPECT_GE(resumed.images_kept, 12 * 2 * kFramesPerTake);
  EXPECT_LT(resumed.images_kept, resumed.images);
  EXPECT_FALSE(fs::exists(out_ / "resumed.partial"));
  EXPECT_FALSE(fs::exists(resumed.dataset / ".resume-key"));
  validate_dataset(read_dataset(resumed.dataset));

  // Other options start afresh.
  fs::resize_file(matte, fs::file_size(matte) / 2);
  EXPECT_THROW(build(options, "again", {}, damaged), Error);
  fs::copy_file(mattes() / "speech" / "cam12" / "000002.png", matte, fs::copy_options::overwrite_existing);
  options.png_compression = 6;
  EXPECT_EQ(build(options, "again", {}, damaged).images_kept, 0);
}

TEST_F(DatasetBuild, BadInputIsAnErrorNamingTheFile) {
  const fs::path damaged = mattes_copy();
  DatasetBuildOptions options;

  const fs::path missing = damaged / "expressions" / "cam05" / "000001.png";
  fs::remove(missing);
  EXPECT_NE(error_of([&] { build(options, "a", {}, damaged); }).find(missing.string() + ": is missing"),
            std::string::npos);
  write_image(Image8(100, 80, 1), missing);
  const std::string size_error = error_of([&] { build(options, "b", {}, damaged); });
  EXPECT_NE(size_error.find(missing.string() + ": is 100x80"), std::string::npos) << size_error;
  fs::copy_file(mattes() / "expressions" / "cam05" / "000001.png", missing, fs::copy_options::overwrite_existing);

  const fs::path done = damaged / "speech" / "mattes.json";
  fs::remove(done);
  EXPECT_NE(error_of([&] { build(options, "c", {}, damaged); }).find(done.string() + ": is missing"),
            std::string::npos);
  write_text_atomic(done, "{}\n");

  const fs::path tracked_copy = out_ / "tracked";
  fs::copy(tracked(), tracked_copy, fs::copy_options::recursive);
  const fs::path mesh = tracked_copy / "speech" / "000001.bin";
  fs::remove(mesh);
  EXPECT_NE(error_of([&] { build(options, "d", tracked_copy, damaged); }).find(mesh.string() + ": is missing"),
            std::string::npos);

  options.downsample = 5;
  EXPECT_NE(error_of([&] { build(options, "f"); }).find("rig.json: camera cam00 is 512x384, which downsample 5"),
            std::string::npos);
  options = {};
  options.test_takes = {"nope"};
  EXPECT_NE(error_of([&] { build(options, "g"); }).find("capture.json: has no performance take 'nope'"),
            std::string::npos);
  options = {};
  options.test_cameras = {"cam99"};
  EXPECT_NE(error_of([&] { build(options, "h"); }).find("rig.json: has no camera 'cam99'"), std::string::npos);
  EXPECT_FALSE(fs::exists(out_ / "h.partial"));  // bad input is found before anything is written
}

// Damages the shared capture's images for one test and restores them after.
class CaptureImagesSetAside {
 public:
  explicit CaptureImagesSetAside(fs::path aside) : aside_(std::move(aside)) { fs::create_directories(aside_); }
  ~CaptureImagesSetAside() {
    for (const auto& [image, copy] : saved_) fs::copy_file(copy, image, fs::copy_options::overwrite_existing);
  }
  CaptureImagesSetAside(const CaptureImagesSetAside&) = delete;
  CaptureImagesSetAside& operator=(const CaptureImagesSetAside&) = delete;

  void remove(const fs::path& image) {
    save(image);
    fs::remove(image);
  }
  void truncate(const fs::path& image) {
    save(image);
    fs::resize_file(image, fs::file_size(image) / 2);
  }

 private:
  void save(const fs::path& image) {
    const fs::path copy = aside_ / std::to_string(saved_.size());
    fs::copy_file(image, copy);
    saved_.emplace_back(image, copy);
  }
  fs::path aside_;
  std::vector<std::pair<fs::path, fs::path>> saved_;
};

fs::path capture_image(const fs::path& capture, const std::string& take, const std::string& camera, int frame) {
  char name[16];
  std::snprintf(name, sizeof name, "%06d.png", frame);
  return capture / "takes" / take / camera / name;
}

TEST_F(DatasetBuild, AMissingAndATruncatedImageAreLeftOutAndRecorded) {
  CaptureImagesSetAside damage(out_ / "aside");
  const fs::path deleted = capture_image(capture(), "expressions", "cam02", 1);
  const fs::path truncated = capture_image(capture(), "speech", "cam07", 2);
  damage.remove(deleted);
  damage.truncate(truncated);
  DatasetBuildOptions options;
  options.frames = 0;
  const auto s = build(options, "gaps");
  const Dataset d = read_dataset(s.dataset);
  validate_dataset(d);
  ASSERT_EQ(d.missing_images.size(), 2u);
  EXPECT_EQ(d.missing_images[0].camera, "cam02");
  EXPECT_EQ(d.missing_images[0].frame, "expressions_000001");
  EXPECT_NE(d.missing_images[0].reason.find(deleted.string() + ": is missing"), std::string::npos)
      << d.missing_images[0].reason;
  EXPECT_EQ(d.missing_images[1].camera, "cam07");
  EXPECT_EQ(d.missing_images[1].frame, "speech_000002");
  EXPECT_NE(d.missing_images[1].reason.find(truncated.string()), std::string::npos) << d.missing_images[1].reason;
  EXPECT_FALSE(fs::exists(d.image_path("cam02", "expressions_000001")));
  EXPECT_FALSE(fs::exists(d.image_path("cam07", "speech_000002")));
  EXPECT_TRUE(fs::exists(d.image_path("cam07", "speech_000001")));
  EXPECT_EQ(d.frames.size(), size_t(2 * kFramesPerTake));
  EXPECT_EQ(s.missing_images, 2);
  EXPECT_EQ(s.images, 13 * 2 * kFramesPerTake - 2);

  // `tega dataset check` reports the gaps.
  const auto check = test::run_tega("dataset check --data " + s.dataset.string());
  ASSERT_EQ(check.exit_code, 0) << check.output;
  EXPECT_NE(check.output.find("2 missing images (cam02: 1, cam07: 1)"), std::string::npos) << check.output;
  EXPECT_NE(check.output.find("missing image: camera cam07, frame speech_000002: " + truncated.string()),
            std::string::npos)
      << check.output;
}

TEST_F(DatasetBuild, ACameraMissingMostFramesStopsItSayingWhatAndWritingNothing) {
  CaptureImagesSetAside damage(out_ / "aside");
  for (const char* take : {"expressions", "speech"})
    for (int frame = 0; frame < kFramesPerTake; ++frame) damage.remove(capture_image(capture(), take, "cam04", frame));
  DatasetBuildOptions options;
  options.frames = 0;
  const std::string message = error_of([&] { build(options, "dead"); });
  EXPECT_NE(message.find(capture().string() + ": camera cam04 has no usable image of 6 of the 6 frames"),
            std::string::npos)
      << message;
  EXPECT_NE(message.find("missing_images.max_missing_fraction_per_camera"), std::string::npos) << message;
  EXPECT_FALSE(fs::exists(out_ / "dead"));
  EXPECT_FALSE(fs::exists(out_ / "dead.partial"));  // found before anything was written
}

TEST_F(DatasetBuild, OnTheCommandLine) {
  const std::string inputs = " --capture " + capture().string() + " --tracked " + tracked().string() + " --mattes ";
  const fs::path out = out_ / "cli";
  const auto r = test::run_tega("dataset build" + inputs + mattes().string() + " --out " + out.string() +
                                " --set frames=2 --set test_camera_count=1");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_NE(r.output.find(": 1 train + 1 test frames, 12 train + 1 test cameras, 26 images"), std::string::npos)
      << r.output;
  validate_dataset(read_dataset(out));

  const fs::path damaged = mattes_copy();
  const fs::path missing = damaged / "speech" / "cam00" / "000001.png";
  fs::remove(missing);
  const auto bad = test::run_tega("dataset build" + inputs + damaged.string() + " --out " + (out_ / "bad").string());
  EXPECT_EQ(bad.exit_code, 1) << bad.output;
  EXPECT_NE(bad.output.find(missing.string() + ": is missing"), std::string::npos) << bad.output;

  const auto printed = test::run_tega("dataset build --print-options --set frames=7");
  EXPECT_EQ(printed.exit_code, 0) << printed.output;
  EXPECT_NE(printed.output.find("dataset:\n"), std::string::npos) << printed.output;
  EXPECT_NE(printed.output.find("  frames: 7"), std::string::npos) << printed.output;
}

}  // namespace
}  // namespace tega::matting
