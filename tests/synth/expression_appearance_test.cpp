// Expression-dependent appearance (Options::self_shadowing,
// Options::expression_specular): the head's shadows on itself follow its
// creases, its open mouth and the light; the skin's gloss follows its
// stretch, its creases and the mouth; both off, every image is unchanged.

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <functional>
#include <iostream>
#include <sstream>

#include "tega/core/image.h"
#include "tega/core/options.h"
#include "tega/synth/fine_mesh.h"
#include "tega/synth/head.h"
#include "tega/synth/shadow_map.h"
#include "tega/synth/skin_gloss.h"
#include "tega/synth/virtual_studio.h"
#include "test_support.h"

namespace tega::synth {
namespace {

namespace fs = std::filesystem;

// Appends an n x n grid of quads spanning [-half, half]^2 at height z,
// wound counter-clockwise seen from +z (it faces up).
void add_square(Vertices& positions, Triangles& faces, double half, double z, int n) {
  const int first = static_cast<int>(positions.rows());
  positions.conservativeResize(first + (n + 1) * (n + 1), 3);
  for (int j = 0; j <= n; ++j)
    for (int i = 0; i <= n; ++i)
      positions.row(first + j * (n + 1) + i) =
          Eigen::RowVector3f(float(-half + 2 * half * i / n), float(-half + 2 * half * j / n), float(z));
  const int f0 = static_cast<int>(faces.rows());
  faces.conservativeResize(f0 + 2 * n * n, 3);
  int f = f0;
  for (int j = 0; j < n; ++j) {
    for (int i = 0; i < n; ++i) {
      const int a = first + j * (n + 1) + i, b = a + 1, c = a + n + 1, d = c + 1;
      faces.row(f++) = Eigen::RowVector3i(a, b, d);
      faces.row(f++) = Eigen::RowVector3i(a, d, c);
    }
  }
}

// A 20 cm floor with a 2 cm square hovering 2 cm above its centre.
struct FloorAndSquare {
  Vertices positions;
  Triangles faces;
  FloorAndSquare() {
    add_square(positions, faces, 0.1, 0.0, 40);
    add_square(positions, faces, 0.01, 0.02, 4);
  }
};

const Eigen::Vector3f kUp(0, 0, 1);

TEST(ShadowMap, AnOccluderShadowsWhereTheLightCastsItAndTheShadowMovesWithTheLight) {
  const FloorAndSquare scene;
  // Light from +x at 63 degrees elevation: the square's shadow spans x in [-0.02, 0].
  const ShadowMap from_right(scene.positions, scene.faces, Eigen::Vector3f(0.5f, 0, 1).normalized(), 512, 0.0005);
  const ShadowMap from_left(scene.positions, scene.faces, Eigen::Vector3f(-0.5f, 0, 1).normalized(), 512, 0.0005);
  EXPECT_LT(from_right.texel_m(), 0.0006);
  EXPECT_EQ(from_right.visibility({-0.01f, 0, 0}, kUp), 0.0f);
  EXPECT_EQ(from_right.visibility({0.008f, 0, 0}, kUp), 1.0f);
  EXPECT_EQ(from_left.visibility({0.01f, 0, 0}, kUp), 0.0f);
  EXPECT_EQ(from_left.visibility({-0.008f, 0, 0}, kUp), 1.0f);
  // The square's own top is lit.
  EXPECT_EQ(from_right.visibility({0, 0, 0.02f}, kUp), 1.0f);
  // A soft edge: about half the light at the shadow's border, all of it a softness further out.
  EXPECT_NEAR(from_right.visibility({0.0f, 0.0f, 0}, kUp), 0.5f, 0.2f);
  EXPECT_EQ(from_right.visibility({0.0011f, 0.0f, 0}, kUp), 1.0f);
}

TEST(ShadowMap, OpenSurfacesDoNotShadowThemselvesAtAnyLightAngle) {
  const FloorAndSquare scene;
  for (float elevation_deg : {80.0f, 45.0f, 20.0f, 8.0f}) {
    const float e = elevation_deg * float(M_PI) / 180;
    const Eigen::Vector3f towards_light = Eigen::Vector3f(std::cos(e), 0.3f * std::cos(e), std::sin(e)).normalized();
    const ShadowMap map(scene.positions, scene.faces, towards_light, 512, 0.001);
    float darkest = 1;
    // Points of the floor on the lit side of the square (x > 0.02) and on the far side beyond its shadow.
    for (float x = 0.02f; x < 0.095f; x += 0.0013f)
      for (float y = -0.09f; y < 0.09f; y += 0.0017f) darkest = std::min(darkest, map.visibility({x, y, 0}, kUp));
    EXPECT_EQ(darkest, 1.0f) << "light at " << elevation_deg << " degrees";
  }
}

// Fine vertices of the neutral face in a box of the face frame (interocular units).
std::vector<int> face_box(const Head& head, const Mesh& fine, double x0, double x1, double y0, double y1) {
  std::vector<int> out;
  for (int v = 0; v < fine.num_vertices(); ++v) {
    const Eigen::Vector3d f = head.frame.to_face(fine.positions.row(v).cast<double>().transpose());
    if (f.x() > x0 && f.x() < x1 && f.y() > y0 && f.y() < y1 && f.z() > 0) out.push_back(v);
  }
  return out;
}

std::vector<float> expression_of(const BlendshapeModel& model, const std::vector<std::pair<const char*, float>>& set) {
  std::vector<float> e(model.expression_names.size(), 0.0f);
  for (const auto& [name, value] : set) {
    const int i = model.expression_index(name);
    if (i >= 0) e[i] = value;
  }
  return e;
}

struct Visibilities {
  double mean = 0, darkest = 1;
  int count = 0;
};

// Visibility of the listed fine vertices, from `towards_light`, with their own normals.
Visibilities visibilities(const FineFrame& frame, const Triangles& faces, const std::vector<int>& vertices,
                          const Eigen::Vector3f& towards_light, const std::function<bool(int)>& keep) {
  const ShadowMap map(frame.positions, faces, towards_light, 1024, 0.0005);
  Visibilities out;
  for (int v : vertices) {
    const Eigen::Vector3f n = frame.normals.row(v).transpose();
    if (!keep(v) || n.dot(towards_light) <= 0.05f) continue;
    const float visible = map.visibility(frame.positions.row(v).transpose(), n);
    out.mean += visible;
    out.darkest = std::min<double>(out.darkest, visible);
    ++out.count;
  }
  if (out.count) out.mean /= out.count;
  return out;
}

// A light from above, `elevation_deg` over the mean tangent plane of `vertices`.
Eigen::Vector3f raking_light_from_above(const FineFrame& frame, const std::vector<int>& vertices, float elevation_deg) {
  Eigen::Vector3f n = Eigen::Vector3f::Zero();
  for (int v : vertices) n += frame.normals.row(v).transpose();
  n.normalize();
  const Eigen::Vector3f up = (Eigen::Vector3f::UnitY() - n.y() * n).normalized();
  const float e = elevation_deg * float(M_PI) / 180;
  return (std::sin(e) * n + std::cos(e) * up).normalized();
}

TEST(SelfShadowing, ForeheadFurrowsShadowThemselvesAsTheyFormWhileOpenSkinStaysLit) {
  const Head head = make_procedural_head();
  const FineMeshMaker maker(head, WrinkleSettings{});
  const Mesh& fine = maker.fine_topology();
  const std::vector<int> forehead = face_box(head, fine, -0.4, 0.4, 0.6, 1.0);
  const std::vector<int> cheek = face_box(head, fine, 0.6, 1.0, -0.9, -0.4);
  const auto frame = [&](const std::vector<float>& e) { return maker.make(head.model.evaluate({}, e), e); };
  const FineFrame neutral = frame(expression_of(head.model, {}));
  const FineFrame raised = frame(expression_of(
      head.model, {{"browInnerUp_L", 1}, {"browInnerUp_R", 1}, {"browOuterUp_L", 1}, {"browOuterUp_R", 1}}));
  // Light raking down the forehead, 12 degrees over it; the cheek lit from the front.
  const Eigen::Vector3f over_forehead = raking_light_from_above(neutral, forehead, 12);
  const Eigen::Vector3f from_front = Eigen::Vector3f(0.1f, 0.2f, 1.0f).normalized();

  // The furrows' bottoms (crease shading below 0.75 at the full raise).
  const auto furrow = [&](int v) { return raised.shading[v] < 0.75f; };
  const Visibilities flat = visibilities(neutral, fine.faces, forehead, over_forehead, furrow);
  const Visibilities furrowed = visibilities(raised, fine.faces, forehead, over_forehead, furrow);
  const Visibilities cheek_lit = visibilities(raised, fine.faces, cheek, from_front, [](int) { return true; });
  std::cout << "furrow bottoms lit: " << flat.mean << " at rest, " << furrowed.mean << " raised (" << furrowed.count
            << " vertices)\n";
  ASSERT_GT(furrowed.count, 100);
  ASSERT_GT(cheek_lit.count, 100);
  EXPECT_GT(flat.mean, 0.99);
  EXPECT_LT(furrowed.mean, 0.7);
  EXPECT_EQ(furrowed.darkest, 0.0);
  EXPECT_EQ(cheek_lit.darkest, 1.0);
}

// ICT-FaceKit's open mouth: its interior (teeth, gums, tongue, the socket)
// lies in the lips' and the upper jaw's shadow from the studio's key light,
// while the forehead is lit.
TEST(SelfShadowing, AnOpenMouthsInteriorIsInShadowOfTheKeyLight) {
  TEGA_REQUIRE_ICT_FACEKIT(ict);
  const Head head = load_head(ict, 0.01, {});
  const FineMeshMaker maker(head, WrinkleSettings{1, 0.0012, 0.5});
  const Mesh& fine = maker.fine_topology();
  const std::vector<float> e = expression_of(head.model, {{"jawOpen", 1}});
  const FineFrame open = maker.make(head.model.evaluate({}, e), e);
  const Eigen::Vector3f key = Eigen::Vector3f(-0.5f, 0.55f, 0.67f).normalized();  // the studio's key light

  // The interior: within the mouth's width and height, over a centimetre behind the lips' front.
  double front = -1e9;
  for (int v : face_box(head, fine, -0.2, 0.2, -1.2, -0.9))
    front = std::max(front, head.frame.to_face(fine.positions.row(v).cast<double>().transpose()).z());
  std::vector<int> interior;
  for (int v = 0; v < fine.num_vertices(); ++v) {
    const Eigen::Vector3d f = head.frame.to_face(fine.positions.row(v).cast<double>().transpose());
    if (std::abs(f.x()) < 0.25 && f.y() > -1.3 && f.y() < -0.9 && f.z() < front - 0.2 && f.z() > front - 0.8)
      interior.push_back(v);
  }
  const Visibilities inside = visibilities(open, fine.faces, interior, key, [](int) { return true; });
  const Visibilities outside =
      visibilities(open, fine.faces, face_box(head, fine, -0.4, 0.4, 0.6, 1.0), key, [](int) { return true; });
  std::cout << "open mouth, key light: interior " << inside.mean << " lit (" << inside.count << " vertices), forehead "
            << outside.mean << " (" << outside.count << ")\n";
  ASSERT_GT(inside.count, 20);
  ASSERT_GT(outside.count, 20);
  EXPECT_LT(inside.mean, 0.3);
  EXPECT_GT(outside.mean, 0.95);
}

TEST(SkinGloss, OneAtRestShinierWhereStretchedMatteInCreasesWetLipsWhenOpen) {
  const Head head = make_procedural_head();
  const FineMeshMaker maker(head, WrinkleSettings{});
  const Mesh& fine = maker.fine_topology();
  const auto gloss = [&](const ExpressionSpecularOptions& o, const std::vector<float>& e) {
    // A rigid motion of the head changes nothing.
    const RigidTransform pose{Eigen::AngleAxisd(0.3, Eigen::Vector3d(1, 2, 0).normalized()).toRotationMatrix(),
                              Eigen::Vector3d(0.01, -0.02, 0.03)};
    const Vertices coarse = head.model.evaluate({}, e, pose);
    return SkinGloss(head, maker, o).per_vertex(coarse, e, maker.make(coarse, e));
  };
  const ExpressionSpecularOptions all{2.0, 1.0, 4.0};
  const std::vector<float> rest = expression_of(head.model, {});
  const Vertices& neutral = head.model.neutral.positions;
  EXPECT_TRUE(SkinGloss(head, maker, {}).per_vertex(neutral, rest, maker.make(neutral, rest)).empty());
  for (float g : gloss(all, rest)) ASSERT_NEAR(g, 1.0f, 1e-4f);

  // Stretch: the opening jaw stretches the chin and cheeks and shines them more the further it opens.
  const ExpressionSpecularOptions stretch{2.0, 0.0, 0.0};
  const std::vector<float> half = gloss(stretch, expression_of(head.model, {{"jawOpen", 0.5f}}));
  const std::vector<float> full = gloss(stretch, expression_of(head.model, {{"jawOpen", 1.0f}}));
  // (Area is quadratic in a shape's coefficient, so not every vertex rises steadily; on average they do.)
  int shinier = 0, matte = 0;
  double mean_half = 0, mean_full = 0;
  for (size_t v = 0; v < full.size(); ++v) {
    if (full[v] > 1.05f) ++shinier, mean_half += half[v], mean_full += full[v];
    matte += full[v] < 0.95f;
  }
  mean_half /= std::max(shinier, 1), mean_full /= std::max(shinier, 1);
  std::cout << "jawOpen 1: " << shinier << " fine vertices shinier by > 5 % (mean " << mean_full << ", at jawOpen 0.5 "
            << mean_half << "), " << matte << " more matte by > 5 %, largest "
            << *std::max_element(full.begin(), full.end())
            << ", smallest " << *std::min_element(full.begin(), full.end()) << "\n";
  EXPECT_GT(mean_half, 1.02);
  EXPECT_LT(mean_half, mean_full - 0.02);
  EXPECT_GT(shinier, 100);

  // Creases: the furrows' bottoms turn matte as the brows rise.
  const std::vector<float> raised_e = expression_of(
      head.model, {{"browInnerUp_L", 1}, {"browInnerUp_R", 1}, {"browOuterUp_L", 1}, {"browOuterUp_R", 1}});
  const FineFrame raised = maker.make(head.model.evaluate({}, raised_e), raised_e);
  const std::vector<float> creased = gloss({0.0, 1.0, 0.0}, raised_e);
  int furrow_bottoms = 0;
  for (int v : face_box(head, fine, -0.4, 0.4, 0.6, 1.0))
    if (raised.shading[v] < 0.75f) {
      ++furrow_bottoms;
      EXPECT_LT(creased[v], 0.75f);
    }
  EXPECT_GT(furrow_bottoms, 100);

  // Lips: wetter as the jaw opens; the forehead stays as it was.
  const std::vector<float> wet = gloss({0.0, 0.0, 4.0}, expression_of(head.model, {{"jawOpen", 1.0f}}));
  float wettest = 0;
  for (int v : face_box(head, fine, -0.1, 0.1, -1.15, -0.95)) wettest = std::max(wettest, wet[v]);
  EXPECT_GT(wettest, 4.0f);
  for (int v : face_box(head, fine, -0.4, 0.4, 0.6, 1.0)) EXPECT_NEAR(wet[v], 1.0f, 1e-3f);
}

// A small capture of the "expressions" script: frame 0 at rest, frame 2 the
// brows raised, frame 7 the jaw open.
Options small_expressions_capture() {
  Options o;
  o.studio.cameras = 2;
  o.studio.width = 96;
  o.studio.height = 72;
  o.frames = 11;
  o.calibration_frames = 0;
  o.takes = {"expressions"};
  o.test_takes = {};
  o.test_cameras = 1;
  o.supersampling = 1;
  o.fine_subdivisions = 1;
  o.seed = 5;
  return o;
}

std::string contents(const fs::path& file) {
  std::ifstream in(file, std::ios::binary);
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

// Every file of `a` but capture.json (which records the options), compared
// with the same file of `b` by `compare`; returns how many were compared.
int compare_files(const fs::path& a, const fs::path& b,
                  const std::function<void(const fs::path& rel, const fs::path& a, const fs::path& b)>& compare) {
  int compared = 0;
  for (const auto& entry : fs::recursive_directory_iterator(a)) {
    if (!entry.is_regular_file()) continue;
    const fs::path rel = fs::relative(entry.path(), a);
    if (rel == "capture.json") continue;
    EXPECT_TRUE(fs::exists(b / rel)) << rel;
    compare(rel, entry.path(), b / rel);
    ++compared;
  }
  return compared;
}

// Per pixel and channel, b - a, of two 8-bit images of one size.
std::vector<int> differences(const fs::path& a, const fs::path& b) {
  const Image8 x = read_image_u8(a), y = read_image_u8(b);
  EXPECT_EQ(x.pixels.size(), y.pixels.size());
  std::vector<int> d(x.pixels.size());
  for (size_t i = 0; i < d.size(); ++i) d[i] = int(y.pixels[i]) - int(x.pixels[i]);
  return d;
}

class ExpressionAppearance : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    dir_ = new tega::test::TempDir;
    render_virtual_studio(small_expressions_capture(), *dir_ / "plain");
  }
  static void TearDownTestSuite() { delete dir_; }
  static fs::path plain() { return *dir_ / "plain"; }
  static fs::path render(const std::string& name, const Options& o) {
    render_virtual_studio(o, *dir_ / name);
    return *dir_ / name;
  }
  static tega::test::TempDir* dir_;
};
tega::test::TempDir* ExpressionAppearance::dir_ = nullptr;

TEST_F(ExpressionAppearance, OffEveryFileIsByteIdenticalWhateverTheOtherSettings) {
  Options o = small_expressions_capture();
  o.self_shadowing.map_size = 256;
  o.self_shadowing.softness_m = 0.004;
  o.expression_specular = {};
  const fs::path off = render("off", o);
  const int compared = compare_files(plain(), off, [](const fs::path& rel, const fs::path& a, const fs::path& b) {
    EXPECT_EQ(contents(a), contents(b)) << rel;
  });
  EXPECT_GT(compared, 11 * 2 * 3);
}

TEST_F(ExpressionAppearance, SelfShadowingOnlyDarkensTheHeadAndMostWhereTheMouthOpens) {
  Options o = small_expressions_capture();
  o.self_shadowing.enabled = true;
  o.self_shadowing.map_size = 512;
  const fs::path shadowed = render("shadowed", o);
  int images = 0;
  compare_files(plain(), shadowed, [&](const fs::path& rel, const fs::path& a, const fs::path& b) {
    const std::string name = rel.string();
    if ((name.find("takes/") != 0 && name.find("dataset/images/") != 0) || rel.extension() != ".png") {
      EXPECT_EQ(contents(a), contents(b)) << rel << ": only the head's colours change";
      return;
    }
    ++images;
    const std::vector<int> d = differences(a, b);
    EXPECT_LE(*std::max_element(d.begin(), d.end()), 1) << rel << " is brighter in places";
  });
  EXPECT_EQ(images, 11 * 2 * 2 + 2);  // takes (with the clean plate) and the dataset
  // Frame 7, the jaw open, in the frontal camera's matted image (RGBA, alpha unchanged).
  const std::vector<int> d = differences(plain() / "dataset/images/cam00/expressions_000007.png",
                                         shadowed / "dataset/images/cam00/expressions_000007.png");
  int head = 0, unchanged = 0, darker = 0, darkest = 0;
  const Image8 alpha = read_image_u8(plain() / "dataset/images/cam00/expressions_000007.png");
  for (size_t p = 0; p < d.size() / 4; ++p) {
    if (alpha.pixels[4 * p + 3] < 255) continue;
    ++head;
    const int change = std::min({d[4 * p], d[4 * p + 1], d[4 * p + 2]});
    unchanged += change >= -1;
    darker += change <= -10;
    darkest = std::min(darkest, change);
  }
  std::cout << "frame 7, cam00: " << head << " head pixels, " << unchanged << " unchanged, " << darker
            << " darker by 10+ levels, at most by " << -darkest << "\n";
  EXPECT_GT(darker, 5);
  EXPECT_GT(unchanged, head / 2);
}

TEST_F(ExpressionAppearance, ExpressionSpecularLeavesTheRestingFrameAndChangesTheExpressiveOnes) {
  Options o = small_expressions_capture();
  o.expression_specular = {2.0, 1.0, 4.0};
  const fs::path glossy = render("glossy", o);
  // Largest change of a channel, and channels changed at all (the noise is the same in both).
  const auto changes = [&](int frame) {
    const std::string image = "dataset/images/cam00/expressions_00000" + std::to_string(frame) + ".png";
    std::pair<int, int> out{0, 0};
    for (int x : differences(plain() / image, glossy / image)) {
      out.first = std::max(out.first, std::abs(x));
      out.second += x != 0;
    }
    return out;
  };
  const auto [rest_largest, rest_changed] = changes(0);
  const auto [open_largest, open_changed] = changes(7);
  std::cout << "frame 0 (rest): largest change " << rest_largest << "; frame 7 (jaw open): largest " << open_largest
            << ", " << open_changed << " channels changed\n";
  EXPECT_LE(rest_largest, 1);
  EXPECT_GE(open_largest, 2);
  EXPECT_GT(open_changed, 100);
}

TEST(ExpressionAppearanceOptions, LoadFromYamlAndBadValuesAreRefusedByName) {
  Options o;
  load_options_from_string(o,
                           "self_shadowing: {enabled: true, map_size: 2048, softness_m: 0.002}\n"
                           "expression_specular: {stretch_exponent: 2, crease_matte: 1, wet_lips: 3}\n",
                           "", "test");
  EXPECT_TRUE(o.self_shadowing.enabled);
  EXPECT_EQ(o.self_shadowing.map_size, 2048);
  EXPECT_EQ(o.expression_specular.wet_lips, 3.0);
  EXPECT_NO_THROW(validate_options(o));
  EXPECT_THROW(load_options_from_string(o, "self_shadowing: {blur: 1}\n", "", "test"), std::exception);
  const auto refused = [](const std::function<void(Options&)>& change) {
    Options bad;
    change(bad);
    return tega::test::error_message([&] { validate_options(bad); });
  };
  EXPECT_NE(refused([](Options& b) { b.self_shadowing.map_size = 16; }).find("self_shadowing.map_size"),
            std::string::npos);
  EXPECT_NE(refused([](Options& b) { b.self_shadowing.softness_m = -1; }).find("self_shadowing.softness_m"),
            std::string::npos);
  EXPECT_NE(refused([](Options& b) { b.expression_specular.wet_lips = -1; }).find("expression_specular.wet_lips"),
            std::string::npos);
  EXPECT_NE(refused([](Options& b) { b.expression_specular.stretch_exponent = NAN; })
                .find("expression_specular.stretch_exponent"),
            std::string::npos);
}

}  // namespace
}  // namespace tega::synth
