// bench/dataset: images per second of the capture-to-dataset stages at the
// paper's sizes (6144 x 4096 captured, 3072 x 2048 in the dataset) on the
// target's 2 cores, on a virtual-studio capture it renders (rendering is not
// timed) with its true meshes as the tracked ones, stored as RGB or (--bayer)
// raw Bayer: tega matte's mattes, tega dataset build on them, and tega
// dataset build matting the images itself (PNG, then .zst); the steps of one
// image on one thread; then, per 3072 x 2048 RGBA image, what the
// dataset's storage costs the trainer's loader: PNG write and read at several
// zlib levels, and tega's raw pixels in zstd (.zst).
#include <CLI/CLI.hpp>
#include <chrono>
#include <cstdio>
#include <ctime>
#include <filesystem>

#include "tega/core/downsample.h"
#include "tega/core/files.h"
#include "tega/core/image.h"
#include "tega/core/mesh.h"
#include "tega/core/rig.h"
#include "tega/core/take.h"
#include "tega/core/take_images.h"
#include "tega/core/tracked.h"
#include "tega/matting/dataset_build.h"
#include "tega/matting/dataset_image.h"
#include "tega/matting/matte.h"
#include "tega/scoring/tracking_scores.h"
#include "tega/synth/virtual_studio.h"


namespace fs = std::filesystem;
using namespace tega;

namespace {

using Clock = std::chrono::steady_clock;

double seconds_since(Clock::time_point start) { return std::chrono::duration<double>(Clock::now() - start).count(); }

// CPU seconds of every thread of the process: what a build costs whatever
// else the machine runs (wall-clock figures on a shared machine are not).
double cpu_seconds() { return double(std::clock()) / CLOCKS_PER_SEC; }

// Mean seconds of `f` over `repeats` calls.
template <class F>
double timed(int repeats, F&& f) {
  const auto start = Clock::now();
  for (int i = 0; i < repeats; ++i) f();
  return seconds_since(start) / repeats;
}

void storage_table(const Image8& rgba, const fs::path& dir, int repeats) {
  const double megabytes = double(rgba.pixels.size()) / 1e6;
  std::printf("\nstorage of one %dx%d RGBA image (%.1f MB raw), one thread, mean of %d:\n", rgba.width, rgba.height,
              megabytes, repeats);
  std::printf("%-14s %10s %10s %10s %14s\n", "format", "MB", "write ms", "read ms", "read MB/s raw");
  const PixelView view{rgba.pixels.data(), rgba.width, rgba.height, 4, 8, size_t(rgba.width) * 4};
  for (const int level : {0, 1, 3, 6}) {
    const fs::path file = dir / ("level" + std::to_string(level) + ".png");
    const double write_s = timed(repeats, [&] { write_png_view(view, file, level); });
    const double read_s = timed(repeats, [&] { read_image_u8(file); });
    std::printf("png level %-4d %10.2f %10.1f %10.1f %14.0f\n", level, double(fs::file_size(file)) / 1e6, 1000 * write_s,
                1000 * read_s, megabytes / read_s);
  }
  for (const int level : {1, 3}) {
    const fs::path file = dir / ("level" + std::to_string(level) + ".zst");
    const double write_s = timed(repeats, [&] { write_zstd_view(view, file, level); });
    const double read_s = timed(repeats, [&] { read_image_u8(file); });
    std::printf("zstd level %-3d %10.2f %10.1f %10.1f %14.0f\n", level, double(fs::file_size(file)) / 1e6,
                1000 * write_s, 1000 * read_s, megabytes / read_s);
  }
}

// Every take of the capture stored as raw BayerRG8 (R G / G B), the way
// tega capture writes a studio camera's frames (PNG level 1).
void mosaic_capture(const fs::path& capture) {
  for (const auto& listed : read_capture(capture).takes) {
    TakeInfo take = read_take(capture / "takes" / listed.name);
    if (take.pixel_format.rfind("Bayer", 0) == 0 || take.kind == "calibration") continue;
    for (const auto& camera : take.cameras) {
      for (int frame = 0; frame < take.frames; ++frame) {
        if (!take.has_image(camera, frame)) continue;
        const Image8 rgb = read_image_u8(take.image_path(camera, frame));
        Image8 raw(rgb.width, rgb.height, 1);
        for (int y = 0; y < rgb.height; ++y)
          for (int x = 0; x < rgb.width; ++x) raw.at(x, y, 0) = rgb.at(x, y, (y % 2) + (x % 2));
        write_png_view({raw.pixels.data(), raw.width, raw.height, 1, 8, size_t(raw.width)}, take.image_path(camera, frame),
                       1);
      }
    }
    take.pixel_format = "BayerRG8";
    write_take(take, take.folder);
  }
}

// One image's steps, one thread: where the time of a build goes.
void stage_table(const fs::path& capture, const Camera& camera, int downsample) {
  const TakeInfo take = read_take(capture / "takes" / "expressions");
  Image8 rgb, matte, small;
  const double read_s = timed(1, [&] {
    rgb = read_recorded_rgb(take, camera.name, 0, camera.width, camera.height, downsample);
  });
  const double matte_s = timed(1, [&] {
    matte = box_downsample(
        read_image_u8(capture / "ground_truth" / "expressions" / "alpha" / camera.name / "000000.png"), downsample);
  });
  const matting::DatasetResampler resampler(camera, downsample);
  const double resampler_s = timed(3, [&] { small = resampler.rgba(rgb, matte); });
  std::printf("\none image, one thread (s): read the %dx%d capture at the dataset's %dx%d %.2f, read its matte and "
              "shrink it %.2f; RGB + matte undistorted into the dataset's RGBA %.2f; writing: below\n",
              camera.width, camera.height, rgb.width, rgb.height, read_s, matte_s, resampler_s);
}

// One image's matte, one thread: where the time of tega matte goes.
void matte_table(const fs::path& capture, const fs::path& tracked, const Camera& camera) {
  const TakeInfo take = read_take(capture / "takes" / "expressions");
  const TakeInfo plate_take = read_take(capture / "takes" / "clean_plate");
  const TrackedSubject subject = read_tracked_subject(tracked);
  const TrackedFrame frame = read_tracked_take(tracked, "expressions").front();
  Image8 photo, alpha;
  Vertices world;
  const double read_s = timed(1, [&] { photo = read_recorded_rgb(take, camera.name, frame.frame, camera.width, camera.height); });
  const double mesh_s = timed(1, [&] { world = read_vertices_bin(frame.mesh, subject.neutral.num_vertices()); });
  const matting::CameraMatting matting(camera, read_recorded_rgb(plate_take, camera.name, 0, camera.width, camera.height), matting::MatteOptions());
  const double matte_s = timed(3, [&] { alpha = matting.matte(photo, world, subject.neutral.faces); });
  const fs::path file = fs::temp_directory_path() / "tega-bench-matte.png";
  const double write_s = timed(3, [&] { matting::write_matte(alpha, file); });
  fs::remove(file);
  std::printf("\none matte, one thread (s): read the %dx%d capture as RGB %.2f, read the mesh %.3f, matte "
              "(silhouette included) %.2f, write %.2f\n",
              photo.width, photo.height, read_s, mesh_s, matte_s, write_s);
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"Images per second of tega dataset build at the paper's sizes."};
  std::string capture_dir, work_dir = (fs::temp_directory_path() / "tega-dataset-bench").string();
  int cameras = 2, frames = 4, width = 6144, height = 4096, downsample = 2, threads = 2, repeats = 3;
  std::vector<int> levels = {1, 6};
  app.add_option("--capture", capture_dir, "A virtual-studio capture to use (default: render one into --work).");
  app.add_option("--work", work_dir, "Where the capture, tracked meshes, mattes and datasets go.");
  app.add_option("--cameras", cameras, "Cameras of the rendered capture.");
  app.add_option("--frames", frames, "Frames of its one performance take.");
  app.add_option("--width", width, "Captured image width.");
  app.add_option("--height", height, "Captured image height.");
  app.add_option("--downsample", downsample, "The dataset's downsampling factor.");
  app.add_option("--threads", threads, "Worker threads (the target machine has 2 cores).");
  app.add_option("--png-levels", levels, "PNG compression levels to build the dataset with.");
  app.add_option("--repeats", repeats, "Repeats of each storage measurement.");
  bool bayer = false;
  app.add_flag("--bayer", bayer,
               "Store the captured images as a studio camera records them, raw BayerRG8 mosaics (a third of the "
               "bytes to decode), debayered by the stages.");
  CLI11_PARSE(app, argc, argv);

  const fs::path work = work_dir;
  fs::path capture = capture_dir;
  if (capture.empty()) {
    capture = work / "capture";
    synth::Options studio;
    studio.studio.cameras = cameras;
    studio.studio.width = width;
    studio.studio.height = height;
    studio.frames = frames;
    studio.calibration_frames = 0;
    studio.takes = {"expressions"};
    studio.test_takes = {};
    studio.test_cameras = 1;
    studio.supersampling = 1;  // rendering is not what is timed
    studio.write_fine_meshes = false;
    studio.threads = threads;
    std::printf("rendering %s (%d cameras x %d frames at %dx%d)\n", capture.c_str(), cameras, frames, width, height);
    const auto start = Clock::now();
    synth::render_virtual_studio(studio, capture, true);
    std::printf("rendered in %.1f s\n", seconds_since(start));
  }
  if (bayer) mosaic_capture(capture);
  const fs::path tracked = work / "tracked", mattes = work / "mattes";
  remove_tree(tracked);
  remove_tree(mattes);
  scoring::write_studio_truth_as_tracked(capture, tracked);
  const Rig rig = read_rig_json(capture / "rig.json");
  const TakeInfo take = read_take(capture / "takes" / "expressions");
  std::printf("captured images: %s, %dx%d\n", take.pixel_format.c_str(), width, height);

  // What a camera costs once, whatever its frame count (a 400-frame dataset
  // pays it once per 400 images, this bench once per `frames`): the
  // resampler's maps, and for matting the clean plate, read and shrunk.
  const Camera& first_camera = rig.cameras.front();
  const double resampler_s = timed(1, [&] { matting::DatasetResampler(first_camera, downsample); });
  // tega matte mattes the full-size photos, the build at the dataset's size.
  const TakeInfo plate_take = read_take(capture / "takes" / "clean_plate");
  const auto plate_cost = [&](int size_factor) {
    return timed(1, [&] {
      matting::CameraMatting(matting::recorded_camera_at_dataset_size(first_camera, size_factor),
                             read_recorded_rgb(plate_take, first_camera.name, 0, first_camera.width,
                                                        first_camera.height, size_factor),
                             matting::MatteOptions());
    });
  };
  const double plate_s = plate_cost(1), small_plate_s = plate_cost(downsample);
  std::printf("once per camera (s): the resampler's maps %.2f, the clean plate read and shrunk %.2f (tega matte), "
              "%.2f (the build)\n",
              resampler_s, plate_s, small_plate_s);

  std::printf("\n%-46s %8s %10s %10s %14s %16s\n", "run (2 threads)", "images", "seconds", "images/s",
              "images/s steady", "CPU s per image");
  const auto report = [&](const std::string& name, int images, double seconds, double cpu, double per_camera_s) {
    // Per-camera set-up runs on one thread while the others wait.
    const double setup = per_camera_s * double(rig.cameras.size());
    std::printf("%-46s %8d %10.1f %10.2f %14.2f %16.2f\n", name.c_str(), images, seconds, images / seconds,
                images / (seconds - setup), (cpu - setup) / images);
  };
  matting::MatteOptions matte_options;
  matte_options.threads = threads;
  auto start = Clock::now();
  double cpu_start = cpu_seconds();
  const matting::MatteSummary matted = matting::matte_capture({capture, tracked, mattes}, matte_options);
  const double matte_s = seconds_since(start), matte_cpu = cpu_seconds() - cpu_start;
  report("tega matte", matted.images, matte_s, matte_cpu, plate_s);

  fs::path last;
  for (const int level : levels) {
    matting::DatasetBuildOptions options;
    options.downsample = downsample;
    options.frames = 0;
    options.threads = threads;
    options.png_compression = level;
    const std::string suffix = " (PNG level " + std::to_string(level) + ")";
    start = Clock::now();
    cpu_start = cpu_seconds();
    const auto two_stage = matting::build_dataset(
        {capture, tracked, mattes, work / ("dataset" + std::to_string(level)), {}, true}, options);
    const double build_s = seconds_since(start), build_cpu = cpu_seconds() - cpu_start;
    report("tega dataset build --mattes" + suffix, two_stage.images, build_s, build_cpu, resampler_s);
    report("  both stages" + suffix, two_stage.images, matte_s + build_s, matte_cpu + build_cpu, plate_s + resampler_s);

    start = Clock::now();
    cpu_start = cpu_seconds();
    const auto one_pass = matting::build_dataset(
        {capture, tracked, {}, work / ("dataset-matted-here" + std::to_string(level)), {}, true}, options);
    report("tega dataset build, matting here" + suffix, one_pass.images, seconds_since(start),
           cpu_seconds() - cpu_start, small_plate_s + resampler_s);
    uintmax_t bytes = 0;
    for (const auto& entry : fs::recursive_directory_iterator(one_pass.dataset / "images"))
      if (entry.is_regular_file()) bytes += entry.file_size();
    std::printf("  %.2f MB per image\n", double(bytes) / 1e6 / one_pass.images);
    last = one_pass.dataset;
  }

  {
    matting::DatasetBuildOptions options;
    options.downsample = downsample;
    options.frames = 0;
    options.threads = threads;
    options.image_format = "zst";
    start = Clock::now();
    cpu_start = cpu_seconds();
    const auto zst = matting::build_dataset({capture, tracked, {}, work / "dataset-matted-here-zst", {}, true}, options);
    report("tega dataset build, matting here (zst)", zst.images, seconds_since(start), cpu_seconds() - cpu_start,
           small_plate_s + resampler_s);
  }

  matte_table(capture, tracked, first_camera);
  stage_table(capture, first_camera, downsample);
  const auto first = *fs::recursive_directory_iterator(last / "images" / first_camera.name);
  storage_table(read_image_u8(first.path()), work, repeats);
  return 0;
}
