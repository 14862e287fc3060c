// bench/mesh_io: read and write times of core's OBJ, PLY and .bin mesh I/O for
// the ICT-FaceKit template and a generated mesh of about a million triangles
// (quads with UVs), and, beside them, OpenMesh's own OBJ and PLY readers on the
// same files (with what tega needs, and at their fastest) (docs/meshes-and-images.md says why core keeps its readers).
#include <CLI/CLI.hpp>
#include <OpenMesh/Core/IO/MeshIO.hh>
#include <OpenMesh/Core/Mesh/PolyMesh_ArrayKernelT.hh>
#include <OpenMesh/Core/Mesh/TriMesh_ArrayKernelT.hh>
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <functional>
#include <string>
#include <vector>

#include "tega/core/files.h"
#include "tega/core/mesh.h"

namespace fs = std::filesystem;
using namespace tega;

namespace {

// A grid of quads, fanned into triangles, with one UV per vertex.
Mesh quad_grid(int columns, int rows) {
  Mesh mesh;
  const int width = columns + 1;
  mesh.positions.resize(width * (rows + 1), 3);
  mesh.uvs.resize(width * (rows + 1), 2);
  for (int y = 0; y <= rows; ++y) {
    for (int x = 0; x <= columns; ++x) {
      mesh.positions.row(y * width + x) << 0.001f * x, 0.001f * y, 0.0001f * ((x * 7 + y * 13) % 17);
      mesh.uvs.row(y * width + x) << float(x) / columns, float(y) / rows;
    }
  }
  mesh.faces.resize(2 * columns * rows, 3);
  mesh.triangle_polygon.resize(2 * columns * rows);
  for (int y = 0; y < rows; ++y) {
    for (int x = 0; x < columns; ++x) {
      const int quad = y * columns + x, a = y * width + x, b = a + 1, c = a + width + 1, d = a + width;
      mesh.faces.row(2 * quad) << a, b, c;
      mesh.faces.row(2 * quad + 1) << a, c, d;
      mesh.triangle_polygon[2 * quad] = mesh.triangle_polygon[2 * quad + 1] = quad;
    }
  }
  mesh.uv_faces = mesh.faces;
  return mesh;
}

// The median wall time of `runs` calls, in milliseconds.
double median_ms(int runs, const std::function<void()>& action) {
  std::vector<double> times;
  for (int i = 0; i < runs; ++i) {
    const auto start = std::chrono::steady_clock::now();
    action();
    times.push_back(std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count());
  }
  std::sort(times.begin(), times.end());
  return times[times.size() / 2];
}

// OpenMesh's reader with what tega needs from a file: polygons and corner UVs
// (for PLY, MeshLab's per-face texcoord list, which OpenMesh reads as a custom property).
bool read_with_openmesh(const fs::path& file) {
  OpenMesh::PolyMesh_ArrayKernelT<> mesh;
  mesh.request_halfedge_texcoords2D();
  OpenMesh::IO::Options options = OpenMesh::IO::Options::FaceTexCoord;
  if (file.extension() == ".ply") options += OpenMesh::IO::Options::Custom;
  return OpenMesh::IO::read_mesh(mesh, file.string(), options);
}

// OpenMesh's reader at its fastest: triangles only, no UVs, no custom properties.
bool read_bare_with_openmesh(const fs::path& file) {
  OpenMesh::TriMesh_ArrayKernelT<> mesh;
  return OpenMesh::IO::read_mesh(mesh, file.string());
}

// The median time of `read`, or why there is none.
std::string openmesh_read_ms(int runs, const fs::path& file, bool (*read)(const fs::path&)) {
  if (!read(file)) return "fails";
  char text[32];
  std::snprintf(text, sizeof text, "%.1f", median_ms(runs, [&] { read(file); }));
  return text;
}

void bench(const char* name, const Mesh& mesh, const fs::path& dir, int runs) {
  std::printf("\n%s: %d vertices, %d UVs, %d triangles (median of %d runs, ms)\n", name, mesh.num_vertices(),
              static_cast<int>(mesh.uvs.rows()), mesh.num_faces(), runs);
  std::printf("| format | write | read | OpenMesh read | OpenMesh read, bare TriMesh |\n"
              "| --- | ---: | ---: | ---: | ---: |\n");
  for (const char* extension : {".obj", ".ply"}) {
    const fs::path file = dir / (std::string("mesh") + extension);
    const double write = median_ms(runs, [&] { write_mesh(mesh, file); });
    const double read = median_ms(runs, [&] { read_mesh(file); });
    const std::string openmesh = openmesh_read_ms(runs, file, read_with_openmesh);
    const std::string bare = openmesh_read_ms(runs, file, read_bare_with_openmesh);
    std::printf("| %s | %.1f | %.1f | %s | %s |\n", extension + 1, write, read, openmesh.c_str(), bare.c_str());
  }
  const fs::path bin = dir / "mesh.bin";
  const double write = median_ms(runs, [&] { write_vertices_bin(mesh.positions, bin); });
  const double read = median_ms(runs, [&] { read_vertices_bin(bin, mesh.num_vertices()); });
  std::printf("| bin (positions) | %.1f | %.1f | | |\n", write, read);
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"Mesh read and write times: OBJ, PLY, .bin."};
  std::string ict = "../shared/data/ict-facekit/generic_neutral_mesh.obj";
  int columns = 708, rows = 707, runs = 5;
  std::string dir = (fs::temp_directory_path() / "tega-mesh-io-bench").string();
  app.add_option("--ict", ict, "ICT-FaceKit's neutral mesh.");
  app.add_option("--columns", columns, "Quads across the generated grid.");
  app.add_option("--rows", rows, "Quads down the generated grid.");
  app.add_option("--runs", runs, "Runs per measurement (the median is printed).");
  app.add_option("--dir", dir, "Where the files are written.");
  CLI11_PARSE(app, argc, argv);

  fs::create_directories(dir);
  if (fs::exists(ict)) {
    bench("ICT-FaceKit neutral", read_obj(ict), dir, runs);
  } else {
    std::printf("%s is absent: the ICT-FaceKit rows are skipped\n", ict.c_str());
  }
  bench("generated grid", quad_grid(columns, rows), dir, std::max(1, runs / 2));
  fs::remove_all(dir);
}
