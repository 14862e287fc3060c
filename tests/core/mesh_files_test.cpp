// Meshes as other tools write them: MeshLab's PLY (ASCII and binary), an OBJ
// with UV seams as modellers export it, and the ICT-FaceKit template checked
// against OpenMesh's own reader.
#include <gtest/gtest.h>

#include <OpenMesh/Core/IO/MeshIO.hh>
#include <OpenMesh/Core/Mesh/PolyMesh_ArrayKernelT.hh>
#include <cstring>
#include <set>
#include <sstream>

#include "tega/core/files.h"
#include "tega/core/mesh.h"
#include "test_support.h"

namespace tega {
namespace {

// One polygon corner: its vertex and UV.
struct Corner {
  int32_t vertex;
  float u, v;
  bool operator==(const Corner&) const = default;
};

// Each polygon's corners, put back together from the fans the readers make.
std::vector<std::vector<Corner>> polygons(const Mesh& mesh) {
  std::vector<std::vector<Corner>> result;
  const auto corner = [&](Eigen::Index t, int k) {
    const int32_t uv = mesh.uv_faces(t, k);
    return Corner{mesh.faces(t, k), mesh.uvs(uv, 0), mesh.uvs(uv, 1)};
  };
  for (Eigen::Index t = 0; t < mesh.num_faces(); ++t) {
    if (t == 0 || mesh.triangle_polygon[t] != mesh.triangle_polygon[t - 1]) {
      result.push_back({corner(t, 0), corner(t, 1)});
    }
    result.back().push_back(corner(t, 2));
  }
  return result;
}

// Two triangles sharing the edge 0-2 with a UV seam along it, as MeshLab
// (VCG) writes a textured triangle mesh.
constexpr const char* kMeshLabHeader =
    "ply\n"
    "format %s 1.0\n"
    "comment VCGLIB generated\n"
    "comment TextureFile head.png\n"
    "element vertex 4\n"
    "property float x\n"
    "property float y\n"
    "property float z\n"
    "element face 2\n"
    "property list uchar int vertex_indices\n"
    "property list uchar float texcoord\n"
    "end_header\n";
const float kPositions[4][3] = {{0, 0, 0}, {1, 0, 0.5f}, {1, 1, 0}, {0, 1, -0.25f}};
const int32_t kFaces[2][3] = {{0, 1, 2}, {0, 2, 3}};
const float kTexcoords[2][6] = {{0.1f, 0.1f, 0.4f, 0.1f, 0.4f, 0.4f}, {0.6f, 0.6f, 0.9f, 0.9f, 0.6f, 0.9f}};

std::string meshlab_header(const char* format) {
  char header[1024];
  std::snprintf(header, sizeof header, kMeshLabHeader, format);
  return header;
}

void expect_meshlab_fixture(const Mesh& mesh) {
  ASSERT_EQ(mesh.num_vertices(), 4);
  for (int v = 0; v < 4; ++v) {
    EXPECT_EQ(mesh.positions.row(v), Eigen::RowVector3f(kPositions[v][0], kPositions[v][1], kPositions[v][2]));
  }
  const std::vector<std::vector<Corner>> expected = {
      {{0, 0.1f, 0.1f}, {1, 0.4f, 0.1f}, {2, 0.4f, 0.4f}},
      {{0, 0.6f, 0.6f}, {2, 0.9f, 0.9f}, {3, 0.6f, 0.9f}}};
  EXPECT_EQ(polygons(mesh), expected);
  // Vertices 0 and 2 are on the seam: two UVs each, six UVs in all.
  EXPECT_EQ(mesh.uvs.rows(), 6);
}

TEST(MeshLabPly, AsciiReadsAndRoundTrips) {
  test::TempDir dir;
  std::ostringstream text;
  text << meshlab_header("ascii");
  for (const auto& p : kPositions) text << p[0] << ' ' << p[1] << ' ' << p[2] << '\n';
  for (int f = 0; f < 2; ++f) {
    text << "3 " << kFaces[f][0] << ' ' << kFaces[f][1] << ' ' << kFaces[f][2] << " 6";
    for (float t : kTexcoords[f]) text << ' ' << t;
    text << '\n';
  }
  test::write_text(dir / "meshlab.ply", text.str());
  const Mesh mesh = read_ply(dir / "meshlab.ply");
  expect_meshlab_fixture(mesh);

  write_ply(mesh, dir / "again.ply");
  const Mesh again = read_ply(dir / "again.ply");
  EXPECT_EQ(again.positions, mesh.positions);
  EXPECT_EQ(again.faces, mesh.faces);
  EXPECT_EQ(again.uvs, mesh.uvs);
  EXPECT_EQ(again.uv_faces, mesh.uv_faces);
  // What tega writes, MeshLab's convention again: the texcoord list per face.
  const std::string written = read_text_file(dir / "again.ply");
  EXPECT_NE(written.find("property list uchar float texcoord\n"), std::string::npos);
}

TEST(MeshLabPly, BinaryLittleEndianReads) {
  test::TempDir dir;
  std::string bytes = meshlab_header("binary_little_endian");
  const auto append = [&](const void* data, size_t size) { bytes.append(static_cast<const char*>(data), size); };
  for (const auto& p : kPositions) append(p, sizeof p);
  for (int f = 0; f < 2; ++f) {
    const uint8_t corners = 3, uvs = 6;
    append(&corners, 1);
    append(kFaces[f], sizeof kFaces[f]);
    append(&uvs, 1);
    append(kTexcoords[f], sizeof kTexcoords[f]);
  }
  write_text_atomic(dir / "meshlab.ply", bytes);
  expect_meshlab_fixture(read_ply(dir / "meshlab.ply"));
}

TEST(MeshObjFile, ModellerCubeKeepsSeamsUvNumbersAndQuads) {
  // A cube as modellers export it: normals, smoothing groups, a material, and
  // UVs cut along seams (vertex 1 has three UVs: 1, 15 and 20).
  const std::string faces =
      "f 1/1/1 5/2/1 7/3/1 3/4/1\n"
      "f 4/5/2 3/4/2 7/3/2 8/6/2\n"
      "f 8/6/3 7/3/3 5/7/3 6/8/3\n"
      "f 6/8/4 2/9/4 4/10/4 8/11/4\n"
      "f 2/14/5 1/15/5 3/16/5 4/17/5\n"
      "f 6/18/6 5/19/6 1/20/6 2/9/6\n";
  std::string text = "# exported\nmtllib cube.mtl\no Cube\n";
  text += "v 1 1 -1\nv 1 -1 -1\nv 1 1 1\nv 1 -1 1\nv -1 1 -1\nv -1 -1 -1\nv -1 1 1\nv -1 -1 1\n";
  for (int t = 0; t < 20; ++t) text += "vt " + std::to_string(0.05 * t) + " " + std::to_string(1 - 0.03 * t) + "\n";
  for (int n = 0; n < 6; ++n) text += "vn 0 0 1\n";
  text += "usemtl skin\ns off\n" + faces;
  test::TempDir dir;
  test::write_text(dir / "cube.obj", text);

  const Mesh mesh = read_obj(dir / "cube.obj");
  EXPECT_EQ(mesh.num_vertices(), 8);
  EXPECT_EQ(mesh.uvs.rows(), 20);  // vt 12 and 13 are used by no face, and kept
  EXPECT_EQ(mesh.num_faces(), 12);
  std::set<int32_t> uvs_of_vertex_1;
  for (Eigen::Index t = 0; t < mesh.num_faces(); ++t) {
    for (int k = 0; k < 3; ++k) {
      if (mesh.faces(t, k) == 0) uvs_of_vertex_1.insert(mesh.uv_faces(t, k));
    }
  }
  EXPECT_EQ(uvs_of_vertex_1, (std::set<int32_t>{0, 14, 19}));

  // Written back: the same quads with the same vertex and UV numbers.
  write_obj(mesh, dir / "again.obj");
  const std::string without_normals =
      "f 1/1 5/2 7/3 3/4\n"
      "f 4/5 3/4 7/3 8/6\n"
      "f 8/6 7/3 5/7 6/8\n"
      "f 6/8 2/9 4/10 8/11\n"
      "f 2/14 1/15 3/16 4/17\n"
      "f 6/18 5/19 1/20 2/9\n";
  const std::string written = read_text_file(dir / "again.obj");
  EXPECT_NE(written.find(without_normals), std::string::npos) << written;
  const Mesh again = read_obj(dir / "again.obj");
  EXPECT_EQ(again.positions, mesh.positions);
  EXPECT_EQ(again.uvs, mesh.uvs);
  EXPECT_EQ(again.uv_faces, mesh.uv_faces);
  EXPECT_EQ(again.triangle_polygon, mesh.triangle_polygon);
}

TEST(MeshIctTemplate, AgreesWithOpenMeshsReader) {
  TEGA_REQUIRE_ICT_FACEKIT(ict);
  const auto file = ict / "generic_neutral_mesh.obj";
  const Mesh mesh = read_obj(file);

  OpenMesh::PolyMesh_ArrayKernelT<> reference;
  reference.request_halfedge_texcoords2D();
  OpenMesh::IO::Options options = OpenMesh::IO::Options::FaceTexCoord;
  ASSERT_TRUE(OpenMesh::IO::read_mesh(reference, file.string(), options));
  ASSERT_EQ(mesh.num_vertices(), static_cast<int>(reference.n_vertices()));
  for (const auto vertex : reference.vertices()) {
    const auto& p = reference.point(vertex);
    ASSERT_EQ(mesh.positions.row(vertex.idx()), Eigen::RowVector3f(p[0], p[1], p[2])) << "vertex " << vertex.idx();
  }
  // The same polygons, in the same order, with the same UV at every corner
  // (OpenMesh may start a polygon's loop at another corner).
  const std::vector<std::vector<Corner>> ours = polygons(mesh);
  ASSERT_EQ(ours.size(), reference.n_faces());
  for (const auto face : reference.faces()) {
    std::vector<Corner> theirs;
    for (const auto halfedge : reference.fh_range(face)) {
      const auto& uv = reference.texcoord2D(halfedge);
      theirs.push_back({reference.to_vertex_handle(halfedge).idx(), uv[0], uv[1]});
    }
    const std::vector<Corner>& polygon = ours[face.idx()];
    ASSERT_EQ(polygon.size(), theirs.size()) << "polygon " << face.idx();
    const auto start = std::find_if(theirs.begin(), theirs.end(), [&](const Corner& c) { return c.vertex == polygon[0].vertex; });
    ASSERT_NE(start, theirs.end()) << "polygon " << face.idx();
    std::rotate(theirs.begin(), start, theirs.end());
    ASSERT_EQ(polygon, theirs) << "polygon " << face.idx();
  }
}

}  // namespace
}  // namespace tega
