#include <gtest/gtest.h>

#include <functional>

#include "tega/core/error.h"
#include "tega/core/files.h"
#include "tega/core/mesh.h"
#include "test_support.h"

namespace tega {
namespace {

// Two quads side by side sharing the edge 1-4, cut by a UV seam along it:
// vertices 1 and 4 have a UV in each quad. Positions and UVs carry values
// that only an exact (shortest round-trip) float writer preserves.
Mesh seam_mesh() {
  Mesh mesh;
  mesh.positions.resize(6, 3);
  mesh.positions << 0.0f, 0.0f, 0.1f,  //
      1.0f / 3.0f, 0.0f, -2.5e-7f,     //
      2.0f, 0.0f, 1e10f,               //
      0.0f, 1.0f, 3.14159265f,         //
      1.0f / 3.0f, 1.0f, -0.0f,        //
      2.0f, 1.0f, 123456.789f;
  mesh.uvs.resize(8, 2);
  mesh.uvs << 0.0f, 0.0f, 0.4f, 0.0f, 0.4f, 1.0f / 7.0f, 0.0f, 1.0f,  // left quad
      0.6f, 0.0f, 1.0f, 0.0f, 1.0f, 1.0f, 0.6f, 1.0f / 7.0f;          // right quad
  // Fans of the quads (0 1 4 3) and (1 2 5 4), as the readers triangulate.
  mesh.faces.resize(4, 3);
  mesh.faces << 0, 1, 4, 0, 4, 3, 1, 2, 5, 1, 5, 4;
  mesh.uv_faces.resize(4, 3);
  mesh.uv_faces << 0, 1, 2, 0, 2, 3, 4, 5, 6, 4, 6, 7;
  mesh.triangle_polygon = {0, 0, 1, 1};
  return mesh;
}

void expect_same_mesh(const Mesh& actual, const Mesh& expected) {
  EXPECT_EQ(actual.positions, expected.positions);
  EXPECT_EQ(actual.faces, expected.faces);
  EXPECT_EQ(actual.uvs, expected.uvs);
  EXPECT_EQ(actual.uv_faces, expected.uv_faces);
  EXPECT_EQ(actual.triangle_polygon, expected.triangle_polygon);
}

// What a UV seam means, independent of how UVs are numbered: the UV of every face corner.
std::vector<float> corner_uvs(const Mesh& mesh) {
  std::vector<float> uvs;
  for (Eigen::Index f = 0; f < mesh.uv_faces.rows(); ++f) {
    for (int k = 0; k < 3; ++k) {
      uvs.push_back(mesh.uvs(mesh.uv_faces(f, k), 0));
      uvs.push_back(mesh.uvs(mesh.uv_faces(f, k), 1));
    }
  }
  return uvs;
}

using test::error_message;

TEST(MeshObj, RoundTripKeepsSeamsPolygonsAndExactFloats) {
  test::TempDir dir;
  const Mesh mesh = seam_mesh();
  write_obj(mesh, dir / "seam.obj");
  expect_same_mesh(read_obj(dir / "seam.obj"), mesh);
  // The quads are written back as quads.
  const std::string text = read_text_file(dir / "seam.obj");
  EXPECT_NE(text.find("\nf 1/1 2/2 5/3 4/4\n"), std::string::npos) << text;
}

TEST(MeshPly, RoundTripKeepsSeamsPolygonsAndExactFloats) {
  test::TempDir dir;
  const Mesh mesh = seam_mesh();
  write_ply(mesh, dir / "seam.ply");
  // The seam mesh's UVs are in order of first use, which is how PLY rebuilds them.
  expect_same_mesh(read_ply(dir / "seam.ply"), mesh);
}

TEST(MeshIo, DispatchesByExtension) {
  test::TempDir dir;
  const Mesh mesh = seam_mesh();
  write_mesh(mesh, dir / "a.OBJ");
  write_mesh(mesh, dir / "a.ply");
  expect_same_mesh(read_mesh(dir / "a.OBJ"), mesh);
  expect_same_mesh(read_mesh(dir / "a.ply"), mesh);
  EXPECT_THROW(write_mesh(mesh, dir / "a.stl"), Error);
  EXPECT_FALSE(std::filesystem::exists(dir / "a.stl"));
}

TEST(MeshObj, ReadsEveryFaceSyntax) {
  test::TempDir dir;
  test::write_text(dir / "syntax.obj",
                   "# comment\r\n"
                   "mtllib x.mtl\n"
                   "o thing\n"
                   "v 0 0 0\nv 1 0 0\nv 1 1 0 1.0\nv 0 1 0 0.5 0.5 0.5\nv +2 0.5 -1e-3\n"
                   "vt 0 0\nvt 1 0\nvt 1 1\nvt 0.5\n"
                   "vn 0 0 1\n"
                   "g group\nusemtl skin\ns 1\n"
                   "f 1/1/1 2/2/1 3/3/1 4/4/1\r\n"
                   "f -4/-3 -1/-1 -3/-2\n"  // relative: vertices 2 5 3, UVs 2 4 3
                   "l 1 2\n");
  const Mesh mesh = read_obj(dir / "syntax.obj");
  ASSERT_EQ(mesh.num_vertices(), 5);
  EXPECT_EQ(mesh.positions.row(4), Eigen::RowVector3f(2.0f, 0.5f, -1e-3f));
  ASSERT_EQ(mesh.uvs.rows(), 4);
  EXPECT_EQ(mesh.uvs.row(3), Eigen::RowVector2f(0.5f, 0.0f));
  Triangles faces(3, 3), uv_faces(3, 3);
  faces << 0, 1, 2, 0, 2, 3, 1, 4, 2;
  uv_faces << 0, 1, 2, 0, 2, 3, 1, 3, 2;
  EXPECT_EQ(mesh.faces, faces);
  EXPECT_EQ(mesh.uv_faces, uv_faces);
  EXPECT_EQ(mesh.triangle_polygon, (std::vector<int32_t>{0, 0, 1}));
}

TEST(MeshObj, PentagonWithoutUvsIsAFan) {
  test::TempDir dir;
  test::write_text(dir / "penta.obj",
                   "v 0 0 0\nv 1 0 0\nv 2 1 0\nv 1 2 0\nv 0 1 0\nvt 0 0\nvn 0 0 1\n"
                   "f 1//1 2//1 3//1 4//1 5//1\nf 1 2 3\n");
  const Mesh mesh = read_obj(dir / "penta.obj");
  Triangles faces(4, 3);
  faces << 0, 1, 2, 0, 2, 3, 0, 3, 4, 0, 1, 2;
  EXPECT_EQ(mesh.faces, faces);
  EXPECT_FALSE(mesh.has_uvs());  // the vt is used by no face
  EXPECT_EQ(mesh.uv_faces.rows(), 0);
  EXPECT_EQ(mesh.triangle_polygon, (std::vector<int32_t>{0, 0, 0, 1}));

  write_obj(mesh, dir / "again.obj");
  expect_same_mesh(read_obj(dir / "again.obj"), mesh);
}

TEST(MeshObj, OutOfRangeIndexNamesFileAndLine) {
  test::TempDir dir;
  const auto file = dir / "bad_index.obj";
  test::write_text(file, "v 0 0 0\nv 1 0 0\nv 0 1 0\n\nf 1 2 4\n");
  const std::string message = error_message([&] { read_obj(file); });
  EXPECT_NE(message.find(file.string()), std::string::npos) << message;
  EXPECT_NE(message.find("line 5"), std::string::npos) << message;
  EXPECT_NE(message.find("vertex index 4 is out of range"), std::string::npos) << message;

  test::write_text(file, "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 -4\n");
  EXPECT_NE(error_message([&] { read_obj(file); }).find("line 4"), std::string::npos);
  test::write_text(file, "v 0 0 0\nv 1 0 0\nv 0 1 0\nvt 0 0\nf 1/1 2/2 3/1\n");
  EXPECT_NE(error_message([&] { read_obj(file); }).find("texture coordinate index 2"), std::string::npos);
}

TEST(MeshObj, MalformedInputNamesFileAndLine) {
  test::TempDir dir;
  const auto file = dir / "malformed.obj";
  test::write_text(file, "v 0 0 0\nv 1 0x 0\n");
  std::string message = error_message([&] { read_obj(file); });
  EXPECT_NE(message.find(file.string() + ": line 2: malformed number '0x'"), std::string::npos) << message;

  test::write_text(file, "v 0 0\n");
  EXPECT_NE(error_message([&] { read_obj(file); }).find("line 1: missing z"), std::string::npos);
  test::write_text(file, "v 0 0 0\nv 1 0 0\nv 0 1 0\nvt 0 0\nf 1/1 2 3\n");
  EXPECT_NE(error_message([&] { read_obj(file); }).find("line 5"), std::string::npos);
  test::write_text(file, "v 0 0 0\nv 1 0 0\nf 1 2\n");
  EXPECT_NE(error_message([&] { read_obj(file); }).find("line 3: face with 2 corners"), std::string::npos);
  message = error_message([&] { read_obj(dir / "missing.obj"); });
  EXPECT_NE(message.find("missing.obj"), std::string::npos) << message;
}

TEST(MeshPly, ReadsAsciiWithOtherPropertiesAndElements) {
  test::TempDir dir;
  test::write_text(dir / "ascii.ply",
                   "ply\r\nformat ascii 1.0\r\ncomment from a scanner\r\n"
                   "element vertex 4\r\nproperty double x\r\nproperty float nx\r\n"
                   "property float y\r\nproperty float z\r\nproperty list uchar int extra\r\n"
                   "element face 2\r\nproperty uchar flags\r\nproperty list uchar uint vertex_indices\r\n"
                   "property list uchar float texcoord\r\n"
                   "element edge 1\r\nproperty int vertex1\r\nproperty int vertex2\r\n"
                   "end_header\r\n"
                   "0 9 0 0 0\r\n1 9 0 0 2 7 7\r\n1 9 1 0 0\r\n0.25 9 1 0 1 5\r\n"
                   "3 4 0 1 2 3 8 0 0 1 0 1 1 0 1\r\n"
                   "0 3 0 2 1 6 0 0 1 1 0.5 0\r\n"
                   "0 1\r\n");
  const Mesh mesh = read_ply(dir / "ascii.ply");
  Vertices positions(4, 3);
  positions << 0, 0, 0, 1, 0, 0, 1, 1, 0, 0.25f, 1, 0;
  EXPECT_EQ(mesh.positions, positions);
  Triangles faces(3, 3);
  faces << 0, 1, 2, 0, 2, 3, 0, 2, 1;
  EXPECT_EQ(mesh.faces, faces);
  EXPECT_EQ(mesh.triangle_polygon, (std::vector<int32_t>{0, 0, 1}));
  // (0,0) and (1,1) are shared by both faces: the rebuilt UV array has each once.
  UVs uvs(5, 2);
  uvs << 0, 0, 1, 0, 1, 1, 0, 1, 0.5f, 0;
  EXPECT_EQ(mesh.uvs, uvs);
  Triangles uv_faces(3, 3);
  uv_faces << 0, 1, 2, 0, 2, 3, 0, 2, 4;
  EXPECT_EQ(mesh.uv_faces, uv_faces);
}

TEST(MeshPly, BadInputNamesFile) {
  test::TempDir dir;
  const auto file = dir / "bad.ply";
  test::write_text(file, "not a ply\n");
  EXPECT_NE(error_message([&] { read_ply(file); }).find(file.string() + ": is not a PLY file"), std::string::npos);
  test::write_text(file, "ply\nformat binary_big_endian 1.0\nend_header\n");
  EXPECT_NE(error_message([&] { read_ply(file); }).find("binary_big_endian"), std::string::npos);
  test::write_text(file,
                   "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\n"
                   "element face 1\nproperty list uchar int vertex_indices\nend_header\n0 0 0\n1 0 0\n0 1 0\n3 0 1 3\n");
  std::string message = error_message([&] { read_ply(file); });
  EXPECT_NE(message.find(file.string()), std::string::npos) << message;
  EXPECT_NE(message.find("out of range"), std::string::npos) << message;
  test::write_text(file,
                   "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\n"
                   "end_header\n0 0 0\n1 0 0\n0 1\n");
  EXPECT_NE(error_message([&] { read_ply(file); }).find("ends early"), std::string::npos);
  // Counts no body could hold (found by fuzzing: the reader reserved or looped for them).
  test::write_text(file, "ply\nformat ascii 1.0\nelement vertex 444444444444\nproperty float x\nproperty float y\n"
                         "property float z\nend_header\n0 0 0\n");
  message = error_message([&] { read_ply(file); });
  EXPECT_NE(message.find("PLY element 'vertex' declares 444444444444 items, more than the file's 6 bytes"),
            std::string::npos)
      << message;
  test::write_text(file, "ply\nformat ascii 1.0\nelement nothing 444444444444\nend_header\n");
  message = error_message([&] { read_ply(file); });
  EXPECT_NE(message.find("PLY element 'nothing' has 444444444444 items but no properties"), std::string::npos)
      << message;
}

TEST(MeshBin, RoundTripAndCountChecks) {
  test::TempDir dir;
  Vertices vertices(3, 3);
  vertices << 1.5f, -2.0f, 1e-30f, 0.1f, 0.2f, 0.3f, 7, 8, 9;
  write_vertices_bin(vertices, dir / "frame.bin");
  EXPECT_EQ(std::filesystem::file_size(dir / "frame.bin"), 36u);
  EXPECT_EQ(read_vertices_bin(dir / "frame.bin"), vertices);
  EXPECT_EQ(read_vertices_bin(dir / "frame.bin", 3), vertices);

  const std::string message = error_message([&] { read_vertices_bin(dir / "frame.bin", 7306); });
  EXPECT_NE(message.find((dir / "frame.bin").string()), std::string::npos) << message;
  EXPECT_NE(message.find("expected 7306 vertices, found 3"), std::string::npos) << message;

  test::write_text(dir / "odd.bin", std::string(40, '\0'));
  const std::string odd = error_message([&] { read_vertices_bin(dir / "odd.bin"); });
  EXPECT_NE(odd.find("odd.bin: size 40 bytes is not a multiple of 12"), std::string::npos) << odd;
}

TEST(MeshValidate, NamesSourceAndProblem) {
  Mesh mesh = seam_mesh();
  EXPECT_NO_THROW(mesh.validate("seam"));
  mesh.uv_faces(3, 2) = 8;
  EXPECT_NE(error_message([&] { mesh.validate("seam"); }).find("seam: UV face 3 refers to UV 8"), std::string::npos);
  mesh = seam_mesh();
  mesh.triangle_polygon.pop_back();
  EXPECT_THROW(mesh.validate("seam"), Error);
  mesh.triangle_polygon.clear();  // every triangle its own polygon
  EXPECT_NO_THROW(mesh.validate("seam"));
  mesh.faces(0, 0) = -1;
  EXPECT_THROW(mesh.validate("seam"), Error);
}

TEST(MeshNormals, AreaWeightedAndZeroForIsolatedVertices) {
  Mesh mesh;
  mesh.positions.resize(5, 3);
  // Vertex 0 is shared by a triangle of area 2 facing +z and one of area 1 facing -y.
  mesh.positions << 0, 0, 0, 2, 0, 0, 0, 2, 0, 0, 0, 1, 5, 5, 5;
  mesh.faces.resize(2, 3);
  mesh.faces << 0, 1, 2, 0, 1, 3;
  const Vertices normals = mesh.vertex_normals();
  const Eigen::RowVector3f expected = Eigen::RowVector3f(0, -1, 2).normalized();
  EXPECT_LT((normals.row(0) - expected).norm(), 1e-6f);
  EXPECT_LT((normals.row(2) - Eigen::RowVector3f(0, 0, 1)).norm(), 1e-6f);
  EXPECT_LT((normals.row(3) - Eigen::RowVector3f(0, -1, 0)).norm(), 1e-6f);
  EXPECT_EQ(normals.row(4), Eigen::RowVector3f::Zero());
}

TEST(MeshIct, NeutralLoadsAndRoundTrips) {
  TEGA_REQUIRE_ICT_FACEKIT(ict);
  const Mesh neutral = read_obj(ict / "generic_neutral_mesh.obj");
  EXPECT_EQ(neutral.num_vertices(), 26719);
  EXPECT_EQ(neutral.uvs.rows(), 28911);
  // 25836 quads and 548 triangles.
  EXPECT_EQ(neutral.num_faces(), 2 * 25836 + 548);
  EXPECT_EQ(neutral.triangle_polygon.back(), 26383);
  // Centimetres: a head is about 25 cm across.
  const float width = neutral.positions.col(0).maxCoeff() - neutral.positions.col(0).minCoeff();
  EXPECT_GT(width, 20.0f);
  EXPECT_LT(width, 30.0f);

  test::TempDir dir;
  write_obj(neutral, dir / "neutral.obj");
  expect_same_mesh(read_obj(dir / "neutral.obj"), neutral);

  write_ply(neutral, dir / "neutral.ply");
  const Mesh ply = read_ply(dir / "neutral.ply");
  EXPECT_EQ(ply.positions, neutral.positions);
  EXPECT_EQ(ply.faces, neutral.faces);
  EXPECT_EQ(ply.triangle_polygon, neutral.triangle_polygon);
  EXPECT_EQ(corner_uvs(ply), corner_uvs(neutral));
  EXPECT_LE(ply.uvs.rows(), neutral.uvs.rows());
}

}  // namespace
}  // namespace tega
