// tega matte on a 13-camera virtual-studio capture, scored against the
// studio's true alpha: with a tracked mesh a few millimetres off (what
// tracking gives), under an exposure drift, without the clean plate; reruns
// and bad input.
#include <gtest/gtest.h>

#include <cstdio>
#include <opencv2/imgproc.hpp>

#include "cli_support.h"
#include "small_studio.h"
#include "tega/core/error.h"
#include "tega/core/files.h"
#include "tega/core/image.h"
#include "tega/core/mesh.h"
#include "tega/core/take.h"
#include "tega/matting/matte.h"
#include "tega/scoring/matte_scores.h"
#include "tega/scoring/tracking_scores.h"
#include "tega/synth/virtual_studio.h"
#include "test_support.h"

namespace fs = std::filesystem;

namespace tega::matting {
namespace {

constexpr int kFrames = 2;

void print_scores(const char* label, const scoring::MatteScores& s) {
  std::printf("%s: %d images, mean |error| %.4f (worst %.4f), within 3 px of the edge %.4f (worst %.4f), IoU %.4f "
              "(worst %.4f)\n",
              label, s.images, s.mean_error, s.worst_mean_error, s.boundary_error, s.worst_boundary_error, s.iou,
              s.worst_iou);
}

// The true meshes moved 2 mm and grown 1 %: a tracked mesh's silhouette is
// that far from the subject's.
void displace_tracked_meshes(const fs::path& tracked) {
  for (const auto& entry : fs::directory_iterator(tracked / "expressions")) {
    if (entry.path().extension() != ".bin") continue;
    Vertices v = read_vertices_bin(entry.path());
    const Eigen::RowVector3f centre = v.colwise().mean();
    const Eigen::RowVector3f moved_centre = centre + Eigen::RowVector3f(0.002f, -0.001f, 0.001f);
    v = ((v.rowwise() - centre) * 1.01f).rowwise() + moved_centre;
    write_vertices_bin(v, entry.path());
  }
}

class Matte : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    dir_ = new test::TempDir();
    synth::render_virtual_studio(test::small_studio(13, 512, 384, kFrames), capture());
    scoring::write_studio_truth_as_tracked(capture(), tracked());
    displace_tracked_meshes(tracked());
  }
  static void TearDownTestSuite() { delete dir_; }
  static fs::path capture() { return dir_->path() / "capture"; }
  static fs::path tracked() { return dir_->path() / "tracked"; }
  static fs::path out(const std::string& name) { return dir_->path() / name; }

  static MatteOptions options() {
    MatteOptions o;
    o.threads = 2;
    return o;
  }

  static test::TempDir* dir_;
};
test::TempDir* Matte::dir_ = nullptr;

TEST_F(Matte, MeetsTheTargetsWithAMeshMillimetresOff) {
  const MatteSummary summary = matte_capture({capture(), tracked(), out("mattes"), {}, {}}, options());
  EXPECT_EQ(summary.images, 13 * kFrames);
  EXPECT_TRUE(summary.clean_plate);
  EXPECT_TRUE(fs::exists(out("mattes") / "expressions" / "mattes.json"));
  const scoring::MatteScores s = scoring::score_mattes(out("mattes"), capture(), "expressions");
  print_scores("clean plate and mesh", s);
  EXPECT_EQ(s.images, 13 * kFrames);
  EXPECT_LE(s.worst_mean_error, 0.02);
  EXPECT_LE(s.boundary_error, 0.1);
  EXPECT_GE(s.worst_iou, 0.98);

  // A rerun with the same options keeps every matte.
  const MatteSummary again = matte_capture({capture(), tracked(), out("mattes"), {}, {}}, options());
  EXPECT_EQ(again.images, 0);
  EXPECT_EQ(again.images_kept, 13 * kFrames);
}

TEST_F(Matte, ScoresNameTheWorstImage) {
  // The true alpha as mattes, but for one camera's frame 1, spoiled along its edge by a blur.
  const fs::path mattes = out("mattes_truth"), truth = capture() / "ground_truth" / "expressions" / "alpha";
  fs::create_directories(mattes / "expressions");
  fs::copy(truth, mattes / "expressions", fs::copy_options::recursive);
  const TakeInfo take = read_take(capture() / "takes" / "expressions");
  const std::string camera = take.cameras[5];
  const fs::path spoiled = mattes / "expressions" / camera / "000001.png";
  Image8 alpha = read_image_u8(spoiled);
  cv::Mat view(alpha.height, alpha.width, CV_8U, alpha.pixels.data());
  cv::GaussianBlur(view, view, cv::Size(9, 9), 3);
  write_image(alpha, spoiled);

  const scoring::MatteScores s = scoring::score_mattes(mattes, capture(), "expressions");
  EXPECT_GT(s.worst_boundary_error, 0.05);
  EXPECT_EQ(s.worst_boundary_image, camera + "/000001.png");
  EXPECT_EQ(s.worst_mean_image, camera + "/000001.png");
  EXPECT_EQ(s.worst_iou_image, camera + "/000001.png");
}

TEST_F(Matte, FollowsAnExposureDrift) {
  // The same capture with every performance photo 8 % brighter than the clean plate.
  const fs::path brighter = out("brighter");
  fs::copy(capture(), brighter, fs::copy_options::recursive);
  const TakeInfo take = read_take(brighter / "takes" / "expressions");
  for (const auto& camera : take.cameras) {
    for (int f = 0; f < kFrames; ++f) {
      Image8 photo = read_image_u8(take.image_path(camera, f));
      for (auto& p : photo.pixels) p = uint8_t(std::min(255.0, std::round(p * 1.08)));
      write_image(photo, take.image_path(camera, f));
    }
  }
  matte_capture({brighter, tracked(), out("mattes_brighter"), {}, {}}, options());
  const scoring::MatteScores s = scoring::score_mattes(out("mattes_brighter"), brighter, "expressions");
  print_scores("8 % brighter than the clean plate", s);
  EXPECT_LE(s.worst_mean_error, 0.02);
  EXPECT_LE(s.boundary_error, 0.1);
  EXPECT_GE(s.worst_iou, 0.98);
}

TEST_F(Matte, MattesWidePhotosAtAFractionOfTheirSize) {
  // As 6144-pixel photos are by default: here at half size, the alpha enlarged back.
  MatteOptions o = options();
  o.max_work_width = 256;
  matte_capture({capture(), tracked(), out("mattes_half"), {}, {}}, o);
  const scoring::MatteScores s = scoring::score_mattes(out("mattes_half"), capture(), "expressions");
  print_scores("matted at half size", s);
  EXPECT_LE(s.worst_mean_error, 0.02);
  EXPECT_LE(s.boundary_error, 0.15);
  EXPECT_GE(s.worst_iou, 0.97);
}

// The studio's cameras are 3072 x 2048: matted at half size (the default max_work_width, 2048) the
// worst image's edge misses the target (0.14 on the H200's chain and here), at full size, as
// studio13-capture.yaml and studio-bench set it, it meets it.
TEST(MatteAtTheStudiosSize, MeetsTheTargetsMattedAtFullSize) {
  test::TempDir dir;
  const fs::path capture = dir / "capture", tracked = dir / "tracked";
  synth::render_virtual_studio(test::small_studio(13, 3072, 2048, 1), capture);
  scoring::write_studio_truth_as_tracked(capture, tracked);
  displace_tracked_meshes(tracked);
  MatteOptions o;
  o.threads = 2;
  o.max_work_width = 3072;
  matte_capture({capture, tracked, dir / "full", {}, {}}, o);
  const scoring::MatteScores full = scoring::score_mattes(dir / "full", capture, "expressions");
  print_scores("3072 x 2048 at full size", full);
  EXPECT_LE(full.worst_mean_error, 0.02);
  EXPECT_LE(full.worst_boundary_error, 0.1);
  EXPECT_GE(full.worst_iou, 0.98);

  o.max_work_width = MatteOptions().max_work_width;
  matte_capture({capture, tracked, dir / "half", {}, {}}, o);
  const scoring::MatteScores half = scoring::score_mattes(dir / "half", capture, "expressions");
  print_scores("3072 x 2048 at half size", half);
  EXPECT_GT(half.worst_boundary_error, full.worst_boundary_error);
}

// A bust cut two pixels above the photo's bottom (as the frontal camera sees
// the virtual studio's at 3072 x 2048): the 3 x 3 difference and the closing
// carry the subject onto those rows, which show the backdrop; unmixed against
// the plate, they are background again.
TEST(MatteAtThePhotosBorder, AnEdgeJustInsideTheFrameIsUnmixed) {
  const int width = 160, height = 96, bottom = height - 2;  // the bust covers rows [30, bottom)
  Image8 plate(width, height, 3, 0);
  for (int y = 0; y < height; ++y)
    for (int x = 0; x < width; ++x)
      for (int c = 0; c < 3; ++c) plate.at(x, y, c) = uint8_t(60 + 10 * c + (x * 7 + y * 3) % 5);
  Image8 photo = plate, silhouette(width, height, 1, 0);
  const cv::Rect bust(40, 30, 80, bottom - 30);
  for (int y = bust.y; y < bust.y + bust.height; ++y) {
    for (int x = bust.x; x < bust.x + bust.width; ++x) {
      const uint8_t skin[3] = {230, 175, 145};
      for (int c = 0; c < 3; ++c) photo.at(x, y, c) = skin[c];
      silhouette.at(x, y, 0) = 255;
    }
  }
  const Image8 alpha = compute_matte(photo, &plate, silhouette, 4, MatteOptions());
  for (int x = bust.x + 4; x < bust.x + bust.width - 4; ++x) {
    EXPECT_GE(alpha.at(x, bottom - 1, 0), 250) << "x " << x;
    EXPECT_LE(alpha.at(x, bottom, 0), 10) << "x " << x;
    EXPECT_LE(alpha.at(x, height - 1, 0), 10) << "x " << x;
  }
}

TEST_F(Matte, FallsBackOnTheMeshWithoutACleanPlate) {
  MatteOptions o = options();
  o.use_clean_plate = false;
  const MatteSummary summary = matte_capture({capture(), tracked(), out("mattes_mesh_only"), {}, {}}, o);
  EXPECT_FALSE(summary.clean_plate);
  const scoring::MatteScores s = scoring::score_mattes(out("mattes_mesh_only"), capture(), "expressions");
  print_scores("mesh alone", s);
  // The mesh is 2 mm off: the silhouette is right to a few pixels.
  EXPECT_LE(s.worst_mean_error, 0.05);
  EXPECT_GE(s.worst_iou, 0.9);
}

TEST_F(Matte, NamesTheFileOfBadInput) {
  const fs::path broken = out("tracked_broken");
  fs::copy(tracked(), broken, fs::copy_options::recursive);
  fs::remove(broken / "expressions" / "000001.json");
  try {
    matte_capture({capture(), broken, out("mattes_broken"), {}, {}}, options());
    FAIL() << "a frame without a tracking record must be refused";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("000001.json"), std::string::npos) << e.what();
  }
  EXPECT_FALSE(fs::exists(out("mattes_broken") / "expressions" / "mattes.json"));

  // A photo of the wrong size.
  const fs::path small = out("small_photo");
  fs::copy(capture(), small, fs::copy_options::recursive);
  const TakeInfo take = read_take(small / "takes" / "expressions");
  write_image(Image8(100, 80, 3, 0), take.image_path(take.cameras[3], 1));
  try {
    matte_capture({small, tracked(), out("mattes_small"), {}, {}}, options());
    FAIL() << "a photo of the wrong size must be refused";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find(take.cameras[3]), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("100x80"), std::string::npos) << e.what();
  }
}

TEST_F(Matte, RunsFromTheCommandLine) {
  const std::string inputs = " --capture " + capture().string() + " --tracked " + tracked().string();
  const auto r = test::run_tega("matte" + inputs + " --out " + out("mattes_cli").string() + " --threads 2 --set edge.band_px=2");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_NE(r.output.find(std::to_string(13 * kFrames) + " image(s) matted"), std::string::npos) << r.output;
  const Image8 alpha = read_image_u8(out("mattes_cli") / "expressions" / "cam00" / "000001.png");
  EXPECT_EQ(alpha.channels, 1);
  EXPECT_EQ(alpha.width, 512);

  const auto missing = test::run_tega("matte --tracked " + tracked().string() + " --out " + out("x").string());
  EXPECT_NE(missing.exit_code, 0);
  EXPECT_NE(missing.output.find("--capture"), std::string::npos) << missing.output;
  const auto unknown = test::run_tega("matte --print-options --set edge.width=3");
  EXPECT_NE(unknown.exit_code, 0);
  EXPECT_NE(unknown.output.find("edge.width"), std::string::npos) << unknown.output;
  const auto printed = test::run_tega("matte --print-options --set edge.band_px=5");
  ASSERT_EQ(printed.exit_code, 0) << printed.output;
  EXPECT_NE(printed.output.find("band_px: 5"), std::string::npos) << printed.output;
}

}  // namespace
}  // namespace tega::matting
