#include "tega/core/rig.h"

#include <gtest/gtest.h>

#include <fstream>
#include <functional>
#include <nlohmann/json.hpp>
#include <sstream>

#include "tega/core/error.h"
#include "test_support.h"

namespace tega {
namespace {

using nlohmann::json;

// Three cameras, one per COLMAP model tega writes: no distortion (PINHOLE),
// k3 == 0 (OPENCV) and full (FULL_OPENCV).
Rig studio_rig() {
  Rig rig;
  const std::array<std::array<double, 5>, 3> distortions{
      {{0, 0, 0, 0, 0}, {-0.11, 0.07, 0.0011, -0.0007, 0}, {-0.12, 0.08, 0.0012, -0.0008, -0.02}}};
  for (int i = 0; i < 3; ++i) {
    Camera c;
    c.name = "cam0" + std::to_string(i);
    c.width = 2048 + 16 * i;
    c.height = 1334 - 8 * i;
    c.K << 1800.25 + 10 * i, 0, 1020.3 + i, 0, 1795.5 - 3 * i, 660.7 - i, 0, 0, 1;
    c.distortion = distortions[static_cast<size_t>(i)];
    c.world_to_camera.R =
        Eigen::AngleAxisd(0.3 + 0.4 * i, Eigen::Vector3d(0.2, 1.0, -0.3 * i).normalized())
            .toRotationMatrix();
    c.world_to_camera.t = Eigen::Vector3d(0.05 * i - 0.1, -0.123456789, 1.3 + 0.01 * i);
    rig.cameras.push_back(c);
  }
  return rig;
}

void expect_same_rig(const Rig& expected, const Rig& actual, double tolerance) {
  ASSERT_EQ(expected.camera_names(), actual.camera_names());
  for (size_t i = 0; i < expected.cameras.size(); ++i) {
    const Camera& e = expected.cameras[i];
    const Camera& a = actual.cameras[i];
    SCOPED_TRACE(e.name);
    EXPECT_EQ(e.width, a.width);
    EXPECT_EQ(e.height, a.height);
    EXPECT_LE((e.K - a.K).cwiseAbs().maxCoeff(), tolerance * e.K.cwiseAbs().maxCoeff());
    for (size_t k = 0; k < 5; ++k) EXPECT_NEAR(e.distortion[k], a.distortion[k], tolerance);
    EXPECT_LE((e.world_to_camera.R - a.world_to_camera.R).cwiseAbs().maxCoeff(), tolerance);
    EXPECT_LE((e.world_to_camera.t - a.world_to_camera.t).cwiseAbs().maxCoeff(), tolerance);
  }
}

std::string read_text(const std::filesystem::path& file) {
  std::ifstream in(file, std::ios::binary);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

std::vector<std::string> lines_of(const std::string& text) {
  std::vector<std::string> lines;
  std::istringstream in(text);
  for (std::string line; std::getline(in, line);) lines.push_back(line);
  return lines;
}

std::vector<std::string> words_of(const std::string& line) {
  std::vector<std::string> words;
  std::istringstream in(line);
  for (std::string word; in >> word;) words.push_back(word);
  return words;
}

using test::error_message;

TEST(Rig, LooksCamerasUpByName) {
  const Rig rig = studio_rig();
  EXPECT_EQ(rig.camera_names(), (std::vector<std::string>{"cam00", "cam01", "cam02"}));
  EXPECT_TRUE(rig.contains("cam01"));
  EXPECT_FALSE(rig.contains("cam03"));
  EXPECT_EQ(rig.camera("cam02").width, 2080);
  EXPECT_NE(error_message([&] { rig.camera("cam03"); }).find("'cam03'"), std::string::npos);
}

TEST(RigJson, RoundTripIsExact) {
  test::TempDir dir;
  const Rig rig = studio_rig();
  write_rig_json(rig, dir / "rig.json");
  expect_same_rig(rig, read_rig_json(dir / "rig.json"), 0.0);

  const json doc = json::parse(read_text(dir / "rig.json"));
  EXPECT_EQ(doc["format"], "tega-rig");
  EXPECT_EQ(doc["version"], 1);
  EXPECT_EQ(doc["units"], "metres");
  EXPECT_EQ(doc["cameras"][1]["K"][0][2], 1021.3);
  EXPECT_EQ(doc["cameras"][2]["t"][1], -0.123456789);
}

class RigJsonErrors : public ::testing::Test {
 protected:
  void SetUp() override {
    write_rig_json(studio_rig(), dir_ / "rig.json");
    doc_ = json::parse(read_text(dir_ / "rig.json"));
  }
  // The error reading the rig after `edit`; it always names the file.
  std::string error_after(const std::function<void(json&)>& edit) {
    json doc = doc_;
    edit(doc);
    test::write_text(dir_ / "bad.json", doc.dump(2));
    const std::string message = error_message([&] { read_rig_json(dir_ / "bad.json"); });
    EXPECT_NE(message.find((dir_ / "bad.json").string()), std::string::npos) << message;
    return message;
  }

  test::TempDir dir_;
  json doc_;
};

#define EXPECT_CONTAINS(text, part) \
  EXPECT_NE((text).find(part), std::string::npos) << "'" << (text) << "' lacks '" << (part) << "'"

TEST_F(RigJsonErrors, UnknownFormatOrVersion) {
  EXPECT_CONTAINS(error_after([](json& d) { d["format"] = "colmap"; }), "'format' is 'colmap'");
  EXPECT_CONTAINS(error_after([](json& d) { d["version"] = 2; }), "unsupported version 2");
  EXPECT_CONTAINS(error_after([](json& d) { d["units"] = "millimetres"; }), "'units'");
  EXPECT_CONTAINS(error_after([](json& d) { d.erase("format"); }), "missing field 'format'");
}

TEST_F(RigJsonErrors, MissingOrMisshapenFieldNamesTheCamera) {
  const std::string missing = error_after([](json& d) { d["cameras"][1].erase("K"); });
  EXPECT_CONTAINS(missing, "camera 'cam01'");
  EXPECT_CONTAINS(missing, "missing field 'K'");
  const std::string shape = error_after([](json& d) { d["cameras"][2]["t"] = {1.0, 2.0}; });
  EXPECT_CONTAINS(shape, "camera 'cam02'");
  EXPECT_CONTAINS(shape, "'t' must be a 3 numbers");
  EXPECT_CONTAINS(error_after([](json& d) { d["cameras"][0]["R"][1][2] = "x"; }), "'R' must be a 3x3");
  EXPECT_CONTAINS(error_after([](json& d) { d["cameras"][0].erase("name"); }),
                  "camera #0: missing field 'name'");
  EXPECT_CONTAINS(error_after([](json& d) { d["cameras"][0]["distorsion"] = 0; }),
                  "unknown field 'distorsion'");
}

TEST_F(RigJsonErrors, InvalidValuesNameTheCameraAndField) {
  const std::string rotation = error_after([](json& d) { d["cameras"][1]["R"][0][0] = 0.9; });
  EXPECT_CONTAINS(rotation, "camera 'cam01'");
  EXPECT_CONTAINS(rotation, "'R' is not orthonormal");
  const std::string reflection = error_after([](json& d) {
    for (int c = 0; c < 3; ++c) d["cameras"][0]["R"][0][c] = -d["cameras"][0]["R"][0][c].get<double>();
  });
  EXPECT_CONTAINS(reflection, "reflection");
  const std::string focal = error_after([](json& d) { d["cameras"][2]["K"][1][1] = -5.0; });
  EXPECT_CONTAINS(focal, "camera 'cam02'");
  EXPECT_CONTAINS(focal, "non-positive focal length");
  EXPECT_CONTAINS(error_after([](json& d) { d["cameras"][0]["width"] = 0; }),
                  "'width' and 'height' must be positive");
  EXPECT_CONTAINS(error_after([](json& d) { d["cameras"][0]["K"][2][2] = 2.0; }), "must have the form");
  EXPECT_CONTAINS(error_after([](json& d) { d["cameras"][2]["name"] = "cam00"; }),
                  "camera 'cam00': duplicate camera name");
  EXPECT_CONTAINS(error_after([](json& d) { d["cameras"][2]["name"] = "cam 2"; }), "whitespace");
  EXPECT_CONTAINS(error_after([](json& d) { d["cameras"] = json::array(); }), "no cameras");
}

TEST_F(RigJsonErrors, NotJson) {
  test::write_text(dir_ / "bad.json", "{\"format\": \"tega-rig\",");
  EXPECT_CONTAINS(error_message([&] { read_rig_json(dir_ / "bad.json"); }), "not valid JSON");
}

TEST(RigWriters, RefuseAnInvalidRigAndWriteNothing) {
  test::TempDir dir;
  Rig rig = studio_rig();
  rig.cameras[1].name = "cam 01";
  EXPECT_THROW(write_rig_json(rig, dir / "rig.json"), Error);
  EXPECT_THROW(write_krt(rig, dir / "KRT"), Error);
  EXPECT_THROW(write_colmap_text(rig, dir / "colmap"), Error);
  EXPECT_TRUE(std::filesystem::is_empty(dir.path()));
}

TEST(RigColmap, RoundTripPreservesEveryParameter) {
  test::TempDir dir;
  const Rig rig = studio_rig();
  write_colmap_text(rig, dir / "sparse");
  for (const char* file : {"cameras.txt", "images.txt", "points3D.txt"})
    EXPECT_TRUE(std::filesystem::exists(dir / "sparse" / file)) << file;
  expect_same_rig(rig, read_colmap_text(dir / "sparse"), 1e-12);
}

TEST(RigColmap, WritesOneModelPerDistortionAndCentresPixelsAtHalf) {
  test::TempDir dir;
  const Rig rig = studio_rig();
  write_colmap_text(rig, dir / "sparse");
  std::vector<std::vector<std::string>> cameras;
  for (const std::string& line : lines_of(read_text(dir / "sparse" / "cameras.txt")))
    if (line[0] != '#') cameras.push_back(words_of(line));
  ASSERT_EQ(cameras.size(), 3u);
  EXPECT_EQ(cameras[0][1], "PINHOLE");
  EXPECT_EQ(cameras[0].size(), 4u + 4u);
  EXPECT_EQ(cameras[1][1], "OPENCV");
  EXPECT_EQ(cameras[1].size(), 4u + 8u);
  EXPECT_EQ(cameras[2][1], "FULL_OPENCV");
  EXPECT_EQ(cameras[2].size(), 4u + 12u);
  // COLMAP puts the top-left pixel's centre at (0.5, 0.5).
  EXPECT_EQ(std::stod(cameras[0][6]), rig.cameras[0].K(0, 2) + 0.5);
  EXPECT_EQ(std::stod(cameras[0][7]), rig.cameras[0].K(1, 2) + 0.5);
  EXPECT_EQ(std::stod(cameras[2][12]), -0.02);
}

TEST(RigColmap, MetresPerUnitScalesTranslations) {
  test::TempDir dir;
  const Rig rig = studio_rig();
  write_colmap_text(rig, dir / "sparse", 0.001);
  const std::vector<std::string> lines = lines_of(read_text(dir / "sparse" / "images.txt"));
  ASSERT_EQ(lines.size(), 4u + 2 * 3);
  const std::vector<std::string> first = words_of(lines[4]);
  ASSERT_EQ(first.size(), 10u);
  EXPECT_EQ(first[9], "cam00");
  EXPECT_TRUE(lines[5].empty());
  EXPECT_NEAR(std::stod(first[6]), -123.456789, 1e-9);
  EXPECT_NEAR(std::stod(first[7]), 1300.0, 1e-9);
  expect_same_rig(rig, read_colmap_text(dir / "sparse", 0.001), 1e-12);
}

TEST(RigColmap, ReadsColmapsOwnOutput) {
  test::TempDir dir;
  test::write_text(dir / "cameras.txt",
                   "# Camera list with one line of data per camera:\n"
                   "1 SIMPLE_RADIAL 640 480 500 320.5 240.5 -0.05\n"
                   "2 RADIAL 800 600 610 400.5 300.5 -0.01 0.002\n");
  test::write_text(dir / "images.txt",
                   "# Image list with two lines of data per image:\n"
                   "3 0.70710678118654757 0 0.70710678118654757 0 10 20 -30 1 left.png\n"
                   "10.0 20.0 -1 11.5 12.5 4\n"
                   "7 1 0 0 0 0 0 100 2 right.png\n"
                   "\n");
  test::write_text(dir / "points3D.txt", "");
  const Rig rig = read_colmap_text(dir.path(), 0.01);
  // COLMAP names images by their files; a camera is the name without its image extension.
  ASSERT_EQ(rig.camera_names(), (std::vector<std::string>{"left", "right"}));
  const Camera& left = rig.camera("left");
  EXPECT_EQ(left.width, 640);
  EXPECT_EQ(left.K(0, 0), 500);
  EXPECT_EQ(left.K(1, 1), 500);
  EXPECT_EQ(left.K(0, 2), 320);
  EXPECT_EQ(left.K(1, 2), 240);
  EXPECT_EQ(left.distortion, (std::array<double, 5>{-0.05, 0, 0, 0, 0}));
  // A quarter turn about +y: camera +z looks along world -x.
  EXPECT_LT((left.world_to_camera.R.transpose() * Eigen::Vector3d::UnitZ() + Eigen::Vector3d::UnitX())
                .norm(), 1e-15);
  EXPECT_LT((left.world_to_camera.t - Eigen::Vector3d(0.1, 0.2, -0.3)).norm(), 1e-15);
  const Camera& right = rig.camera("right");
  EXPECT_EQ(right.K(0, 0), 610);
  EXPECT_EQ(right.distortion, (std::array<double, 5>{-0.01, 0.002, 0, 0, 0}));
  EXPECT_LT((right.center() - Eigen::Vector3d(0, 0, -1)).norm(), 1e-15);
}

TEST(RigColmap, ImageNameSuffixAndSparsePointsForDenseWorkspaces) {
  test::TempDir dir;
  const Rig rig = studio_rig();
  std::vector<ColmapPoint> points(2);
  points[0].position = Eigen::Vector3d(0.1, 0.2, 0.3);
  points[0].observations = {{0, Eigen::Vector2d(10, 20)}, {2, Eigen::Vector2d(30.25, 40)}};
  points[1].position = Eigen::Vector3d(-0.1, 0, 1);
  points[1].observations = {{2, Eigen::Vector2d(5, 6)}, {1, Eigen::Vector2d(7, 8)}};
  write_colmap_text(rig, dir / "sparse", 0.001, ".png", points);
  expect_same_rig(rig, read_colmap_text(dir / "sparse", 0.001), 1e-12);

  const std::vector<std::string> images = lines_of(read_text(dir / "sparse" / "images.txt"));
  ASSERT_EQ(images.size(), 4u + 2 * 3);
  EXPECT_EQ(words_of(images[4])[9], "cam00.png");
  // POINTS2D as (X, Y, POINT3D_ID), pixel centres at +0.5.
  EXPECT_EQ(images[5], "10.5 20.5 1");
  EXPECT_EQ(images[7], "7.5 8.5 2");
  EXPECT_EQ(images[9], "30.75 40.5 1 5.5 6.5 2");
  // TRACK[] as (IMAGE_ID, POINT2D_IDX) by image, coordinates in COLMAP units.
  std::vector<std::string> points3d;
  for (const std::string& line : lines_of(read_text(dir / "sparse" / "points3D.txt")))
    if (line[0] != '#') points3d.push_back(line);
  EXPECT_EQ(points3d, (std::vector<std::string>{"1 100 200 300 0 0 0 0 1 0 3 0", "2 -100 0 1000 0 0 0 0 2 0 3 1"}));

  points[1].observations[0].first = 3;
  EXPECT_CONTAINS(error_message([&] { write_colmap_text(rig, dir / "bad", 1.0, ".png", points); }),
                  "point 2 is observed by camera index 3, but the rig has 3 cameras");
}

TEST(RigColmap, CameraNameDropsOnlyImageExtensions) {
  EXPECT_EQ(colmap_camera_name("cam00.png"), "cam00");
  EXPECT_EQ(colmap_camera_name("IMG_0001.JPG"), "IMG_0001");
  EXPECT_EQ(colmap_camera_name("a.b.jpeg"), "a.b");
  EXPECT_EQ(colmap_camera_name("cam00"), "cam00");
  EXPECT_EQ(colmap_camera_name("cam.raw"), "cam.raw");
  EXPECT_EQ(colmap_camera_name(".png"), ".png");
}

TEST(RigColmap, ErrorsNameFileAndLine) {
  test::TempDir dir;
  test::write_text(dir / "cameras.txt", "# cameras\n1 PINHOLE 640 480 500 500 320 240\n"
                                        "2 OPENCV_FISHEYE 640 480 500 500 320 240 0 0 0 0\n");
  test::write_text(dir / "images.txt", "1 1 0 0 0 0 0 0 1 a\n\n");
  const std::string model = error_message([&] { read_colmap_text(dir.path()); });
  EXPECT_CONTAINS(model, (dir / "cameras.txt").string() + ": line 3: unsupported camera model "
                                                          "'OPENCV_FISHEYE'");

  test::write_text(dir / "cameras.txt", "1 PINHOLE 640 480 500 500 320\n");
  EXPECT_CONTAINS(error_message([&] { read_colmap_text(dir.path()); }),
                  "line 1: camera model PINHOLE takes 4 parameters, found 3");

  test::write_text(dir / "cameras.txt", "1 PINHOLE 640 480 500 500 320 240\n");
  test::write_text(dir / "images.txt", "1 1 0 0 0 0 0 0 1 a\n\n2 1 0 0 0 0 0 0 3 b\n\n");
  EXPECT_CONTAINS(error_message([&] { read_colmap_text(dir.path()); }),
                  (dir / "images.txt").string() + ": line 3: CAMERA_ID 3 is not in cameras.txt");

  EXPECT_CONTAINS(error_message([&] { read_colmap_text(dir.path(), 0.0); }), "metres_per_unit");
}

TEST(RigColmap, RefusesSkew) {
  test::TempDir dir;
  Rig rig = studio_rig();
  rig.cameras[1].K(0, 1) = 0.5;
  EXPECT_CONTAINS(error_message([&] { write_colmap_text(rig, dir / "sparse"); }),
                  "camera 'cam01': COLMAP has no skew");
}

TEST(RigKrt, RoundTripPreservesEveryParameter) {
  test::TempDir dir;
  const Rig rig = studio_rig();
  write_krt(rig, dir / "KRT");
  // KRT carries no image size: cameras of other sizes come back at the given one.
  Rig expected = rig;
  for (Camera& c : expected.cameras) c.width = 1334, c.height = 2048;
  expect_same_rig(expected, read_krt(dir / "KRT", 1334, 2048), 1e-12);
}

TEST(RigKrt, TranslationsAreMillimetres) {
  test::TempDir dir;
  const Rig rig = studio_rig();
  write_krt(rig, dir / "KRT");
  const std::vector<std::string> lines = lines_of(read_text(dir / "KRT"));
  ASSERT_EQ(lines.size(), 9u * 3);
  for (size_t c = 0; c < 3; ++c) {
    EXPECT_EQ(lines[9 * c], rig.cameras[c].name);
    EXPECT_TRUE(lines[9 * c + 8].empty());
    for (int r = 0; r < 3; ++r) {
      const std::vector<std::string> words = words_of(lines[9 * c + 5 + static_cast<size_t>(r)]);
      ASSERT_EQ(words.size(), 4u);
      EXPECT_NEAR(std::stod(words[3]), 1000.0 * rig.cameras[c].world_to_camera.t(r), 1e-9);
      EXPECT_EQ(std::stod(words[0]), rig.cameras[c].world_to_camera.R(r, 0));
    }
  }
}

TEST(RigKrt, ReadsMultifaceFile) {
  test::TempDir dir;
  test::write_text(dir / "KRT",
                   "400002\n"
                   "7193.4 0.0 1031.1\n"
                   "0.0 7193.1 669.2\n"
                   "0.0 0.0 1.0\n"
                   "0.0 0.0 0.0 0.0 0.0\n"
                   "0.96 0.0 0.28 -93.5\n"
                   "0.0 1.0 0.0 12.25\n"
                   "-0.28 0.0 0.96 1024.0\n"
                   "\n");
  const Rig rig = read_krt(dir / "KRT", 1334, 2048);
  ASSERT_EQ(rig.cameras.size(), 1u);
  const Camera& c = rig.cameras[0];
  EXPECT_EQ(c.name, "400002");
  EXPECT_EQ(c.width, 1334);
  EXPECT_EQ(c.K(0, 2), 1031.1);
  EXPECT_FALSE(c.has_distortion());
  EXPECT_NEAR(c.world_to_camera.t.x(), -0.0935, 1e-15);
  EXPECT_NEAR(c.world_to_camera.t.z(), 1.024, 1e-15);
  // Centre = -R^T t: x = -(0.96 * -0.0935 - 0.28 * 1.024), z = -(0.28 * -0.0935 + 0.96 * 1.024).
  EXPECT_LT((c.center() - Eigen::Vector3d(0.37648, -0.01225, -0.95686)).norm(), 1e-12);
}

class RigKrtErrors : public ::testing::Test {
 protected:
  void SetUp() override {
    write_krt(studio_rig(), dir_ / "KRT");
    lines_ = lines_of(read_text(dir_ / "KRT"));
  }
  // The error reading `text` as a KRT file; it always names the file.
  std::string error_reading(const std::string& text) {
    test::write_text(dir_ / "bad", text);
    const std::string message = error_message([&] { read_krt(dir_ / "bad", 1334, 2048); });
    EXPECT_EQ(message.rfind((dir_ / "bad").string() + ": line ", 0), 0u) << message;
    return message;
  }
  std::string first_lines(size_t count) const {
    std::string text;
    for (size_t i = 0; i < count; ++i) text += lines_[i] + "\n";
    return text;
  }

  test::TempDir dir_;
  std::vector<std::string> lines_;
};

TEST_F(RigKrtErrors, FileEndingInsideACameraBlock) {
  // Camera cam01 starts on line 10; its [R|t] rows are lines 15 to 17.
  EXPECT_CONTAINS(error_reading(first_lines(15)),
                  "line 16: expected row 2 of [R|t] of camera 'cam01', found the end of the file");
  EXPECT_CONTAINS(error_reading(first_lines(10)),
                  "line 11: expected row 1 of K of camera 'cam01', found the end of the file");
}

TEST_F(RigKrtErrors, LineCutShort) {
  const std::string& row = lines_[6];
  const std::string text = first_lines(6) + row.substr(0, row.find(' ', row.find(' ') + 1));
  EXPECT_CONTAINS(error_reading(text),
                  "line 7: expected row 2 of [R|t] of camera 'cam00' (4 numbers), found 2 values");
}

TEST_F(RigKrtErrors, WrongNumberCountOrNonNumericToken) {
  std::vector<std::string> lines = lines_;
  lines[2] = "0 1795.5";
  std::string text;
  for (const std::string& line : lines) text += line + "\n";
  EXPECT_CONTAINS(error_reading(text),
                  "line 3: expected row 2 of K of camera 'cam00' (3 numbers), found 2 values");

  lines = lines_;
  lines[13] = "-0.11 0.07 zero -0.0007 0";
  text.clear();
  for (const std::string& line : lines) text += line + "\n";
  EXPECT_CONTAINS(error_reading(text), "line 14: expected the distortion k1 k2 p1 p2 k3 of camera "
                                       "'cam01' (5 numbers), found 'zero'");
}

TEST_F(RigKrtErrors, MissingBlankLineBetweenCameras) {
  std::string text = first_lines(8);
  for (size_t i = 9; i < lines_.size(); ++i) text += lines_[i] + "\n";
  EXPECT_CONTAINS(error_reading(text),
                  "line 9: expected a blank line after camera 'cam00', found 'cam01'");
}

TEST_F(RigKrtErrors, EmptyFileHasNoCameras) {
  test::write_text(dir_ / "empty", "\n\n");
  EXPECT_CONTAINS(error_message([&] { read_krt(dir_ / "empty", 1334, 2048); }), "no cameras");
}

TEST(RigFormats, JsonToColmapToKrtToJsonPreservesEverything) {
  test::TempDir dir;
  const Rig rig = studio_rig();
  write_rig_json(rig, dir / "a.json");
  write_colmap_text(read_rig_json(dir / "a.json"), dir / "sparse", 0.001);
  Rig from_colmap = read_colmap_text(dir / "sparse", 0.001);
  write_krt(from_colmap, dir / "KRT");
  Rig from_krt = read_krt(dir / "KRT", 1, 1);
  for (size_t i = 0; i < rig.cameras.size(); ++i) {
    from_krt.cameras[i].width = rig.cameras[i].width;
    from_krt.cameras[i].height = rig.cameras[i].height;
  }
  write_rig_json(from_krt, dir / "b.json");
  expect_same_rig(rig, read_rig_json(dir / "b.json"), 1e-12);
}

}  // namespace
}  // namespace tega
