// Stanford PLY, ASCII or binary little-endian. UVs travel as MeshLab does:
// a per-face "texcoord" list of 2 floats per corner, which keeps UV seams
// (a vertex may have a different UV in every face around it).
//
// Written here rather than through OpenMesh's PLY reader and writer, which
// tega links (tega/core/openmesh.h), because:
//  - OpenMesh reads MeshLab's per-face `texcoord` list only as a custom
//    property (Options::Custom); without it, its reader misparses the face
//    element: it drops faces (2 in, 1 out) or fails on a binary file;
//  - the corner order of that list is only recoverable through where OpenMesh
//    happens to start each face's halfedge loop;
//  - its reader is slower (ICT-FaceKit's template: 68 ms against 24 ms;
//    1M triangles: 1.49 s against 1.27 s; bench/mesh_io);
//  - it keeps no polygon numbers, refuses non-manifold faces by duplicating
//    vertices, and reports errors as `false` plus a line on stderr.

#include <bit>
#include <cctype>
#include <charconv>
#include <cstring>
#include <limits>
#include <string>
#include <string_view>
#include <unordered_map>

#include "mesh_io.h"
#include "tega/core/error.h"
#include "tega/core/files.h"
#include "tega/core/mesh.h"

namespace tega {

namespace {

enum class PlyType { I8, U8, I16, U16, I32, U32, F32, F64 };

struct PlyProperty {
  std::string name;
  PlyType type = PlyType::F32;  // of the values (list entries for a list)
  bool is_list = false;
  PlyType count_type = PlyType::U8;
};

struct PlyElement {
  std::string name;
  int64_t count = 0;
  std::vector<PlyProperty> properties;

  int find(std::string_view property) const {
    for (size_t i = 0; i < properties.size(); ++i) {
      if (properties[i].name == property) return static_cast<int>(i);
    }
    return -1;
  }
};

struct PlyHeader {
  bool binary = false;
  std::vector<PlyElement> elements;
  size_t body_offset = 0;
};

int type_size(PlyType type) {
  switch (type) {
    case PlyType::I8:
    case PlyType::U8: return 1;
    case PlyType::I16:
    case PlyType::U16: return 2;
    case PlyType::I32:
    case PlyType::U32:
    case PlyType::F32: return 4;
    case PlyType::F64: return 8;
  }
  return 0;
}

std::vector<std::string_view> split_words(std::string_view line) {
  std::vector<std::string_view> words;
  size_t i = 0;
  while (i < line.size()) {
    while (i < line.size() && (line[i] == ' ' || line[i] == '\t' || line[i] == '\r')) ++i;
    size_t j = i;
    while (j < line.size() && line[j] != ' ' && line[j] != '\t' && line[j] != '\r') ++j;
    if (j > i) words.push_back(line.substr(i, j - i));
    i = j;
  }
  return words;
}

PlyType parse_type(const std::filesystem::path& file, std::string_view name) {
  static const std::pair<std::string_view, PlyType> kNames[] = {
      {"char", PlyType::I8},    {"int8", PlyType::I8},     {"uchar", PlyType::U8},   {"uint8", PlyType::U8},
      {"short", PlyType::I16},  {"int16", PlyType::I16},   {"ushort", PlyType::U16}, {"uint16", PlyType::U16},
      {"int", PlyType::I32},    {"int32", PlyType::I32},   {"uint", PlyType::U32},   {"uint32", PlyType::U32},
      {"float", PlyType::F32},  {"float32", PlyType::F32}, {"double", PlyType::F64}, {"float64", PlyType::F64}};
  for (const auto& [n, type] : kNames) {
    if (n == name) return type;
  }
  throw Error(file, "unknown PLY property type '" + std::string(name) + "'");
}

PlyHeader parse_header(const std::filesystem::path& file, std::string_view text) {
  PlyHeader header;
  size_t start = 0;
  bool first = true, has_format = false;
  for (;;) {
    const size_t end = text.find('\n', start);
    if (end == std::string_view::npos) throw Error(file, first ? "is not a PLY file" : "PLY header has no end_header");
    const std::string_view line = text.substr(start, end - start);
    const std::vector<std::string_view> words = split_words(line);
    start = end + 1;
    if (first) {
      if (words.size() != 1 || words[0] != "ply") throw Error(file, "is not a PLY file");
      first = false;
      continue;
    }
    if (words.empty() || words[0] == "comment" || words[0] == "obj_info") continue;
    if (words[0] == "end_header") break;
    if (words[0] == "format" && words.size() == 3) {
      if (words[1] == "ascii") {
        header.binary = false;
      } else if (words[1] == "binary_little_endian") {
        header.binary = true;
      } else {
        throw Error(file, "unsupported PLY format '" + std::string(words[1]) +
                              "' (ascii and binary_little_endian are read)");
      }
      has_format = true;
    } else if (words[0] == "element" && words.size() == 3) {
      PlyElement element;
      element.name = words[1];
      const auto [ptr, ec] = std::from_chars(words[2].data(), words[2].data() + words[2].size(), element.count);
      if (ec != std::errc{} || element.count < 0) {
        throw Error(file, "bad PLY element count '" + std::string(words[2]) + "'");
      }
      header.elements.push_back(std::move(element));
    } else if (words[0] == "property" && !header.elements.empty() && (words.size() == 3 || words.size() == 5)) {
      PlyProperty property;
      if (words.size() == 5) {
        if (words[1] != "list") throw Error(file, "bad PLY property line");
        property.is_list = true;
        property.count_type = parse_type(file, words[2]);
        property.type = parse_type(file, words[3]);
        property.name = words[4];
      } else {
        property.type = parse_type(file, words[1]);
        property.name = words[2];
      }
      header.elements.back().properties.push_back(std::move(property));
    } else {
      throw Error(file, "bad PLY header line '" + std::string(line) + "'");
    }
  }
  if (!has_format) throw Error(file, "PLY header has no format line");
  header.body_offset = start;
  return header;
}

// Values of a binary little-endian body, in file order.
class BinarySource {
 public:
  BinarySource(const std::filesystem::path& file, std::string_view body) : file_(file), body_(body) {}

  double next(PlyType type) {
    const size_t size = type_size(type);
    if (at_ + size > body_.size()) throw Error(file_, "PLY body ends early");
    const char* p = body_.data() + at_;
    at_ += size;
    switch (type) {
      case PlyType::I8: return load<int8_t>(p);
      case PlyType::U8: return load<uint8_t>(p);
      case PlyType::I16: return load<int16_t>(p);
      case PlyType::U16: return load<uint16_t>(p);
      case PlyType::I32: return load<int32_t>(p);
      case PlyType::U32: return load<uint32_t>(p);
      case PlyType::F32: return load<float>(p);
      case PlyType::F64: return load<double>(p);
    }
    return 0;
  }

 private:
  template <typename T>
  static double load(const char* p) {
    T value;
    std::memcpy(&value, p, sizeof value);
    return static_cast<double>(value);
  }

  const std::filesystem::path& file_;
  std::string_view body_;
  size_t at_ = 0;
};

// Values of an ASCII body, in file order (line breaks carry no meaning).
class AsciiSource {
 public:
  AsciiSource(const std::filesystem::path& file, std::string_view body) : file_(file), body_(body) {}

  double next(PlyType type) {
    while (at_ < body_.size() && std::isspace(static_cast<unsigned char>(body_[at_]))) ++at_;
    size_t end = at_;
    while (end < body_.size() && !std::isspace(static_cast<unsigned char>(body_[end]))) ++end;
    if (end == at_) throw Error(file_, "PLY body ends early");
    const char* first = body_.data() + at_;
    const char* last = body_.data() + end;
    at_ = end;
    // Floats parse as floats, so that what a float property says is read exactly.
    if (type == PlyType::F32) return parse<float>(first, last);
    if (type == PlyType::F64) return parse<double>(first, last);
    return static_cast<double>(parse<int64_t>(first, last));
  }

 private:
  template <typename T>
  T parse(const char* first, const char* last) const {
    T value{};
    const auto [ptr, ec] = std::from_chars(first, last, value);
    if (ec != std::errc{} || ptr != last) {
      throw Error(file_, "malformed number '" + std::string(first, last) + "' in the PLY body");
    }
    return value;
  }

  const std::filesystem::path& file_;
  std::string_view body_;
  size_t at_ = 0;
};

template <class Source>
Mesh read_body(const std::filesystem::path& file, const PlyHeader& header, Source& source) {
  std::vector<float> positions, uvs;
  std::vector<int32_t> faces, uv_faces, triangle_polygon;
  std::unordered_map<uint64_t, int32_t> uv_index;  // (u, v) bit patterns -> index in uvs
  bool has_texcoord = false;
  std::vector<int32_t> corners, corner_uvs;
  std::vector<float> texcoords;
  int32_t num_polygons = 0;

  const auto list_length = [&](const PlyProperty& property) {
    const double n = source.next(property.count_type);
    if (n < 0) throw Error(file, "negative PLY list length");
    return static_cast<int64_t>(n);
  };

  for (const PlyElement& element : header.elements) {
    if (element.name == "vertex") {
      const int xyz[3] = {element.find("x"), element.find("y"), element.find("z")};
      for (int i : xyz) {
        if (i < 0 || element.properties[i].is_list) throw Error(file, "PLY vertices need scalar x, y and z");
      }
      positions.reserve(static_cast<size_t>(element.count) * 3);
      float values[3] = {};
      for (int64_t item = 0; item < element.count; ++item) {
        for (size_t p = 0; p < element.properties.size(); ++p) {
          const PlyProperty& property = element.properties[p];
          if (property.is_list) {
            for (int64_t n = list_length(property); n > 0; --n) source.next(property.type);
            continue;
          }
          const double value = source.next(property.type);
          for (int axis = 0; axis < 3; ++axis) {
            if (xyz[axis] == static_cast<int>(p)) values[axis] = static_cast<float>(value);
          }
        }
        positions.insert(positions.end(), values, values + 3);
      }
    } else if (element.name == "face") {
      int vertex_indices = element.find("vertex_indices");
      if (vertex_indices < 0) vertex_indices = element.find("vertex_index");
      const int texcoord = element.find("texcoord");
      if (vertex_indices < 0 || !element.properties[vertex_indices].is_list) {
        throw Error(file, "PLY faces need a vertex_indices list");
      }
      has_texcoord = texcoord >= 0;
      for (int64_t item = 0; item < element.count; ++item) {
        corners.clear();
        texcoords.clear();
        for (size_t p = 0; p < element.properties.size(); ++p) {
          const PlyProperty& property = element.properties[p];
          const int64_t n = property.is_list ? list_length(property) : 1;
          for (int64_t k = 0; k < n; ++k) {
            const double value = source.next(property.type);
            if (static_cast<int>(p) == vertex_indices) {
              if (!(value >= 0 && value <= std::numeric_limits<int32_t>::max())) {
                throw Error(file, "PLY face " + std::to_string(item) + " has vertex index " + std::to_string(value));
              }
              corners.push_back(static_cast<int32_t>(value));
            } else if (static_cast<int>(p) == texcoord) {
              texcoords.push_back(static_cast<float>(value));
            }
          }
        }
        const size_t num_corners = corners.size();
        if (num_corners < 3) {
          throw Error(file, "PLY face " + std::to_string(item) + " has " + std::to_string(num_corners) + " corners");
        }
        if (has_texcoord) {
          if (texcoords.size() != 2 * num_corners) {
            throw Error(file, "PLY face " + std::to_string(item) + " has " + std::to_string(texcoords.size()) +
                                  " texcoord values for " + std::to_string(num_corners) + " corners");
          }
          corner_uvs.clear();
          for (size_t c = 0; c < num_corners; ++c) {
            const uint64_t key = (uint64_t{std::bit_cast<uint32_t>(texcoords[2 * c])} << 32) |
                                 std::bit_cast<uint32_t>(texcoords[2 * c + 1]);
            const auto [it, inserted] = uv_index.try_emplace(key, static_cast<int32_t>(uvs.size() / 2));
            if (inserted) uvs.insert(uvs.end(), {texcoords[2 * c], texcoords[2 * c + 1]});
            corner_uvs.push_back(it->second);
          }
        }
        for (size_t k = 1; k + 1 < num_corners; ++k) {
          for (size_t c : {size_t{0}, k, k + 1}) {
            faces.push_back(corners[c]);
            if (has_texcoord) uv_faces.push_back(corner_uvs[c]);
          }
          triangle_polygon.push_back(num_polygons);
        }
        ++num_polygons;
      }
    } else {
      for (int64_t item = 0; item < element.count; ++item) {
        for (const PlyProperty& property : element.properties) {
          const int64_t n = property.is_list ? list_length(property) : 1;
          for (int64_t k = 0; k < n; ++k) source.next(property.type);
        }
      }
    }
  }

  Mesh mesh;
  mesh.positions = Eigen::Map<const Vertices>(positions.data(), static_cast<Eigen::Index>(positions.size() / 3), 3);
  mesh.faces = Eigen::Map<const Triangles>(faces.data(), static_cast<Eigen::Index>(faces.size() / 3), 3);
  if (has_texcoord && !uvs.empty()) {
    mesh.uvs = Eigen::Map<const UVs>(uvs.data(), static_cast<Eigen::Index>(uvs.size() / 2), 2);
    mesh.uv_faces = Eigen::Map<const Triangles>(uv_faces.data(), static_cast<Eigen::Index>(uv_faces.size() / 3), 3);
  }
  mesh.triangle_polygon = std::move(triangle_polygon);
  mesh.validate(file);
  return mesh;
}

template <typename T>
void append_binary(std::string& out, T value) {
  char bytes[sizeof(T)];
  std::memcpy(bytes, &value, sizeof(T));
  out.append(bytes, sizeof(T));
}

// Each element's count against what the body can hold, before anything is
// read or reserved: a damaged count would otherwise make the reader reserve
// terabytes or loop for ages over items that carry no data.
void check_counts(const std::filesystem::path& file, const PlyHeader& header, size_t body_bytes) {
  for (const PlyElement& element : header.elements) {
    if (element.count == 0) continue;
    if (element.properties.empty())
      throw Error(file, "PLY element '" + element.name + "' has " + std::to_string(element.count) +
                            " items but no properties");
    // Binary: at least each scalar or list length; ASCII: at least a character for each.
    int64_t bytes_per_item = 0;
    for (const PlyProperty& property : element.properties)
      bytes_per_item += header.binary ? type_size(property.is_list ? property.count_type : property.type) : 1;
    if (element.count > int64_t(body_bytes) / bytes_per_item)
      throw Error(file, "PLY element '" + element.name + "' declares " + std::to_string(element.count) +
                            " items, more than the file's " + std::to_string(body_bytes) + " bytes of data can hold");
  }
}

}  // namespace

Mesh read_ply(const std::filesystem::path& file) {
  const std::string text = read_text_file(file);
  const PlyHeader header = parse_header(file, text);
  const std::string_view body = std::string_view(text).substr(header.body_offset);
  check_counts(file, header, body.size());
  if (header.binary) {
    BinarySource source(file, body);
    return read_body(file, header, source);
  }
  AsciiSource source(file, body);
  return read_body(file, header, source);
}

void write_ply(const Mesh& mesh, const std::filesystem::path& file) {
  mesh.validate(file);
  const bool uvs = mesh.has_uvs();
  // List lengths are uchars: corners, and twice the corners for texcoord.
  const std::vector<detail::PolygonRun> runs = detail::polygon_runs(mesh, uvs ? 127 : 255);
  std::string out = "ply\nformat binary_little_endian 1.0\ncomment written by tega\n";
  out += "element vertex " + std::to_string(mesh.num_vertices()) + "\n";
  out += "property float x\nproperty float y\nproperty float z\n";
  out += "element face " + std::to_string(runs.size()) + "\n";
  out += "property list uchar int vertex_indices\n";
  if (uvs) out += "property list uchar float texcoord\n";
  out += "end_header\n";

  out.reserve(out.size() + static_cast<size_t>(mesh.num_vertices()) * 12 + runs.size() * (uvs ? 2 : 1) +
              static_cast<size_t>(mesh.num_faces()) * (uvs ? 36 : 12));
  out.append(reinterpret_cast<const char*>(mesh.positions.data()),
             static_cast<size_t>(mesh.positions.size()) * sizeof(float));
  for (const detail::PolygonRun& run : runs) {
    const auto corners = static_cast<uint8_t>(run.num_triangles + 2);
    const int32_t last = run.first_triangle + run.num_triangles;
    append_binary(out, corners);
    append_binary(out, mesh.faces(run.first_triangle, 0));
    append_binary(out, mesh.faces(run.first_triangle, 1));
    for (int32_t t = run.first_triangle; t < last; ++t) append_binary(out, mesh.faces(t, 2));
    if (uvs) {
      const auto uv = [&](int32_t t, int k) {
        append_binary(out, mesh.uvs(mesh.uv_faces(t, k), 0));
        append_binary(out, mesh.uvs(mesh.uv_faces(t, k), 1));
      };
      append_binary(out, static_cast<uint8_t>(2 * corners));
      uv(run.first_triangle, 0);
      uv(run.first_triangle, 1);
      for (int32_t t = run.first_triangle; t < last; ++t) uv(t, 2);
    }
  }
  write_text_atomic(file, out);
}

}  // namespace tega
