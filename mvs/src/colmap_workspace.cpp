#include "tega/mvs/colmap_workspace.h"

#include <spdlog/fmt/fmt.h>

#include <algorithm>
#include <string_view>

#include "colmap_tie_points.h"
#include "tega/core/error.h"
#include "tega/core/files.h"

namespace tega::mvs {
namespace fs = std::filesystem;
namespace {

// tega writes its undistorted images as PNG: lossless, and readable everywhere.
constexpr const char* kImageExtension = ".png";

void check_type(const std::string& type, const fs::path& directory) {
  if (type != "geometric" && type != "photometric")
    throw Error(directory, "depth map type '" + type + "': expected 'geometric' or 'photometric'");
}

fs::path depth_map_file(const fs::path& directory, const std::string& image_file, const std::string& type) {
  return directory / "stereo" / "depth_maps" / (image_file + "." + type + ".bin");
}
fs::path normal_map_file(const fs::path& directory, const std::string& image_file, const std::string& type) {
  return directory / "stereo" / "normal_maps" / (image_file + "." + type + ".bin");
}

void make_directories(const fs::path& directory) {
  std::error_code error;
  fs::create_directories(directory, error);
  if (error) throw Error(directory, "cannot create the directory: " + error.message());
}

void check_writable(const DenseWorkspace& workspace, const fs::path& directory) {
  workspace.rig.validate(directory);
  for (const Camera& camera : workspace.rig.cameras)
    if (camera.has_distortion())
      throw Error(directory, "camera '" + camera.name + "' has distortion; a dense workspace holds undistorted views");
  const auto check_camera = [&](const std::string& name, const char* what) {
    if (!workspace.rig.contains(name))
      throw Error(directory, fmt::format("{} of camera '{}', which is not in the rig", what, name));
  };
  for (const auto& [name, image] : workspace.images) {
    check_camera(name, "an image");
    const Camera& camera = workspace.rig.camera(name);
    if (image.width != camera.width || image.height != camera.height || image.channels != 3)
      throw Error(directory, fmt::format("the image of camera '{}' is {}x{}x{}, expected {}x{} RGB", name, image.width,
                                         image.height, image.channels, camera.width, camera.height));
  }
  for (const auto& [name, map] : workspace.depth_maps) {
    check_camera(name, "a depth map");
    const size_t pixels = size_t(map.width) * size_t(map.height);
    if (map.width <= 0 || map.height <= 0 || map.depth.size() != pixels || map.normals.size() != 3 * pixels)
      throw Error(directory, fmt::format("the depth map of camera '{}' ({}x{}) holds {} depths and {} normal values",
                                         name, map.width, map.height, map.depth.size(), map.normals.size()));
  }
  for (const auto& [name, sources] : workspace.source_views) {
    check_camera(name, "source views");
    for (const std::string& source : sources)
      if (!workspace.rig.contains(source))
        throw Error(directory, "source view '" + source + "' of camera '" + name + "' is not in the rig");
  }
}

std::string patch_match_config(const DenseWorkspace& workspace) {
  std::string text;
  for (const Camera& camera : workspace.rig.cameras) {
    const auto found = workspace.source_views.find(camera.name);
    if (found == workspace.source_views.end()) continue;
    std::string sources;
    for (const std::string& source : found->second) sources += (sources.empty() ? "" : ", ") + source + kImageExtension;
    text += camera.name + kImageExtension + "\n" + sources + "\n";
  }
  return text;
}

std::string fusion_config(const DenseWorkspace& workspace) {
  std::string text;
  for (const Camera& camera : workspace.rig.cameras)
    if (workspace.depth_maps.contains(camera.name)) text += camera.name + kImageExtension + "\n";
  return text;
}

// Camera name -> its image's file name in images/, whatever the extension.
std::map<std::string, std::string> image_files(const fs::path& images) {
  std::error_code error;
  fs::directory_iterator entries(images, error);
  if (error) throw Error(images, "cannot list the images: " + error.message());
  std::map<std::string, std::string> files;
  for (const fs::directory_entry& entry : entries) {
    if (!entry.is_regular_file()) continue;
    const std::string file = entry.path().filename().string();
    const auto [at, added] = files.emplace(colmap_camera_name(file), file);
    if (!added) throw Error(images, "two images for camera '" + at->first + "': " + at->second + " and " + file);
  }
  return files;
}

Image8 to_rgb(const Image8& image, const fs::path& file) {
  if (image.channels == 3) return image;
  if (image.channels < 1 || image.channels > 4)
    throw Error(file, fmt::format("{} channels, expected 1 to 4", image.channels));
  Image8 rgb(image.width, image.height, 3);
  const bool grey = image.channels <= 2;  // grey or grey + alpha
  for (int y = 0; y < image.height; ++y)
    for (int x = 0; x < image.width; ++x)
      for (int c = 0; c < 3; ++c) rgb.at(x, y, c) = image.at(x, y, grey ? 0 : c);
  return rgb;
}

DepthMap read_depth_and_normals(const fs::path& depth_file, const fs::path& normal_file) {
  int width, height, channels;
  std::vector<float> depth = read_colmap_array(depth_file, width, height, channels);
  if (channels != 1) throw Error(depth_file, fmt::format("a depth map has 1 channel, found {}", channels));
  if (!fs::exists(normal_file))
    throw Error(normal_file, "missing: the depth map " + depth_file.string() + " has no normal map");
  int normal_width, normal_height, normal_channels;
  std::vector<float> normals = read_colmap_array(normal_file, normal_width, normal_height, normal_channels);
  if (normal_channels != 3)
    throw Error(normal_file, fmt::format("a normal map has 3 channels, found {}", normal_channels));
  if (normal_width != width || normal_height != height)
    throw Error(normal_file, fmt::format("size mismatch: the normal map is {}x{}, its depth map {}x{}", normal_width,
                                         normal_height, width, height));
  DepthMap map(width, height);
  for (size_t i = 0; i < depth.size(); ++i) {
    // COLMAP marks pixels without an estimate by a depth <= 0; its geometric
    // maps are already filtered, so what they keep is taken at zero cost.
    if (!(depth[i] > 0)) continue;
    map.depth[i] = depth[i];
    map.cost[i] = 0;
    std::copy_n(normals.begin() + std::ptrdiff_t(3 * i), 3, map.normals.begin() + std::ptrdiff_t(3 * i));
  }
  return map;
}

// The non-empty pieces of `text` between separators, without surrounding blanks.
std::vector<std::string> split_trimmed(std::string_view text, char separator) {
  std::vector<std::string> pieces;
  size_t start = 0;
  while (start <= text.size()) {
    const size_t end = std::min(text.find(separator, start), text.size());
    std::string_view piece = text.substr(start, end - start);
    const size_t first = piece.find_first_not_of(" \t\r");
    if (first != std::string_view::npos)
      pieces.emplace_back(piece.substr(first, piece.find_last_not_of(" \t\r") - first + 1));
    start = end + 1;
  }
  return pieces;
}

// patch-match.cfg: pairs of lines, an image then its source images separated
// by commas, or COLMAP's automatic choices (__auto__, __all__), which name none.
std::map<std::string, std::vector<std::string>> read_patch_match_config(const fs::path& file, const Rig& rig) {
  const std::vector<std::string> lines = split_trimmed(read_text_file(file), '\n');
  if (lines.size() % 2 != 0) throw Error(file, "expected pairs of lines (an image, then its source images)");
  std::map<std::string, std::vector<std::string>> sources;
  const auto camera_of = [&](const std::string& image) {
    const std::string name = colmap_camera_name(image);
    if (!rig.contains(name)) throw Error(file, "image '" + image + "' is not in the sparse model");
    return name;
  };
  for (size_t i = 0; i < lines.size(); i += 2) {
    const std::string reference = camera_of(lines[i]);
    if (lines[i + 1].starts_with("__")) continue;
    std::vector<std::string>& list = sources[reference];
    for (const std::string& source : split_trimmed(lines[i + 1], ',')) list.push_back(camera_of(source));
  }
  return sources;
}

}  // namespace

void write_dense_workspace(const DenseWorkspace& workspace, const fs::path& directory, const std::string& type) {
  check_type(type, directory);
  check_writable(workspace, directory);
  make_directories(directory / "images");
  make_directories(directory / "stereo");
  for (const auto& [name, image] : workspace.images)
    write_image(image, directory / "images" / (name + kImageExtension));
  write_colmap_text(workspace.rig, directory / "sparse", 1.0, kImageExtension,
                    tie_points_from_depth_maps(workspace.rig, workspace.depth_maps));
  for (const auto& [name, map] : workspace.depth_maps) {
    write_colmap_array(depth_map_file(directory, name + kImageExtension, type), map.width, map.height, 1, map.depth);
    write_colmap_array(normal_map_file(directory, name + kImageExtension, type), map.width, map.height, 3, map.normals);
  }
  write_text_atomic(directory / "stereo" / "patch-match.cfg", patch_match_config(workspace));
  write_text_atomic(directory / "stereo" / "fusion.cfg", fusion_config(workspace));
  if (workspace.fused) write_point_cloud_ply(*workspace.fused, directory / "fused.ply");
}

DenseWorkspace read_dense_workspace(const fs::path& directory, const std::string& type) {
  check_type(type, directory);
  const fs::path sparse = directory / "sparse";
  if (!fs::exists(sparse / "cameras.txt") && fs::exists(sparse / "cameras.bin"))
    throw Error(sparse, "a binary COLMAP model; tega reads text models (colmap model_converter --output_type TXT)");
  DenseWorkspace workspace;
  workspace.rig = read_colmap_text(sparse);

  const std::map<std::string, std::string> files = image_files(directory / "images");
  for (const Camera& camera : workspace.rig.cameras) {
    const auto found = files.find(camera.name);
    if (found == files.end()) throw Error(directory / "images", "no image of camera '" + camera.name + "'");
    const fs::path image_file = directory / "images" / found->second;
    workspace.images[camera.name] = to_rgb(read_image_u8(image_file), image_file);
    const fs::path depth_file = depth_map_file(directory, found->second, type);
    if (fs::exists(depth_file))
      workspace.depth_maps[camera.name] =
          read_depth_and_normals(depth_file, normal_map_file(directory, found->second, type));
  }
  if (const fs::path config = directory / "stereo" / "patch-match.cfg"; fs::exists(config))
    workspace.source_views = read_patch_match_config(config, workspace.rig);
  if (const fs::path fused = directory / "fused.ply"; fs::exists(fused)) workspace.fused = read_point_cloud_ply(fused);
  return workspace;
}

}  // namespace tega::mvs
