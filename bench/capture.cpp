// bench/capture: sustained recording from Aravis' in-process simulated
// cameras (13 by default) at increasing frame rates. Prints, per rate, the
// frame sets written per second, the camera data the writer consumed (MB/s
// in), what it wrote (MB/s on disk) and every kind of drop; the last rate
// without drops is what this machine sustains. Aravis' simulated cameras
// draw a diagonal ramp, which PNG compresses ~50x: so the bench then runs
// the writer alone on sensor-like frames (a ramp plus noise, which compresses
// about as little as a face does) as fast as it accepts them, for the MB/s
// the writer sustains on real data.
#include <CLI/CLI.hpp>
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <thread>

#include "tega/capture/recorder.h"
#include "tega/capture/take_writer.h"
#include "tega/core/files.h"

namespace fs = std::filesystem;
using namespace tega::capture;

namespace {

// The writer fed as fast as its queues accept sensor-like frames.
void writer_alone(const RigConfig& rig, int cameras, int width, int height, double seconds, const fs::path& out) {
  const PixelFormatInfo format = pixel_format_info(rig.settings.pixel_format);
  const size_t frame_bytes = size_t(width) * height * format.bytes_per_pixel;
  constexpr int kDistinctFrames = 8;  // so that no frame is written from a warm cache twice in a row
  std::vector<std::shared_ptr<std::vector<uint8_t>>> frames;
  uint64_t state = 0x9E3779B97F4A7C15ull;
  for (int i = 0; i < kDistinctFrames; ++i) {
    auto pixels = std::make_shared<std::vector<uint8_t>>(frame_bytes);
    for (size_t p = 0; p < frame_bytes; ++p) {
      state ^= state << 13, state ^= state >> 7, state ^= state << 17;
      const int ramp = int((p % width + p / width + i) % 255);
      (*pixels)[p] = uint8_t(std::clamp(ramp + int(state & 15) - 8, 0, 255));
    }
    frames.push_back(pixels);
  }
  std::vector<TakeWriter::Camera> writer_cameras;
  for (int c = 0; c < cameras; ++c) writer_cameras.push_back({"cam" + std::to_string(c), format});
  tega::remove_tree(out);
  int sets = 0;
  double elapsed = 0;
  uint64_t bytes = 0;
  {
    TakeWriter writer(out, writer_cameras, rig.writer);
    const auto start = std::chrono::steady_clock::now();
    while ((elapsed = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count()) < seconds) {
      FrameSet set;
      set.frames.resize(cameras);
      for (int c = 0; c < cameras; ++c) {
        Frame f;
        f.camera = c;
        f.width = width;
        f.height = height;
        const auto& pixels = frames[(sets + c) % kDistinctFrames];
        f.pixels = pixels->data();
        f.size = frame_bytes;
        f.owner = pixels;
        set.frames[c] = f;
      }
      if (writer.submit(set, sets)) {
        ++sets;
      } else {
        std::this_thread::sleep_for(std::chrono::microseconds(200));
      }
    }
    writer.finish();
    elapsed = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    bytes = writer.bytes_written();
  }
  tega::remove_tree(out);
  std::printf("writer alone on sensor-like frames (ramp + noise): %.1f sets/s = %.1f MB/s of camera data, "
              "%.1f MB/s on disk (%.2fx smaller)\n",
              sets / elapsed, sets * double(frame_bytes) * cameras / 1e6 / elapsed, bytes / 1e6 / elapsed,
              sets * double(frame_bytes) * cameras / std::max<double>(1, bytes));
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"Sustained capture throughput with simulated cameras."};
  int cameras = 13, width = 640, height = 480, compression = 1, threads = 0;
  double seconds = 5;
  std::vector<double> rates{15, 30, 60, 90, 120};
  std::string format = "png", pixel_format = "Mono8", out = (fs::temp_directory_path() / "tega-capture-bench").string();
  app.add_option("--cameras", cameras, "Simulated cameras.");
  app.add_option("--width", width, "Image width.");
  app.add_option("--height", height, "Image height.");
  app.add_option("--pixel-format", pixel_format, "Mono8, Mono16, RGB8, BayerRG8, ...");
  app.add_option("--seconds", seconds, "Seconds recorded per rate.");
  app.add_option("--rates", rates, "Frame rates to try.")->delimiter(',');
  app.add_option("--format", format, "png or tiff.");
  app.add_option("--compression", compression, "PNG zlib level.");
  app.add_option("--threads", threads, "Writer threads (0 = one per hardware thread).");
  app.add_option("--out", out, "Scratch capture folder (removed afterwards).");
  CLI11_PARSE(app, argc, argv);

  RigConfig rig;
  rig.file = "bench";
  rig.source = "fake";
  rig.settings.width = width;
  rig.settings.height = height;
  rig.settings.pixel_format = pixel_format;
  rig.writer.format = format;
  rig.writer.png_compression = compression;
  rig.writer.threads = threads;
  rig.writer.min_free_mb = 0;
  const int bytes_per_pixel = pixel_format_info(pixel_format).bytes_per_pixel;

  std::printf("%d simulated cameras, %dx%d %s, writer %s (zlib level %d), %g s per rate, %u hardware threads\n",
              cameras, width, height, pixel_format.c_str(), format.c_str(), compression, seconds,
              std::thread::hardware_concurrency());
  std::printf("%8s %10s %10s %12s %14s %10s %10s %10s\n", "fps", "sets/s", "MB/s in", "MB/s disk", "rig MB/s",
              "incompl.", "behind", "stream");
  double sustained = 0;
  for (double rate : rates) {
    rig.settings.frame_rate = rate;
    rig.cameras.clear();
    for (int i = 0; i < cameras; ++i)
      rig.cameras.push_back({"cam" + std::to_string(i), "BENCH" + std::to_string(i), rig.settings});
    tega::remove_tree(out);
    TakeRequest request;
    request.name = "bench";
    request.seconds = seconds;
    request.trigger = Trigger::free_run;
    request.live_status = false;
    const TakeOutcome o = record_take(rig, request, out);
    uint64_t stream_drops = 0;
    for (const auto& c : o.cameras) stream_drops += c.stream_failures + c.stream_underruns + c.late_frames;
    const double frame_mb = double(width) * height * bytes_per_pixel / 1e6;
    const double rig_mb_s = frame_mb * cameras * rate;
    const double sets_s = o.frames / o.seconds;
    std::printf("%8.0f %10.1f %10.1f %12.1f %14.1f %10lld %10lld %10llu\n", rate, sets_s, sets_s * cameras * frame_mb,
                o.bytes / 1e6 / o.seconds, rig_mb_s, (long long)o.incomplete_sets, (long long)o.writer_full_dropped,
                (unsigned long long)stream_drops);
    const bool clean = o.incomplete_sets == 0 && o.writer_full_dropped == 0 && stream_drops == 0 &&
                       sets_s >= 0.97 * rate;
    if (clean) sustained = rate;
    std::fflush(stdout);
  }
  tega::remove_tree(out);
  std::printf("sustained without drops: %g fps (%g MB/s of camera data)\n", sustained,
              sustained * cameras * width * height * bytes_per_pixel / 1e6);
  writer_alone(rig, cameras, width, height, seconds, out);
}
