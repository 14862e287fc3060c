// The studio's ICT-FaceKit head carries the model's 68 landmark vertices in
// its own numbering (it leaves the see-through eye overlays out), and the
// dataset hands them on for tega eval's landmark error and close-ups.

#include <gtest/gtest.h>

#include <fstream>
#include <nlohmann/json.hpp>

#include "tega/core/blendshape.h"
#include "tega/synth/head.h"
#include "test_support.h"

namespace tega::synth {
namespace {

TEST(HeadLandmarks, AreTheModelsLandmarkVerticesRenumbered) {
  TEGA_REQUIRE_ICT_FACEKIT(ict);
  const Head head = load_head(ict, 0.01, {});
  const BlendshapeModel model = BlendshapeModel::load_directory(ict, 0.01);
  std::ifstream in(ict / "vertex_indices.json");
  const auto indices = nlohmann::json::parse(in).at("idx_to_landmark_verts").get<std::vector<int>>();
  ASSERT_EQ(head.landmark_vertices.size(), 68u);
  ASSERT_EQ(indices.size(), 68u);
  EXPECT_LT(head.model.num_vertices(), model.num_vertices());  // the renumbering is not the identity
  for (size_t i = 0; i < indices.size(); ++i) {
    EXPECT_EQ(head.model.neutral.positions.row(head.landmark_vertices[i]),
              model.neutral.positions.row(indices[i]))
        << "landmark " << i;
  }
}

TEST(HeadLandmarks, TheProceduralHeadHasNone) { EXPECT_TRUE(make_procedural_head().landmark_vertices.empty()); }

}  // namespace
}  // namespace tega::synth
