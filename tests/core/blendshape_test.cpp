#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <functional>

#include "tega/core/blendshape.h"
#include "tega/core/error.h"
#include "test_support.h"

namespace tega {
namespace {

// A tetrahedron about 10 cm across, in centimetres, as ICT-FaceKit stores its shapes.
std::string tetrahedron_obj(const Vertices& positions) {
  std::string text;
  for (Eigen::Index v = 0; v < positions.rows(); ++v) {
    text += "v " + std::to_string(positions(v, 0)) + " " + std::to_string(positions(v, 1)) + " " +
            std::to_string(positions(v, 2)) + "\n";
  }
  return text + "vt 0 0\nvt 1 0\nvt 0 1\nf 1/1 2/2 3/3\nf 1/1 2/2 4/3\nf 1/1 3/2 4/3\nf 2/1 3/2 4/3\n";
}

Vertices tetrahedron() {
  Vertices v(4, 3);
  v << 0, 0, 0, 10, 0, 0, 0, 10, 0, 0, 0, 10;
  return v;
}

Vertices moved(int vertex, Eigen::RowVector3f offset) {
  Vertices v = tetrahedron();
  v.row(vertex) += offset;
  return v;
}

// A model directory: neutral, two identities, two expressions, and files that are no shapes.
void write_synthetic_model(const std::filesystem::path& dir) {
  test::write_text(dir / "generic_neutral_mesh.obj", tetrahedron_obj(tetrahedron()));
  test::write_text(dir / "identity001.obj", tetrahedron_obj(moved(1, {1, 0, 0})));
  test::write_text(dir / "identity000.obj", tetrahedron_obj(moved(0, {0, -2, 0})));
  test::write_text(dir / "smile.obj", tetrahedron_obj(moved(2, {0, 0, 3})));
  test::write_text(dir / "blink.obj", tetrahedron_obj(moved(3, {4, 0, 0})));
  test::write_text(dir / "coefficients.json", "{}");
  test::write_text(dir / "model.mtl", "newmtl skin\n");
}

using test::error_message;

void expect_near(const Vertices& actual, const Vertices& expected, float tolerance) {
  ASSERT_EQ(actual.rows(), expected.rows());
  EXPECT_LE((actual - expected).cwiseAbs().maxCoeff(), tolerance);
}

TEST(BlendshapeSynthetic, LoadsNamesDeltasInMetres) {
  test::TempDir dir;
  write_synthetic_model(dir.path());
  const BlendshapeModel model = BlendshapeModel::load_directory(dir.path(), 0.01);
  EXPECT_EQ(model.identity_names, (std::vector<std::string>{"identity000", "identity001"}));
  EXPECT_EQ(model.expression_names, (std::vector<std::string>{"blink", "smile"}));
  EXPECT_EQ(model.expression_index("smile"), 1);
  EXPECT_EQ(model.expression_index("frown"), -1);
  EXPECT_EQ(model.neutral.num_faces(), 4);
  EXPECT_TRUE(model.neutral.has_uvs());
  expect_near(model.neutral.positions, tetrahedron() * 0.01f, 1e-7f);

  Vertices smile_delta = Vertices::Zero(4, 3);
  smile_delta(2, 2) = 0.03f;
  expect_near(model.expression_deltas[1], smile_delta, 1e-7f);
  Vertices identity_delta = Vertices::Zero(4, 3);
  identity_delta(0, 1) = -0.02f;
  expect_near(model.identity_deltas[0], identity_delta, 1e-7f);
}

TEST(BlendshapeSynthetic, EvaluatesLinearCombinationsAndPose) {
  test::TempDir dir;
  write_synthetic_model(dir.path());
  const BlendshapeModel model = BlendshapeModel::load_directory(dir.path(), 0.01);

  // Missing coefficients are zero.
  expect_near(model.evaluate({}, {}), model.neutral.positions, 0);
  Vertices expected = tetrahedron() * 0.01f;
  expected(0, 1) += 0.5f * -0.02f;   // identity000
  expected(1, 0) += -1.0f * 0.01f;   // identity001
  expected(2, 2) += 2.0f * 0.03f;    // smile
  const Vertices shaped = model.evaluate({0.5f, -1.0f}, {0.0f, 2.0f});
  expect_near(shaped, expected, 1e-7f);

  RigidTransform pose;
  pose.R = Eigen::AngleAxisd(0.7, Eigen::Vector3d(1, 2, 3).normalized()).toRotationMatrix();
  pose.t = {0.1, -0.2, 1.5};
  const Vertices posed = model.evaluate({0.5f, -1.0f}, {0.0f, 2.0f}, pose);
  for (int v = 0; v < 4; ++v) {
    const Eigen::Vector3d world = pose.apply(shaped.row(v).transpose().cast<double>());
    EXPECT_LT((posed.row(v).transpose().cast<double>() - world).norm(), 1e-6) << v;
  }

  EXPECT_THROW(model.evaluate({0, 0, 1}, {}), Error);
  EXPECT_THROW(model.evaluate({}, {0, 0, 1}), Error);
}

TEST(BlendshapeSynthetic, ShapeWithOtherTopologyIsNamed) {
  test::TempDir dir;
  write_synthetic_model(dir.path());
  Vertices five(5, 3);
  five << tetrahedron(), Eigen::RowVector3f(5, 5, 5);
  test::write_text(dir / "jawOpen.obj", tetrahedron_obj(five));
  std::string message = error_message([&] { BlendshapeModel::load_directory(dir.path(), 0.01); });
  EXPECT_NE(message.find((dir / "jawOpen.obj").string() + ": has 5 vertices"), std::string::npos) << message;

  test::write_text(dir / "jawOpen.obj", "v 0 0 0\nv 10 0 0\nv 0 10 0\nv 0 0 10\nf 1 2 3\n");
  message = error_message([&] { BlendshapeModel::load_directory(dir.path(), 0.01); });
  EXPECT_NE(message.find("jawOpen.obj: has other faces"), std::string::npos) << message;
}

TEST(BlendshapeSynthetic, WrongUnitsAndMissingNeutralAreRefused) {
  test::TempDir dir;
  write_synthetic_model(dir.path());
  // Centimetres read as metres make a 10 m head.
  const std::string message = error_message([&] { BlendshapeModel::load_directory(dir.path(), 1.0); });
  EXPECT_NE(message.find("generic_neutral_mesh.obj: spans 10 m"), std::string::npos) << message;

  std::filesystem::remove(dir / "generic_neutral_mesh.obj");
  EXPECT_NE(error_message([&] { BlendshapeModel::load_directory(dir.path(), 0.01); })
                .find("generic_neutral_mesh.obj: does not exist"),
            std::string::npos);
}

class BlendshapeIct : public ::testing::Test {
 protected:
  // Loading parses 68 meshes of 2.5 MB: once for the suite.
  static void SetUpTestSuite() {
    if (const auto dir = test::ict_facekit_dir()) {
      model_ = new BlendshapeModel(BlendshapeModel::load_directory(*dir, 0.01));
    }
  }
  static void TearDownTestSuite() {
    delete model_;
    model_ = nullptr;
  }
  static const BlendshapeModel* model_;
};

const BlendshapeModel* BlendshapeIct::model_ = nullptr;

TEST_F(BlendshapeIct, LoadsAllShapesInMetres) {
  TEGA_REQUIRE_ICT_FACEKIT(ict);
  ASSERT_NE(model_, nullptr);
  EXPECT_EQ(model_->num_vertices(), 26719);
  EXPECT_EQ(model_->neutral.uvs.rows(), 28911);
  ASSERT_EQ(model_->identity_names.size(), 10u);
  EXPECT_EQ(model_->identity_names.front(), "identity000");
  EXPECT_EQ(model_->identity_names.back(), "identity009");
  // Every other *.obj on disk: 53 ARKit-style shapes, cheekRaiser_L/R and
  // PupilDilate_L/R (data/README.md counts only the first and the last).
  EXPECT_EQ(model_->expression_names.size(), 57u);
  EXPECT_GE(model_->expression_index("PupilDilate_L"), 0);
  EXPECT_GE(model_->expression_index("cheekRaiser_R"), 0);
  EXPECT_EQ(model_->expression_deltas.size(), 57u);
  // A head in metres is a few tens of centimetres across.
  const Vertices& n = model_->neutral.positions;
  const float height = n.col(1).maxCoeff() - n.col(1).minCoeff();
  EXPECT_GT(height, 0.2f);
  EXPECT_LT(height, 0.5f);
}

TEST_F(BlendshapeIct, UnitJawOpenGivesTheJawOpenMesh) {
  TEGA_REQUIRE_ICT_FACEKIT(ict);
  ASSERT_NE(model_, nullptr);
  const int jaw = model_->expression_index("jawOpen");
  ASSERT_GE(jaw, 0);
  std::vector<float> expression(jaw + 1, 0.0f);
  expression[jaw] = 1.0f;
  const Vertices open = model_->evaluate({}, expression);
  const Vertices expected = read_obj(ict / "jawOpen.obj").positions * 0.01f;
  expect_near(open, expected, 1e-6f);
  // The jaw does move: several centimetres at the chin.
  EXPECT_GT((open - model_->neutral.positions).rowwise().norm().maxCoeff(), 0.01f);
}

TEST_F(BlendshapeIct, IsLinearAndPosesRigidly) {
  TEGA_REQUIRE_ICT_FACEKIT(ict);
  ASSERT_NE(model_, nullptr);
  const std::vector<float> identity = {0.8f, -0.5f, 0.0f, 1.2f};
  std::vector<float> expression(model_->expression_names.size(), 0.0f);
  expression[model_->expression_index("jawOpen")] = 0.3f;
  expression[model_->expression_index("mouthSmile_L")] = 0.9f;
  const Vertices& n = model_->neutral.positions;

  const Vertices both = model_->evaluate(identity, expression);
  const Vertices identity_only = model_->evaluate(identity, {});
  const Vertices expression_only = model_->evaluate({}, expression);
  expect_near(both - n, (identity_only - n) + (expression_only - n), 1e-6f);

  std::vector<float> doubled = expression;
  for (float& b : doubled) b *= 2;
  expect_near(model_->evaluate({}, doubled) - n, 2 * (expression_only - n), 1e-6f);

  RigidTransform pose;
  pose.R = Eigen::AngleAxisd(-0.4, Eigen::Vector3d(0.2, 1, 0).normalized()).toRotationMatrix();
  pose.t = {0.05, 1.6, -0.3};
  const Vertices posed = model_->evaluate(identity, expression, pose);
  Eigen::MatrixXd expected = (both.cast<double>() * pose.R.transpose()).rowwise() + pose.t.transpose();
  EXPECT_LT((posed.cast<double>() - expected).cwiseAbs().maxCoeff(), 1e-6);
  // Rigid: distances between vertices are unchanged.
  EXPECT_NEAR((posed.row(0) - posed.row(20000)).norm(), (both.row(0) - both.row(20000)).norm(), 1e-6f);
}

}  // namespace
}  // namespace tega
