#include "tega/tools/gaussian_ply.h"

#include <bit>
#include <cmath>
#include <cstring>
#include <fstream>
#include <map>
#include <sstream>

#include "tega/core/error.h"
#include "tega/core/files.h"
#include "tega/trainer/render.h"

namespace tega::tools {

static_assert(std::endian::native == std::endian::little, "the PLY writer stores host floats as little-endian");

int GaussianCloud::sh_degree() const {
  const int64_t k = sh.size(1);
  for (int degree = 0; degree <= 3; ++degree)
    if ((degree + 1) * (degree + 1) == k) return degree;
  throw Error("a Gaussian cloud has " + std::to_string(k) + " SH coefficients, not 1, 4, 9 or 16");
}

at::Tensor GaussianCloud::covariances() const { return splat::covariance_from_scale_rotation(log_scale.exp(), rotation); }

at::Tensor GaussianCloud::opacities() const { return at::sigmoid(opacity_logit); }

GaussianCloud GaussianCloud::to(const at::Device& device, at::ScalarType dtype) const {
  const auto move = [&](const at::Tensor& t) { return t.to(device, dtype); };
  return {move(means), move(sh), move(opacity_logit), move(log_scale), move(rotation)};
}

std::vector<std::string> ply_property_names(int sh_degree) {
  std::vector<std::string> names{"x", "y", "z", "nx", "ny", "nz", "f_dc_0", "f_dc_1", "f_dc_2"};
  const int rest = 3 * ((sh_degree + 1) * (sh_degree + 1) - 1);
  for (int i = 0; i < rest; ++i) names.push_back("f_rest_" + std::to_string(i));
  names.push_back("opacity");
  for (int i = 0; i < 3; ++i) names.push_back("scale_" + std::to_string(i));
  for (int i = 0; i < 4; ++i) names.push_back("rot_" + std::to_string(i));
  return names;
}

void write_gaussian_ply(const GaussianCloud& cloud, const std::filesystem::path& file) {
  const GaussianCloud c = cloud.to(at::kCPU, at::kFloat);
  const int64_t n = c.size();
  // One row per Gaussian in file order; f_rest goes channel-major ([N,3,K-1]).
  const at::Tensor rest = c.sh.slice(1, 1).transpose(1, 2).reshape({n, -1});
  const at::Tensor rows = at::cat({c.means, at::zeros({n, 3}, at::kFloat), c.sh.select(1, 0), rest,
                                   c.opacity_logit.view({n, 1}), c.log_scale, c.rotation},
                                  1)
                              .contiguous();
  const auto names = ply_property_names(c.sh_degree());
  TORCH_INTERNAL_ASSERT(rows.size(1) == static_cast<int64_t>(names.size()));

  std::ostringstream header;
  header << "ply\nformat binary_little_endian 1.0\ncomment written by tega export (3D Gaussian Splatting layout)\n"
         << "element vertex " << n << "\n";
  for (const auto& name : names) header << "property float " << name << "\n";
  header << "end_header\n";
  write_file_atomic(file, [&](const std::filesystem::path& temp) {
    std::ofstream out(temp, std::ios::binary);
    const std::string text = header.str();
    out.write(text.data(), static_cast<std::streamsize>(text.size()));
    out.write(reinterpret_cast<const char*>(rows.data_ptr<float>()), static_cast<std::streamsize>(rows.numel() * 4));
    if (!out) throw Error(file, "could not be written");
  });
}

namespace {

struct Property {
  std::string name;
  std::string type;
  int bytes = 0;
};

int type_size(const std::string& type) {
  static const std::map<std::string, int> sizes{
      {"char", 1},  {"uchar", 1},  {"int8", 1},  {"uint8", 1},   {"short", 2},   {"ushort", 2},
      {"int16", 2}, {"uint16", 2}, {"int", 4},   {"uint", 4},    {"int32", 4},   {"uint32", 4},
      {"float", 4}, {"float32", 4}, {"double", 8}, {"float64", 8}};
  const auto it = sizes.find(type);
  return it == sizes.end() ? 0 : it->second;
}

double decode(const char* p, const std::string& type) {
  const auto get = [p]<class T>(T) {
    T v;
    std::memcpy(&v, p, sizeof(T));
    return static_cast<double>(v);
  };
  if (type == "float" || type == "float32") return get(float{});
  if (type == "double" || type == "float64") return get(double{});
  if (type == "char" || type == "int8") return get(int8_t{});
  if (type == "uchar" || type == "uint8") return get(uint8_t{});
  if (type == "short" || type == "int16") return get(int16_t{});
  if (type == "ushort" || type == "uint16") return get(uint16_t{});
  if (type == "int" || type == "int32") return get(int32_t{});
  return get(uint32_t{});
}

}  // namespace

GaussianCloud read_gaussian_ply(const std::filesystem::path& file) {
  std::ifstream in(file, std::ios::binary);
  if (!in) throw Error(file, "cannot be opened");
  std::string line;
  if (!std::getline(in, line) || line != "ply") throw Error(file, "is not a PLY file");
  bool binary = false, in_vertex = false, seen_vertex = false;
  int64_t count = -1;
  std::vector<Property> properties;
  while (true) {
    if (!std::getline(in, line)) throw Error(file, "ends inside its header");
    if (!line.empty() && line.back() == '\r') line.pop_back();
    std::istringstream words(line);
    std::string keyword;
    words >> keyword;
    if (keyword == "end_header") break;
    if (keyword == "format") {
      std::string format;
      words >> format;
      if (format == "binary_little_endian") binary = true;
      else if (format != "ascii") throw Error(file, "has format " + format + "; only binary_little_endian and ascii are read");
    } else if (keyword == "element") {
      std::string name;
      words >> name;
      if (seen_vertex) {
        in_vertex = false;  // later elements are not read
        continue;
      }
      if (name != "vertex") throw Error(file, "must have its vertex element first (found '" + name + "')");
      words >> count;
      if (!words || count < 0) throw Error(file, "has a malformed vertex count: " + line);
      in_vertex = seen_vertex = true;
    } else if (keyword == "property" && in_vertex) {
      Property p;
      words >> p.type;
      if (p.type == "list") throw Error(file, "has a list property in its vertex element: " + line);
      words >> p.name;
      p.bytes = type_size(p.type);
      if (p.bytes == 0) throw Error(file, "has a property of unknown type: " + line);
      properties.push_back(p);
    }
  }
  if (!seen_vertex) throw Error(file, "has no vertex element");

  std::map<std::string, size_t> column;
  size_t record = 0;
  for (size_t i = 0; i < properties.size(); ++i) {
    column[properties[i].name] = i;
    record += properties[i].bytes;
  }
  int rest = 0;
  while (column.count("f_rest_" + std::to_string(rest))) ++rest;
  int degree = -1;
  for (int d = 0; d <= 3; ++d)
    if (3 * ((d + 1) * (d + 1) - 1) == rest) degree = d;
  if (degree < 0) throw Error(file, "has " + std::to_string(rest) + " f_rest properties, not 0, 9, 24 or 45");
  std::vector<std::string> wanted = ply_property_names(degree);
  std::erase_if(wanted, [](const std::string& name) { return name == "nx" || name == "ny" || name == "nz"; });
  std::vector<size_t> source;
  for (const auto& name : wanted) {
    const auto it = column.find(name);
    if (it == column.end()) throw Error(file, "lacks the vertex property '" + name + "'");
    const std::string& type = properties[it->second].type;
    if (type != "float" && type != "float32" && type != "double" && type != "float64")
      throw Error(file, "property '" + name + "' is " + type + ", expected float");
    source.push_back(it->second);
  }

  std::vector<size_t> offset(properties.size(), 0);
  for (size_t i = 1; i < properties.size(); ++i) offset[i] = offset[i - 1] + properties[i - 1].bytes;
  at::Tensor values = at::empty({count, static_cast<int64_t>(wanted.size())}, at::kFloat);
  float* out = values.data_ptr<float>();
  std::vector<char> bytes(record);
  std::vector<double> ascii(properties.size());
  for (int64_t v = 0; v < count; ++v) {
    if (binary) {
      if (!in.read(bytes.data(), static_cast<std::streamsize>(record)))
        throw Error(file, "ends after " + std::to_string(v) + " of its " + std::to_string(count) + " vertices");
    } else {
      for (auto& x : ascii)
        if (!(in >> x)) throw Error(file, "has a malformed or missing value in vertex " + std::to_string(v));
    }
    for (size_t k = 0; k < source.size(); ++k) {
      const size_t p = source[k];
      const double x = binary ? decode(bytes.data() + offset[p], properties[p].type) : ascii[p];
      if (!std::isfinite(x)) throw Error(file, "vertex " + std::to_string(v) + " has a non-finite " + wanted[k]);
      *out++ = static_cast<float>(x);
    }
  }

  const int64_t k = (degree + 1) * (degree + 1);
  GaussianCloud cloud;
  cloud.means = values.slice(1, 0, 3).contiguous();
  const at::Tensor dc = values.slice(1, 3, 6).view({count, 1, 3});
  const at::Tensor higher = values.slice(1, 6, 6 + rest).reshape({count, 3, k - 1}).transpose(1, 2);
  cloud.sh = at::cat({dc, higher}, 1).contiguous();
  cloud.opacity_logit = values.select(1, 6 + rest).contiguous();
  cloud.log_scale = values.slice(1, 7 + rest, 10 + rest).contiguous();
  cloud.rotation = values.slice(1, 10 + rest, 14 + rest).contiguous();
  return cloud;
}

at::Tensor render_cloud(const GaussianCloud& cloud, const Camera& camera, const at::Tensor& background,
                        bool antialiased) {
  splat::RasterSettings settings = trainer::raster_settings(camera, antialiased);
  settings.sh_degree = cloud.sh_degree();
  const splat::RasterOutput out = splat::rasterize(cloud.means, cloud.covariances(), cloud.sh, cloud.opacities(),
                                                   background, {trainer::raster_camera(camera)}, settings);
  return out.rgb[0].permute({2, 0, 1});
}

}  // namespace tega::tools
