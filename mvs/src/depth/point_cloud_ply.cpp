// fused.ply as COLMAP writes it (binary little-endian; x y z nx ny nz float,
// red green blue uchar). The reader takes any binary little-endian PLY whose
// first element is `vertex` with float or double x y z and, optionally,
// normals and uchar colours, so it also reads other tools' clouds.
#include <spdlog/fmt/fmt.h>

#include <cstring>
#include <sstream>

#include "binary_file.h"
#include "tega/core/error.h"
#include "tega/mvs/colmap_workspace.h"

namespace tega::mvs {
namespace {

struct Property {
  std::string name, type;
  size_t offset = 0;
};

size_t type_size(const std::string& type) {
  if (type == "char" || type == "uchar" || type == "int8" || type == "uint8") return 1;
  if (type == "short" || type == "ushort" || type == "int16" || type == "uint16") return 2;
  if (type == "int" || type == "uint" || type == "float" || type == "int32" || type == "uint32" || type == "float32")
    return 4;
  if (type == "double" || type == "float64") return 8;
  return 0;
}

bool is_real(const std::string& type) {
  return type == "float" || type == "float32" || type == "double" || type == "float64";
}

struct VertexLayout {
  size_t count = 0, stride = 0, data_offset = 0;
  std::vector<Property> properties;

  const Property* find(const std::string& name) const {
    for (const Property& p : properties)
      if (p.name == name) return &p;
    return nullptr;
  }
};

VertexLayout parse_header(const std::string& bytes, const std::filesystem::path& file) {
  const std::string end_marker = "end_header\n";
  const size_t end = bytes.find(end_marker);
  if (!bytes.starts_with("ply\n") || end == std::string::npos)
    throw Error(file, "bad header: not a PLY file (no \"ply\" line or no \"end_header\")");
  std::istringstream header(bytes.substr(0, end));
  VertexLayout layout;
  layout.data_offset = end + end_marker.size();
  bool in_vertex = false, seen_element = false;
  for (std::string line; std::getline(header, line);) {
    std::istringstream words(line);
    std::string keyword;
    words >> keyword;
    if (keyword == "format") {
      std::string format;
      words >> format;
      if (format != "binary_little_endian")
        throw Error(file, "bad header: format '" + format + "', only binary_little_endian is read");
    } else if (keyword == "element") {
      std::string name;
      words >> name;
      if (!seen_element && name != "vertex")
        throw Error(file, "bad header: the first element is '" + name + "', expected 'vertex'");
      in_vertex = !seen_element;
      seen_element = true;
      if (in_vertex && !(words >> layout.count)) throw Error(file, "bad header: the vertex count is missing");
    } else if (keyword == "property" && in_vertex) {
      Property property;
      words >> property.type >> property.name;
      const size_t size = type_size(property.type);
      if (size == 0)
        throw Error(file,
                    "bad header: vertex property '" + property.name + "' has unsupported type '" + property.type + "'");
      property.offset = layout.stride;
      layout.stride += size;
      layout.properties.push_back(property);
    }
  }
  if (!seen_element) throw Error(file, "bad header: no vertex element");
  for (const char* axis : {"x", "y", "z"}) {
    const Property* p = layout.find(axis);
    if (!p || !is_real(p->type))
      throw Error(file, fmt::format("bad header: no float or double vertex property '{}'", axis));
  }
  return layout;
}

double read_real(const char* record, const Property& property) {
  if (type_size(property.type) == 8) {
    double value;
    std::memcpy(&value, record + property.offset, sizeof value);
    return value;
  }
  float value;
  std::memcpy(&value, record + property.offset, sizeof value);
  return value;
}

}  // namespace

void write_point_cloud_ply(const OrientedPointCloud& cloud, const std::filesystem::path& file) {
  const size_t n = static_cast<size_t>(cloud.size());
  if (size_t(cloud.normals.rows()) != n || (cloud.colors.rows() != 0 && size_t(cloud.colors.rows()) != n))
    throw Error(file, fmt::format("cannot write a cloud of {} points with {} normals and {} colours", n,
                                  cloud.normals.rows(), cloud.colors.rows()));
  std::string bytes = fmt::format(
      "ply\nformat binary_little_endian 1.0\nelement vertex {}\n"
      "property float x\nproperty float y\nproperty float z\n"
      "property float nx\nproperty float ny\nproperty float nz\n"
      "property uchar red\nproperty uchar green\nproperty uchar blue\nend_header\n",
      n);
  constexpr size_t kRecordBytes = 6 * sizeof(float) + 3;
  const size_t data_offset = bytes.size();
  bytes.resize(data_offset + n * kRecordBytes);
  for (size_t i = 0; i < n; ++i) {
    char* record = bytes.data() + data_offset + i * kRecordBytes;
    std::memcpy(record, cloud.points.row(Eigen::Index(i)).data(), 3 * sizeof(float));
    std::memcpy(record + 3 * sizeof(float), cloud.normals.row(Eigen::Index(i)).data(), 3 * sizeof(float));
    // COLMAP's tools expect colours; a cloud without them is written black.
    const uint8_t black[3] = {0, 0, 0};
    std::memcpy(record + 6 * sizeof(float), cloud.colors.rows() ? cloud.colors.row(Eigen::Index(i)).data() : black, 3);
  }
  write_binary_file_atomic(file, bytes);
}

OrientedPointCloud read_point_cloud_ply(const std::filesystem::path& file) {
  const std::string bytes = read_binary_file(file);
  const VertexLayout layout = parse_header(bytes, file);
  const size_t available = bytes.size() - layout.data_offset;
  if (layout.stride == 0 || available / layout.stride < layout.count)
    throw Error(file, fmt::format("truncated data: {} vertices of {} bytes need {} bytes, found {}", layout.count,
                                  layout.stride, double(layout.count) * double(layout.stride), available));

  const Property* position[3] = {layout.find("x"), layout.find("y"), layout.find("z")};
  const Property* normal[3] = {layout.find("nx"), layout.find("ny"), layout.find("nz")};
  const Property* color[3] = {layout.find("red"), layout.find("green"), layout.find("blue")};
  const bool has_normals = normal[0] && normal[1] && normal[2];
  const bool has_colors = color[0] && color[1] && color[2];
  for (const Property* n : normal)
    if (has_normals && !is_real(n->type))
      throw Error(file, "bad header: normal property '" + n->name + "' is not float or double");
  for (const Property* c : color)
    if (has_colors && c->type != "uchar" && c->type != "uint8")
      throw Error(file, "bad header: colour property '" + c->name + "' is not uchar");

  OrientedPointCloud cloud;
  const Eigen::Index n = Eigen::Index(layout.count);
  cloud.points.resize(n, 3);
  cloud.normals.setZero(n, 3);
  if (has_colors) cloud.colors.resize(n, 3);
  for (Eigen::Index i = 0; i < n; ++i) {
    const char* record = bytes.data() + layout.data_offset + size_t(i) * layout.stride;
    for (int k = 0; k < 3; ++k) {
      cloud.points(i, k) = static_cast<float>(read_real(record, *position[k]));
      if (has_normals) cloud.normals(i, k) = static_cast<float>(read_real(record, *normal[k]));
      if (has_colors) cloud.colors(i, k) = static_cast<uint8_t>(record[color[k]->offset]);
    }
  }
  return cloud;
}

}  // namespace tega::mvs
