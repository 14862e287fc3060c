// The expression encoder's input on ICT-FaceKit's head: the UV displacement
// texture must show what the face does. The head's eyeball spheres share the
// face's UV tile; drawn into the texture after the face, they hid nearly every
// face texel and left the networks blind to the expression.

#include <ATen/ATen.h>
#include <gtest/gtest.h>

#include <algorithm>

#include "small_studio.h"
#include "tega/core/dataset.h"
#include "tega/synth/virtual_studio.h"
#include "tega/trainer/avatar_model.h"
#include "test_support.h"

namespace {

// The largest head-space displacement from the template of a vertex that the
// texture draws: on a non-eyeball triangle, at a uv inside the texture.
double largest_drawn_displacement(const tega::Dataset& dataset, const tega::Vertices& world,
                                  const tega::RigidTransform& head_to_world) {
  const tega::Mesh& mesh = dataset.template_mesh;
  std::vector<bool> eyeball(mesh.num_faces(), false);
  for (const int32_t f : dataset.eyeball_faces) eyeball[f] = true;
  double largest = 0;
  for (int f = 0; f < mesh.num_faces(); ++f) {
    if (eyeball[f]) continue;
    for (int k = 0; k < 3; ++k) {
      const Eigen::Vector2f uv = mesh.uvs.row(mesh.uv_faces(f, k));
      if (uv.x() < 0 || uv.x() > 1 || uv.y() < 0 || uv.y() > 1) continue;
      const int v = mesh.faces(f, k);
      const Eigen::Vector3d head =
          head_to_world.R.transpose() * (world.row(v).cast<double>().transpose() - head_to_world.t);
      largest = std::max(largest, (head - mesh.positions.row(v).cast<double>().transpose()).norm());
    }
  }
  return largest;
}

TEST(DisplacementTexture, ShowsTheFacesExpressionOnIctFaceKit) {
  const auto ict = tega::test::ict_facekit_dir();
  if (!ict) GTEST_SKIP() << "ICT-FaceKit is not in the shared data";
  tega::test::TempDir tmp;
  tega::synth::Options capture = tega::test::small_studio(1, 64, 48, 8);
  capture.head = ict->string();
  capture.supersampling = 1;
  capture.fine_subdivisions = 0;
  capture.write_fine_meshes = false;
  tega::synth::render_virtual_studio(capture, tmp / "capture");
  const tega::Dataset dataset = tega::read_dataset(tmp / "capture/dataset");
  ASSERT_FALSE(dataset.eyeball_faces.empty());

  tega::trainer::TrainOptions options;
  options.network.texture_size = 128;
  options.uv_lookup.resolution = 256;
  const tega::trainer::AvatarModel model(dataset, options, at::kCPU);
  // The frame whose face moves furthest: the texture's texels interpolate its
  // vertices, so its largest texel is close to its largest vertex.
  double largest = 0, shown = 0;
  for (const auto& frame : dataset.frames) {
    const tega::Vertices world = dataset.load_mesh(frame.id);
    const double moved = largest_drawn_displacement(dataset, world, frame.head_to_world);
    if (moved <= largest) continue;
    largest = moved;
    shown = model.frame_input(world, frame.head_to_world).displacement_texture.norm(2, 0).max().item<double>();
  }
  std::printf("largest displacement: %.2f mm at a vertex, %.2f mm in the texture\n", 1000 * largest, 1000 * shown);
  ASSERT_GT(largest, 0.005) << "the expressions take should move the face by millimetres";
  EXPECT_GT(shown, 0.7 * largest);
  EXPECT_LE(shown, largest * (1 + 1e-5));
}

}  // namespace
