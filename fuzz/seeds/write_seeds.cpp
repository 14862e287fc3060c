// Writes the seeds of fuzz/corpus/<target>/ with tega's own writers, plus a
// few hand-written valid files for syntax the writers never produce
// (negative OBJ indices, ASCII PLY, COLMAP's other camera models).
// Usage: tega_fuzz_seeds FUZZ_CORPUS_FOLDER (docs/reliability.md).
#include <fstream>
#include <iostream>
#include <iterator>
#include <sstream>

#include "fuzz_target.h"
#include "tega/capture/options.h"
#include "tega/core/dataset.h"
#include "tega/core/error.h"
#include "tega/core/image.h"
#include "tega/core/options.h"
#include "tega/core/take.h"
#include "tega/synth/options.h"
#include "tiny_inputs.h"
#ifdef TEGA_FUZZ_SEEDS_SAFETENSORS
#include <ATen/ATen.h>

#include "tega/nn/safetensors.h"
#endif

namespace {
namespace fs = std::filesystem;
using tega::fuzz::scratch_folder;

std::string file_bytes(const fs::path& file) {
  std::ifstream in(file, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

class SeedWriter {
 public:
  explicit SeedWriter(fs::path corpus) : corpus_(std::move(corpus)) {}
  void add(const std::string& target, const std::string& name, const std::string& bytes) {
    fs::create_directories(corpus_ / target);
    std::ofstream(corpus_ / target / ("seed-" + name), std::ios::binary) << bytes;
    std::cout << target << "/seed-" << name << " (" << bytes.size() << " bytes)\n";
  }
  // Writes through `write` into a scratch file, then adds that file's bytes.
  template <class Write>
  void add_written(const std::string& target, const std::string& name, const std::string& scratch_name, Write write) {
    const fs::path file = scratch_folder() / "written" / scratch_name;
    fs::create_directories(file.parent_path());
    write(file);
    add(target, name, file_bytes(file));
  }

 private:
  fs::path corpus_;
};

std::string indented(const std::string& text) {
  std::istringstream lines(text);
  std::string out;
  for (std::string line; std::getline(lines, line);) out += "  " + line + "\n";
  return out;
}

void rig_seeds(SeedWriter& seeds) {
  const tega::Rig rig = tega::fuzz::tiny_rig(3, true);
  seeds.add_written("rig_json", "three-cameras", "rig.json", [&](const fs::path& f) { tega::write_rig_json(rig, f); });
  seeds.add_written("krt", "three-cameras", "KRT", [&](const fs::path& f) { tega::write_krt(rig, f); });
  const fs::path colmap = scratch_folder() / "written" / "colmap";
  tega::ColmapPoint point{{0.1, 0.2, 0.3}, {{0, {10.5, 20.5}}, {2, {30.0, 12.0}}}};
  tega::write_colmap_text(rig, colmap, 0.001, ".png", {point});
  seeds.add("colmap_text", "three-cameras",
            tega::fuzz::join_parts({file_bytes(colmap / "cameras.txt"), file_bytes(colmap / "images.txt"),
                                    file_bytes(colmap / "points3D.txt")}));
  tega::write_colmap_text(tega::fuzz::tiny_rig(1, false), colmap);
  seeds.add("colmap_text", "pinhole",
            tega::fuzz::join_parts({file_bytes(colmap / "cameras.txt"), file_bytes(colmap / "images.txt"),
                                    file_bytes(colmap / "points3D.txt")}));
  seeds.add("colmap_text", "simple-models",
            tega::fuzz::join_parts({"# CAMERA_ID, MODEL, WIDTH, HEIGHT, PARAMS[]\n"
                                    "1 SIMPLE_PINHOLE 64 48 80 31.5 23.5\n"
                                    "2 SIMPLE_RADIAL 64 48 80 31.5 23.5 -0.01\n"
                                    "3 RADIAL 64 48 80 31.5 23.5 -0.01 0.002\n",
                                    "1 1 0 0 0 0 0 1000 1 a.jpg\n\n"
                                    "2 1 0 0 0 0 0 1000 2 b.JPEG\n\n"
                                    "3 0.7071068 0 0.7071068 0 0 0 1000 3 c\n\n",
                                    ""}));
}

void mesh_seeds(SeedWriter& seeds) {
  const tega::Mesh mesh = tega::fuzz::tiny_mesh();
  seeds.add_written("obj", "quad-and-triangle", "mesh.obj", [&](const fs::path& f) { tega::write_obj(mesh, f); });
  seeds.add("obj", "negative-indices-and-normals",
            "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 1 1 0\nvt 0 0\nvt 1 0\nvt 0 1\nvn 0 0 1\n"
            "f -4/-3/-1 -3/-2/-1 -2/-1/-1\nf 2//1 4//1 3//1\n");
  seeds.add_written("ply", "binary-with-texcoords", "mesh.ply", [&](const fs::path& f) { tega::write_ply(mesh, f); });
  seeds.add("ply", "ascii-quad",
            "ply\nformat ascii 1.0\nelement vertex 4\nproperty float x\nproperty float y\nproperty float z\n"
            "element face 1\nproperty list uchar int vertex_indices\n"
            "property list uchar float texcoord\nend_header\n"
            "0 0 0\n1 0 0\n1 1 0\n0 1 0\n4 0 1 2 3 8 0 0 1 0 1 1 0 1\n");
  seeds.add_written("mesh_bin", "five-vertices", "mesh.bin",
                    [&](const fs::path& f) { tega::write_vertices_bin(mesh.positions, f); });
}

void options_seeds(SeedWriter& seeds) {
  tega::synth::Options studio;
  tega::capture::RigConfig rig;
  rig.cameras.resize(2);
  rig.cameras[0].name = "cam00";
  rig.cameras[0].serial = "A1";
  rig.cameras[1].name = "cam01";
  rig.cameras[1].settings.pixel_format = "BayerRG8";
  seeds.add("options_yaml", "printed",
            "synth:\n" + indented(tega::options_to_yaml(studio)) + "capture:\n" + indented(tega::options_to_yaml(rig)));
  seeds.add("options_yaml", "hand-written",
            "synth:\n  frames: 4\n  studio: {cameras: 3, distortion: [0, 0, 0, 0, 0]}\n  takes: [a, b]\n"
            "capture:\n  source: fake\n  cameras:\n    - {name: cam00, serial: '1'}\n    -\n"
            "  sync: {group_by: frame_id}\n");
}

void capture_seeds(SeedWriter& seeds) {
  tega::TakeInfo take;
  take.name = "expressions";
  take.kind = "performance";
  take.cameras = {"cam00", "cam01"};
  take.frames = 2;
  take.fps = 30;
  take.missing = {{"cam00", {0, 1}}, {"cam01", {0, 1}}};  // every image a recorded gap: the check passes
  const fs::path take_folder = scratch_folder() / "written" / "take";
  tega::write_take(take, take_folder);
  seeds.add("take_json", "all-missing", file_bytes(take_folder / "take.json"));
  take.missing.clear();
  take.pixel_format = "Mono16";
  take.bit_depth = 16;
  take.images = "{camera}/img_{frame}.png";
  tega::write_take(take, take_folder);
  seeds.add("take_json", "mono16", file_bytes(take_folder / "take.json"));

  const fs::path capture = scratch_folder() / "written" / "capture";
  tega::record_take_in_capture(capture, take, 64, 48, "tega_fuzz_seeds");
  take.name = "clean";
  take.kind = "clean_plate";
  tega::record_take_in_capture(capture, take, 64, 48, "tega_fuzz_seeds");
  seeds.add("capture_json", "two-takes", file_bytes(capture / "capture.json"));
}

void dataset_seeds(SeedWriter& seeds) {
  // The rig (cam00, cam01) and template the dataset_manifest target writes beside the manifest.
  tega::Dataset dataset;
  dataset.root = scratch_folder() / "written" / "dataset";
  dataset.rig = tega::fuzz::tiny_rig(2, false);
  dataset.template_mesh = tega::fuzz::tiny_mesh();
  dataset.eyeball_faces = {2};
  dataset.landmark_vertices = {0, 4};
  for (const char* id : {"f000", "f001", "f002"}) {
    tega::DatasetFrame frame;
    frame.id = id;
    frame.sequence = "expressions";
    frame.head_to_world.t = {0, 0.01, 0};
    dataset.frames.push_back(frame);
  }
  dataset.train = {{"f000", "f001"}, {"cam00"}};
  dataset.test = {{"f002"}, {"cam01"}};
  tega::write_dataset_manifest(dataset);
  seeds.add("dataset_manifest", "three-frames", file_bytes(dataset.root / "dataset.json"));
}

void image_seeds(SeedWriter& seeds) {
  tega::Image8 rgba(5, 3, 4);
  for (size_t i = 0; i < rgba.pixels.size(); ++i) rgba.pixels[i] = static_cast<uint8_t>(i * 17);
  seeds.add_written("png_image", "rgba8", "rgba8.png", [&](const fs::path& f) { tega::write_png_with_libpng(rgba, f); });
  tega::Image16 grey(4, 4, 1);
  for (size_t i = 0; i < grey.pixels.size(); ++i) grey.pixels[i] = static_cast<uint16_t>(i * 4000);
  seeds.add_written("png_image", "grey16", "grey16.png", [&](const fs::path& f) { tega::write_png_with_libpng(grey, f); });

  tega::PixelView view{rgba.pixels.data(), rgba.width, rgba.height, 4, 8, static_cast<size_t>(rgba.width) * 4};
  seeds.add_written("zst_image", "rgba8", "rgba8.zst", [&](const fs::path& f) { tega::write_zstd_view(view, f, 1); });
  tega::PixelView view16{grey.pixels.data(), grey.width, grey.height, 1, 16, static_cast<size_t>(grey.width) * 2};
  seeds.add_written("zst_image", "grey16", "grey16.zst", [&](const fs::path& f) { tega::write_zstd_view(view16, f, 3); });

  if (tega::image_format_supported("image.exr")) {
    tega::ImageF depth(4, 3, 1);
    for (size_t i = 0; i < depth.pixels.size(); ++i) depth.pixels[i] = 0.5f + 0.25f * static_cast<float>(i);
    seeds.add_written("exr_image", "float-grey", "depth.exr", [&](const fs::path& f) { tega::write_image(depth, f); });
    tega::ImageF colour(3, 2, 4, 0.25f);
    seeds.add_written("exr_image", "float-rgba", "colour.exr", [&](const fs::path& f) { tega::write_image(colour, f); });
  }
}

#ifdef TEGA_FUZZ_SEEDS_SAFETENSORS
void safetensors_seeds(SeedWriter& seeds) {
  const tega::nn::TensorMap tensors{{"weight", at::arange(6, at::kFloat).reshape({2, 3})},
                                    {"steps", at::tensor({7}, at::kLong)},
                                    {"mask", at::ones({3}, at::kBool)},
                                    {"empty", at::zeros({0, 4}, at::kHalf)}};
  seeds.add_written("safetensors", "four-dtypes", "model.safetensors", [&](const fs::path& f) {
    tega::nn::write_safetensors(f, tensors, {{"iteration", "12"}});
  });
}
#endif

}  // namespace

int main(int argc, char** argv) {
  if (argc != 2) {
    std::cerr << "usage: tega_fuzz_seeds FUZZ_CORPUS_FOLDER (fuzz/corpus)\n";
    return 2;
  }
  try {
    SeedWriter seeds(argv[1]);
    rig_seeds(seeds);
    mesh_seeds(seeds);
    options_seeds(seeds);
    capture_seeds(seeds);
    dataset_seeds(seeds);
    image_seeds(seeds);
#ifdef TEGA_FUZZ_SEEDS_SAFETENSORS
    safetensors_seeds(seeds);
#endif
  } catch (const tega::Error& e) {
    std::cerr << e.what() << "\n";
    return 1;
  }
  return 0;
}
