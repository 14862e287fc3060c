// bench/dataset: images per second of the capture-to-dataset stages at the
// paper's sizes (6144 x 4096 captured, 3072 x 2048 in the dataset) on the
// target's 2 cores, on a virtual-studio capture it renders (rendering is not
// timed) with its true meshes as the tracked ones: tega matte's mattes, then
// tega dataset build on them; then, per 3072 x 2048 RGBA image, what the
// dataset's storage costs the trainer's loader: PNG write and read at several
// zlib levels, and raw RGBA in zstd for comparison.
#include <CLI/CLI.hpp>
#include <chrono>
#include <cstdio>
#include <ctime>
#include <filesystem>

#include "tega/core/downsample.h"
#include "tega/core/files.h"
#include "tega/core/image.h"
#include "tega/core/rig.h"
#include "tega/core/take.h"
#include "tega/core/undistort.h"
#include "tega/matting/dataset_build.h"
#include "tega/matting/matte.h"
#include "tega/synth/virtual_studio.h"
#include "tega/tracking/evaluation.h"

#ifdef TEGA_BENCH_HAVE_ZSTD
#include <zstd.h>
#endif

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
#ifdef TEGA_BENCH_HAVE_ZSTD
  std::vector<char> packed(ZSTD_compressBound(rgba.pixels.size()));
  std::vector<uint8_t> unpacked(rgba.pixels.size());
  for (const int level : {1, 3}) {
    size_t size = 0;
    const double write_s = timed(repeats, [&] {
      size = ZSTD_compress(packed.data(), packed.size(), rgba.pixels.data(), rgba.pixels.size(), level);
    });
    const double read_s = timed(repeats, [&] { ZSTD_decompress(unpacked.data(), unpacked.size(), packed.data(), size); });
    std::printf("zstd level %-3d %10.2f %10.1f %10.1f %14.0f   (in memory: no file, no filter)\n", level,
                double(size) / 1e6, 1000 * write_s, 1000 * read_s, megabytes / read_s);
  }
#endif
}

// One image's steps, one thread: where the time of a build goes.
void stage_table(const fs::path& capture, const Camera& camera, const UndistortionMaps& maps, int downsample) {
  const TakeInfo take = read_take(capture / "takes" / "expressions");
  Image8 rgb, matte, rgba, undistorted, small;
  const double read_s = timed(1, [&] { rgb = read_image_u8(take.image_path(camera.name, 0)); });
  const double matte_s =
      timed(1, [&] { matte = read_image_u8(capture / "ground_truth" / "expressions" / "alpha" / camera.name / "000000.png"); });
  const double compose_s = timed(1, [&] {
    rgba = Image8(rgb.width, rgb.height, 4);
    for (size_t i = 0; i < matte.pixels.size(); ++i) {
      for (int c = 0; c < 3; ++c) rgba.pixels[4 * i + c] = rgb.pixels[3 * i + c];
      rgba.pixels[4 * i + 3] = matte.pixels[i];
    }
  });
  const double undistort_s = timed(1, [&] { undistorted = undistort_image(rgba, maps); });
  const double downsample_s = timed(1, [&] { small = box_downsample(undistorted, downsample); });
  const double one_pass_s = timed(1, [&] { small = undistort_image(rgba, maps, downsample); });
  std::printf("\none image, one thread (s): read %dx%d RGB %.2f, read matte %.2f, to RGBA %.2f, undistort %.2f, "
              "downsample %.2f; both in one pass (what the build does) %.2f; writing: below\n",
              rgb.width, rgb.height, read_s, matte_s, compose_s, undistort_s, downsample_s, one_pass_s);
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
  const fs::path tracked = work / "tracked", mattes = work / "mattes";
  remove_tree(tracked);
  remove_tree(mattes);
  tracking::write_studio_truth_as_tracked(capture, tracked);
  matting::MatteOptions matte_options;
  matte_options.threads = threads;
  const auto matte_start = Clock::now();
  const double matte_cpu_start = cpu_seconds();
  const matting::MatteSummary matted = matting::matte_capture({capture, tracked, mattes}, matte_options);
  const double matte_s = seconds_since(matte_start), matte_cpu = cpu_seconds() - matte_cpu_start;
  std::printf("tega matte: %d images in %.1f s, %.2f images/s, %.2f CPU s per image\n", matted.images, matte_s,
              matted.images / matte_s, matte_cpu / matted.images);

  // Undistortion maps are made once per camera: a dataset of 400 frames pays
  // them once per 400 images, this bench once per `frames`.
  const Rig rig = read_rig_json(capture / "rig.json");
  const auto maps_start = Clock::now();
  const UndistortionMaps maps = rig.cameras.front().undistortion_maps();
  const double maps_s = seconds_since(maps_start);
  std::printf("undistortion maps: %.2f s per camera (%dx%d)\n", maps_s, maps.width, maps.height);

  std::printf("\n%-10s %8s %10s %10s %14s %22s %16s\n", "png level", "images", "seconds", "images/s",
              "MB per image", "images/s without maps", "CPU s per image");
  fs::path last;
  for (const int level : levels) {
    matting::DatasetBuildOptions options;
    options.downsample = downsample;
    options.frames = 0;
    options.threads = threads;
    options.png_compression = level;
    const matting::DatasetBuildRequest request{capture, tracked, mattes, work / ("dataset" + std::to_string(level)),
                                               {}, true};
    const auto start = Clock::now();
    const double cpu_start = cpu_seconds();
    const auto summary = matting::build_dataset(request, options);
    const double seconds = seconds_since(start), cpu = cpu_seconds() - cpu_start;
    uintmax_t bytes = 0;
    for (const auto& entry : fs::recursive_directory_iterator(summary.dataset / "images"))
      if (entry.is_regular_file()) bytes += entry.file_size();
    // The maps of each camera are made by one thread while the other waits.
    const double steady = seconds - maps_s * double(rig.cameras.size());
    std::printf("%-10d %8d %10.1f %10.2f %14.2f %22.2f %16.2f\n", level, summary.images, seconds,
                summary.images / seconds, double(bytes) / 1e6 / summary.images, summary.images / steady,
                (cpu - maps_s * double(rig.cameras.size())) / summary.images);
    std::printf("  with the mattes: %.2f images/s\n", summary.images / (seconds + matte_s));
    last = summary.dataset;
  }

  stage_table(capture, rig.cameras.front(), maps, downsample);
  const auto first = *fs::recursive_directory_iterator(last / "images" / rig.cameras.front().name);
  storage_table(read_image_u8(first.path()), work, repeats);
  return 0;
}
