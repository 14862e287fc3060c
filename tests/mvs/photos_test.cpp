// An ordinary calibrated photo set (one image per camera, a COLMAP text rig,
// no clean plate), and a COLMAP dense workspace meshed back: both against the
// virtual studio's ground truth.
#include <gtest/gtest.h>

#include "tega/core/error.h"
#include "tega/core/rig.h"
#include "tega/mvs/reconstruction.h"
#include "tega/scoring/studio_truth.h"
#include "tega/scoring/surface_scores.h"
#include "tega/synth/virtual_studio.h"
#include "small_studio.h"
#include "test_support.h"

namespace fs = std::filesystem;

namespace tega::mvs {
namespace {

Options quick_options() {
  Options o;
  o.device = "cpu";
  o.surface.threads = 1;  // OpenMP's spinning threads stall beside other tests
  o.patch_match.iterations = 3;
  o.patch_match.geometric_iterations = 1;
  return o;
}

double completeness_at_3mm(const Mesh& mesh, const scoring::StudioTruth& truth, double& median_accuracy) {
  scoring::EvaluationOptions eval;
  eval.tolerances_m = {0.003};
  const scoring::SurfaceScores s = scoring::evaluate_surface(mesh, truth.fine, truth.face_region, eval);
  median_accuracy = s.accuracy_median_m;
  return s.completeness[0];
}

TEST(MvsPhotos, AColmapRiggedPhotoSetAndItsWorkspaceMeshTheFace) {
  const tega::test::TempDir dir;
  synth::render_virtual_studio(tega::test::small_studio(7, 320, 240, 1), dir / "capture");
  const Rig rig = read_rig_json(dir / "capture" / "rig.json");
  write_colmap_text(rig, dir / "sparse");
  fs::create_directories(dir / "photos");
  for (const auto& name : rig.camera_names())
    fs::copy_file(dir / "capture" / "takes" / "expressions" / name / "000000.png", dir / "photos" / (name + ".png"));
  const scoring::StudioTruth truth = scoring::load_studio_truth(dir / "capture", "expressions", 0);

  const PhotoRequest request{dir / "photos", dir / "sparse", 1.0, dir / "photos.ply", dir / "workspace"};
  reconstruct_photos(request, quick_options());
  double accuracy = 0;
  const double completeness = completeness_at_3mm(read_mesh(dir / "photos.ply"), truth, accuracy);
  std::printf("photo set, 7 cameras at 320x240: accuracy median %.2f mm, completeness at 3 mm %.1f %%\n",
              1000 * accuracy, 100 * completeness);
  EXPECT_LT(accuracy, 0.002);
  EXPECT_GT(completeness, 0.75);  // no clean plate: the silhouettes are not masked

  // The workspace it wrote, as COLMAP would hand it over: fused and meshed again.
  mesh_workspace(dir / "workspace", dir / "workspace.ply", quick_options());
  double workspace_accuracy = 0;
  const double workspace_completeness =
      completeness_at_3mm(read_mesh(dir / "workspace.ply"), truth, workspace_accuracy);
  EXPECT_LT(workspace_accuracy, 0.002);
  EXPECT_GT(workspace_completeness, 0.75);

  // A camera of the rig without a photo is named.
  fs::remove(dir / "photos" / "cam03.png");
  try {
    reconstruct_photos(request, quick_options());
    ADD_FAILURE() << "a missing photo was not noticed";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("has no image of camera cam03"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace tega::mvs
