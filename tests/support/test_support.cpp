#include "test_support.h"

#include <cstdlib>
#include <fstream>
#include <random>

#include "tega/core/dataset.h"
#include "tega/core/error.h"
#include "tega/core/files.h"
#include "tega/core/image.h"

namespace tega::test {

std::optional<std::filesystem::path> shared_data_dir() {
  const char* env = std::getenv("TEGA_SHARED_DATA");
  if (!env || !std::filesystem::is_directory(env)) return std::nullopt;
  return std::filesystem::path(env);
}

std::optional<std::filesystem::path> ict_facekit_dir() {
  auto shared = shared_data_dir();
  if (!shared) return std::nullopt;
  auto dir = *shared / "ict-facekit";
  if (!std::filesystem::exists(dir / "generic_neutral_mesh.obj")) return std::nullopt;
  return dir;
}

TempDir::TempDir() {
  std::random_device rd;
  const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
  std::string name = info ? std::string(info->test_suite_name()) + "." + info->name() : "tega";
  path_ = std::filesystem::temp_directory_path() / ("tega-test-" + name + "-" + std::to_string(rd()));
  std::filesystem::create_directories(path_);
}

TempDir::~TempDir() {
  try {
    remove_tree(path_);
  } catch (const Error&) {
  }
}

void write_text(const std::filesystem::path& file, const std::string& text) {
  std::ofstream out(file, std::ios::binary);
  out << text;
}

std::string error_message(const std::function<void()>& action) {
  try {
    action();
  } catch (const Error& e) {
    return e.what();
  }
  ADD_FAILURE() << "no tega::Error thrown";
  return "";
}

void write_tiny_dataset(const std::filesystem::path& root, bool eyeball) {
  Dataset d;
  d.root = root;
  for (const char* name : {"cam00", "cam01"}) {
    Camera c;
    c.name = name;
    c.width = 8;
    c.height = 6;
    c.K << 10, 0, 4, 0, 10, 3, 0, 0, 1;
    c.world_to_camera.t = {0, 0, 1};
    d.rig.cameras.push_back(c);
  }
  d.template_mesh.positions.resize(3, 3);
  d.template_mesh.positions << 0, 0, 0, 1, 0, 0, 0, 1, 0;
  d.template_mesh.faces.resize(1, 3);
  d.template_mesh.faces << 0, 1, 2;
  d.template_mesh.uvs.resize(3, 2);
  d.template_mesh.uvs << 0, 0, 1, 0, 0, 1;
  d.template_mesh.uv_faces = d.template_mesh.faces;
  d.template_mesh.triangle_polygon = {0};
  const char* ids[] = {"smile_000000", "blink_000000"};
  for (int f = 0; f < 2; ++f) {
    DatasetFrame frame;
    frame.id = ids[f];
    frame.sequence = std::string(ids[f]).substr(0, 5);
    frame.head_to_world.t = {0.01, 0, 0};
    d.frames.push_back(frame);
    write_vertices_bin(d.template_mesh.positions, d.mesh_path(frame.id));
    for (int c = 0; c < 2; ++c) {
      Image8 image(8, 6, 4, 255);
      for (int y = 0; y < 6; ++y)
        for (int x = 0; x < 8; ++x) image.at(x, y, 0) = static_cast<uint8_t>(10 * c + f);
      write_image(image, d.image_path(d.rig.cameras[c].name, frame.id));
    }
  }
  d.train = {{"smile_000000"}, {"cam00"}};
  d.test = {{"blink_000000"}, {"cam01"}};
  if (eyeball) d.eyeball_faces = {0};
  write_dataset_manifest(d);
}

}  // namespace tega::test
