// Wavefront OBJ. The reader parses the whole file from memory with
// std::from_chars: blendshape models load dozens of multi-megabyte OBJs.
//
// Written here rather than through OpenMesh's OBJ reader and writer, which
// tega links (tega/core/openmesh.h), because OpenMesh cannot keep what tega's
// meshes promise (docs/meshes-and-images.md, bench/mesh_io):
//  - its reader is 5-9x slower (ICT-FaceKit's template: 298 ms against 35 ms,
//    and no faster into a bare TriMesh without UVs): two passes, a
//    std::stringstream per line;
//  - UVs come back per halfedge, so the file's `vt` numbering (and with it
//    `uv_faces` and the UV count) is lost; its writer renumbers them, sorted
//    by value;
//  - a face it cannot add (non-manifold) is retried on duplicated vertices,
//    which changes the vertex count that .bin meshes and blendshapes rely on;
//  - errors are a `false` and a line on stderr, not the file and line.

#include <charconv>
#include <limits>
#include <string>
#include <string_view>

#include "mesh_io.h"
#include "tega/core/error.h"
#include "tega/core/files.h"
#include "tega/core/mesh.h"

namespace tega {

namespace {

class ObjParser {
 public:
  ObjParser(const std::filesystem::path& file, std::string_view text) : file_(file), text_(text) {}

  Mesh parse() {
    size_t start = 0;
    while (start < text_.size()) {
      size_t end = text_.find('\n', start);
      if (end == std::string_view::npos) end = text_.size();
      ++line_number_;
      parse_line(text_.substr(start, end - start));
      start = end + 1;
    }
    return build();
  }

 private:
  [[noreturn]] void fail(const std::string& message) const {
    throw Error(file_, "line " + std::to_string(line_number_) + ": " + message);
  }

  static bool is_space(char c) { return c == ' ' || c == '\t' || c == '\r'; }

  // The next whitespace-separated token of the current line ("" at its end).
  std::string_view next_token() {
    size_t i = 0;
    while (i < rest_.size() && is_space(rest_[i])) ++i;
    size_t j = i;
    while (j < rest_.size() && !is_space(rest_[j])) ++j;
    const std::string_view token = rest_.substr(i, j - i);
    rest_ = rest_.substr(j);
    return token;
  }

  float parse_float(std::string_view token) {
    // from_chars rejects the leading '+' that some exporters write.
    if (!token.empty() && token.front() == '+') token.remove_prefix(1);
    float value = 0;
    const auto [end, ec] = std::from_chars(token.data(), token.data() + token.size(), value);
    if (ec != std::errc{} || end != token.data() + token.size()) {
      fail("malformed number '" + std::string(token) + "'");
    }
    return value;
  }

  float required_float(const char* what) {
    const std::string_view token = next_token();
    if (token.empty()) fail(std::string("missing ") + what);
    return parse_float(token);
  }

  // One index of a face corner; relative (negative) indices count back from
  // the last element defined so far. Returns a 0-based index.
  int32_t parse_index(std::string_view token, int32_t defined, const char* what) {
    int32_t index = 0;
    const auto [end, ec] = std::from_chars(token.data(), token.data() + token.size(), index);
    if (ec != std::errc{} || end != token.data() + token.size()) {
      fail("malformed " + std::string(what) + " index '" + std::string(token) + "'");
    }
    const int32_t resolved = index < 0 ? defined + index : index - 1;
    if (index == 0 || resolved < 0 || resolved >= defined) {
      fail(std::string(what) + " index " + std::to_string(index) + " is out of range (" + std::to_string(defined) +
           " defined so far)");
    }
    return resolved;
  }

  void parse_line(std::string_view line) {
    rest_ = line;
    const std::string_view keyword = next_token();
    if (keyword == "v") {
      // Extra values (w, or the vertex colours some tools append) are ignored.
      positions_.push_back(required_float("x"));
      positions_.push_back(required_float("y"));
      positions_.push_back(required_float("z"));
    } else if (keyword == "vt") {
      uvs_.push_back(required_float("u"));
      const std::string_view v = next_token();
      uvs_.push_back(v.empty() ? 0.0f : parse_float(v));
    } else if (keyword == "f") {
      parse_face();
    }
  }

  void parse_face() {
    corner_positions_.clear();
    corner_uvs_.clear();
    const auto num_positions = static_cast<int32_t>(positions_.size() / 3);
    const auto num_uvs = static_cast<int32_t>(uvs_.size() / 2);
    for (std::string_view token = next_token(); !token.empty(); token = next_token()) {
      // v, v/vt, v/vt/vn or v//vn.
      const size_t slash = token.find('/');
      corner_positions_.push_back(parse_index(token.substr(0, slash), num_positions, "vertex"));
      bool has_uv = false;
      if (slash != std::string_view::npos) {
        const std::string_view after = token.substr(slash + 1);
        const std::string_view uv = after.substr(0, after.find('/'));
        if (!uv.empty()) {
          corner_uvs_.push_back(parse_index(uv, num_uvs, "texture coordinate"));
          has_uv = true;
        }
      }
      const int mode = has_uv ? 1 : 0;
      if (uv_mode_ < 0) uv_mode_ = mode;
      if (mode != uv_mode_) fail("face corners mix with and without texture coordinates");
    }
    const auto n = static_cast<int32_t>(corner_positions_.size());
    if (n < 3) fail("face with " + std::to_string(n) + " corners");
    for (int32_t k = 1; k + 1 < n; ++k) {
      for (int32_t c : {0, k, k + 1}) {
        faces_.push_back(corner_positions_[c]);
        if (uv_mode_ == 1) uv_faces_.push_back(corner_uvs_[c]);
      }
      triangle_polygon_.push_back(num_polygons_);
    }
    ++num_polygons_;
  }

  Mesh build() {
    Mesh mesh;
    mesh.positions = Eigen::Map<const Vertices>(positions_.data(), static_cast<Eigen::Index>(positions_.size() / 3), 3);
    mesh.faces = Eigen::Map<const Triangles>(faces_.data(), static_cast<Eigen::Index>(faces_.size() / 3), 3);
    // UVs that no face uses would leave uv_faces empty beside a non-empty uvs.
    if (uv_mode_ == 1) {
      mesh.uvs = Eigen::Map<const UVs>(uvs_.data(), static_cast<Eigen::Index>(uvs_.size() / 2), 2);
      mesh.uv_faces = Eigen::Map<const Triangles>(uv_faces_.data(), static_cast<Eigen::Index>(uv_faces_.size() / 3), 3);
    }
    mesh.triangle_polygon = std::move(triangle_polygon_);
    mesh.validate(file_);
    return mesh;
  }

  const std::filesystem::path& file_;
  std::string_view text_;
  std::string_view rest_;  // what the current line has left to parse
  int line_number_ = 0;
  int uv_mode_ = -1;  // whether faces have texture coordinates (1) or not (0); -1 before the first face
  int32_t num_polygons_ = 0;
  std::vector<float> positions_, uvs_;
  std::vector<int32_t> faces_, uv_faces_, triangle_polygon_;
  std::vector<int32_t> corner_positions_, corner_uvs_;  // of the face being parsed
};

void append_float(std::string& out, float value) {
  char buffer[32];
  // Shortest representation that reads back to the same float.
  const auto [end, ec] = std::to_chars(buffer, buffer + sizeof buffer, value);
  out.append(buffer, end);
}

void append_int(std::string& out, int32_t value) {
  char buffer[16];
  const auto [end, ec] = std::to_chars(buffer, buffer + sizeof buffer, value);
  out.append(buffer, end);
}

}  // namespace

Mesh read_obj(const std::filesystem::path& file) {
  const std::string text = read_text_file(file);
  return ObjParser(file, text).parse();
}

void write_obj(const Mesh& mesh, const std::filesystem::path& file) {
  mesh.validate(file);
  std::string out;
  out.reserve(static_cast<size_t>(mesh.num_vertices()) * 36 + static_cast<size_t>(mesh.uvs.rows()) * 24 +
              static_cast<size_t>(mesh.num_faces()) * 40);
  out += "# written by tega\n";
  for (Eigen::Index v = 0; v < mesh.positions.rows(); ++v) {
    out += "v ";
    append_float(out, mesh.positions(v, 0));
    out += ' ';
    append_float(out, mesh.positions(v, 1));
    out += ' ';
    append_float(out, mesh.positions(v, 2));
    out += '\n';
  }
  for (Eigen::Index t = 0; t < mesh.uvs.rows(); ++t) {
    out += "vt ";
    append_float(out, mesh.uvs(t, 0));
    out += ' ';
    append_float(out, mesh.uvs(t, 1));
    out += '\n';
  }
  const bool uvs = mesh.has_uvs();
  const auto corner = [&](int32_t triangle, int k) {
    out += ' ';
    append_int(out, mesh.faces(triangle, k) + 1);
    if (uvs) {
      out += '/';
      append_int(out, mesh.uv_faces(triangle, k) + 1);
    }
  };
  for (const detail::PolygonRun& run : detail::polygon_runs(mesh, std::numeric_limits<int>::max())) {
    out += 'f';
    corner(run.first_triangle, 0);
    corner(run.first_triangle, 1);
    for (int32_t t = run.first_triangle; t < run.first_triangle + run.num_triangles; ++t) corner(t, 2);
    out += '\n';
  }
  write_text_atomic(file, out);
}

}  // namespace tega
