#include <gtest/gtest.h>

#include "tega/synth/fine_mesh.h"

namespace tega::synth {
namespace {

// Forehead vertices of the fine mesh (neutral face-frame position).
std::vector<int> forehead_vertices(const Head& head, const Mesh& fine) {
  std::vector<int> out;
  for (int v = 0; v < fine.num_vertices(); ++v) {
    const Eigen::Vector3d f = head.frame.to_face(fine.positions.row(v).cast<double>().transpose());
    if (std::abs(f.x()) < 0.4 && f.y() > 0.6 && f.y() < 1.0 && f.z() > 0) out.push_back(v);
  }
  return out;
}

std::vector<float> brows_raised(const BlendshapeModel& model, float amount) {
  std::vector<float> e(model.expression_names.size(), 0.0f);
  for (const char* name : {"browInnerUp_L", "browInnerUp_R", "browOuterUp_L", "browOuterUp_R"})
    e[model.expression_index(name)] = amount;
  return e;
}

TEST(FineMesh, SubdivisionKeepsSeamsAndQuadruplesTriangles) {
  const Head head = make_procedural_head();
  const Subdivision s = subdivide(head.model.neutral, 2);
  EXPECT_EQ(s.fine.num_faces(), 16 * head.model.neutral.num_faces());
  EXPECT_NO_THROW(s.fine.validate("fine"));
  EXPECT_GT(s.fine.uvs.rows(), s.fine.num_vertices());  // the seam survives
  for (size_t v = 0; v < s.weight.size(); ++v)
    EXPECT_NEAR(s.weight[v][0] + s.weight[v][1] + s.weight[v][2], 1.0f, 1e-6f);
}

// The fine mesh's offset from the coarse one on the forehead grows with the
// brow raise: the wrinkles are in the fine mesh only.
TEST(FineMesh, ForeheadWrinklesDeepenWithTheBrowRaiseAndShadeTheCreases) {
  const Head head = make_procedural_head();
  const FineMeshMaker maker(head, WrinkleSettings{});
  const Mesh& fine = maker.fine_topology();
  const std::vector<int> forehead = forehead_vertices(head, fine);
  ASSERT_GT(forehead.size(), 100u);

  // Reference: the same coarse mesh without any wrinkle displacement.
  const FineMeshMaker smooth_maker(head, WrinkleSettings{2, 0.0, 0.0});
  double previous_offset = -1, previous_darkest = 2;
  for (float amount : {0.0f, 0.5f, 1.0f}) {
    const std::vector<float> e = brows_raised(head.model, amount);
    const Vertices coarse = head.model.evaluate({}, e);
    const FineFrame wrinkled = maker.make(coarse, e), smooth = smooth_maker.make(coarse, e);
    double offset = 0, darkest = 1;
    for (int v : forehead) {
      offset = std::max<double>(offset, (wrinkled.positions.row(v) - smooth.positions.row(v)).norm());
      darkest = std::min<double>(darkest, wrinkled.shading[v]);
    }
    EXPECT_GT(offset, previous_offset + (amount > 0 ? 2e-4 : -1.0)) << "brows at " << amount;
    EXPECT_LT(darkest, previous_darkest - (amount > 0 ? 0.1 : -1.0)) << "brows at " << amount;
    if (amount == 0) {
      EXPECT_EQ(offset, 0.0);
      EXPECT_EQ(darkest, 1.0);
    }
    previous_offset = offset;
    previous_darkest = darkest;
  }
  EXPECT_NEAR(previous_offset, WrinkleSettings{}.depth_m, 0.3 * WrinkleSettings{}.depth_m);
}

TEST(FineMesh, WrinklesStayOffTheEyeballsAndTheBackOfTheHead) {
  const Head head = make_procedural_head();
  const FineMeshMaker maker(head, WrinkleSettings{});
  std::vector<float> e(head.model.expression_names.size(), 1.0f);
  const Vertices coarse = head.model.evaluate({}, e);
  const FineFrame f = maker.make(coarse, e);
  const FineMeshMaker smooth_maker(head, WrinkleSettings{2, 0.0, 0.0});
  const FineFrame s = smooth_maker.make(coarse, e);
  const Mesh& fine = maker.fine_topology();
  for (int t = 0; t < fine.num_faces(); ++t) {
    if (maker.fine_triangle_eye()[t] == 0) continue;
    for (int k = 0; k < 3; ++k) EXPECT_EQ((f.positions.row(fine.faces(t, k)) - s.positions.row(fine.faces(t, k))).norm(), 0.0f);
  }
  for (int v = 0; v < fine.num_vertices(); ++v)
    if (fine.positions(v, 2) < 0) EXPECT_EQ((f.positions.row(v) - s.positions.row(v)).norm(), 0.0f);
}

}  // namespace
}  // namespace tega::synth
