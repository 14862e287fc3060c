#include <gtest/gtest.h>

#include "tega/synth/head.h"

namespace tega::synth {
namespace {

// Signed volume of the triangles: positive when they are wound
// counter-clockwise seen from outside (outward normals).
double signed_volume(const Mesh& m, bool eyeballs, const std::vector<int8_t>& triangle_eye) {
  double v = 0;
  for (int f = 0; f < m.num_faces(); ++f) {
    if ((triangle_eye[f] != 0) != eyeballs) continue;
    const Eigen::Vector3d a = m.positions.row(m.faces(f, 0)).cast<double>();
    const Eigen::Vector3d b = m.positions.row(m.faces(f, 1)).cast<double>();
    const Eigen::Vector3d c = m.positions.row(m.faces(f, 2)).cast<double>();
    v += a.dot(b.cross(c)) / 6.0;
  }
  return v;
}

TEST(ProceduralHead, IsACoarseTemplateWithUvSeamAndEyeballs) {
  const Head head = make_procedural_head();
  const Mesh& m = head.model.neutral;
  EXPECT_NO_THROW(m.validate("procedural head"));
  EXPECT_GT(m.num_vertices(), 2000);
  EXPECT_LT(m.num_vertices(), 10000);
  // A seam: some positions carry more than one UV.
  EXPECT_GT(m.uvs.rows(), m.num_vertices());
  ASSERT_FALSE(head.eyeball_faces.empty());
  // Skin and each eyeball are closed and wound outwards; a head is some litres.
  const double skin_litres = signed_volume(m, false, head.triangle_eye) * 1000;
  EXPECT_GT(skin_litres, 2.0);
  EXPECT_LT(skin_litres, 8.0);
  const double eyeball_ml = signed_volume(m, true, head.triangle_eye) * 1e6;
  EXPECT_GT(eyeball_ml, 2 * 5.0);  // a 12.5 mm sphere holds 8.2 ml
  EXPECT_LT(eyeball_ml, 2 * 8.5);
}

TEST(ProceduralHead, FaceFrameSitsBetweenTheEyesWithSubjectsLeftAtPlusX) {
  const Head head = make_procedural_head();
  EXPECT_NEAR(head.frame.interocular, 0.064, 0.002);
  EXPECT_GT(head.frame.eye_left.x(), head.frame.eye_right.x());
  EXPECT_NEAR(head.frame.axes.col(2).z(), 1.0, 1e-9);  // looking along +z
}

TEST(ProceduralHead, HasArkitNamedExpressionsActingWhereTheyShould) {
  const Head head = make_procedural_head();
  const BlendshapeModel& model = head.model;
  for (const char* name : {"eyeBlink_L", "eyeBlink_R", "jawOpen", "browInnerUp_L", "browInnerUp_R", "browOuterUp_L",
                           "browOuterUp_R", "mouthSmile_L", "mouthSmile_R"})
    ASSERT_GE(model.expression_index(name), 0) << name;

  // Each shape moves vertices on its own side / region, and leaves the eyeballs alone.
  const auto largest_motion_at = [&](const std::string& name) {
    const Vertices& d = model.expression_deltas[model.expression_index(name)];
    int best = 0;
    for (int v = 0; v < d.rows(); ++v)
      if (d.row(v).norm() > d.row(best).norm()) best = v;
    return std::pair{Eigen::Vector3f(model.neutral.positions.row(best)), d.row(best).norm()};
  };
  const auto [blink_at, blink] = largest_motion_at("eyeBlink_L");
  EXPECT_GT(blink_at.x(), 0.015f);
  EXPECT_GT(blink, 0.003f);
  const auto [jaw_at, jaw] = largest_motion_at("jawOpen");
  EXPECT_LT(jaw_at.y(), -0.05f);
  EXPECT_GT(jaw, 0.01f);
  const auto [brow_at, brow] = largest_motion_at("browOuterUp_R");
  EXPECT_LT(brow_at.x(), -0.02f);
  EXPECT_GT(brow_at.y(), 0.03f);
  for (const auto& d : model.expression_deltas)
    for (int f : head.eyeball_faces)
      for (int k = 0; k < 3; ++k) EXPECT_EQ(d.row(model.neutral.faces(f, k)).norm(), 0.0f);
}

}  // namespace
}  // namespace tega::synth
