// `tega matte` over a capture: every image of every tracked frame, camera by
// camera (one clean plate in memory at a time), frames in parallel.
#include <atomic>
#include <cstdio>
#include <map>
#include <nlohmann/json.hpp>
#include <optional>

#include "clean_plate.h"
#include "opencv_threads.h"
#include "tega/core/error.h"
#include "tega/core/files.h"
#include "tega/core/options.h"
#include "tega/core/progress.h"
#include "tega/core/rig.h"
#include "tega/core/take.h"
#include "tega/core/take_images.h"
#include "tega/core/thread_pool.h"
#include "tega/core/tracked.h"
#include "tega/matting/matte.h"

namespace tega::matting {
namespace fs = std::filesystem;

namespace {

std::string frame_name(int frame) {
  char name[16];
  std::snprintf(name, sizeof name, "%06d", frame);
  return name;
}

struct TakeJob {
  TakeInfo take;
  std::map<int, TrackedFrame> frames;
  fs::path out;
};

}  // namespace

MatteSummary matte_capture(const MatteRequest& request, const MatteOptions& options) {
  const CaptureInfo capture = read_capture(request.capture);
  const fs::path rig_file = capture.rig_file(request.rig);
  const Rig rig = read_rig_json(rig_file);
  const TrackedSubject subject = read_tracked_subject(request.tracked);
  const std::optional<TakeInfo> plate_take = clean_plate_take(capture, options);
  const std::string made_with = options_to_yaml(options) + "clean_plate: " + (plate_take ? plate_take->name : "") +
                                "\ntracked: " + fs::absolute(request.tracked).string() + "\n";
  MatteSummary summary;
  summary.clean_plate = plate_take.has_value();

  std::vector<TakeJob> jobs;
  int64_t images = 0;
  for (const std::string& name : capture.performance_takes(request.takes, "to matte")) {
    TakeJob job{read_take(capture.root / "takes" / name), {}, request.out / name};
    for (auto& frame : read_tracked_take(request.tracked, name)) job.frames[frame.frame] = std::move(frame);
    for (int f = 0; f < job.take.frames; ++f)
      if (!job.frames.count(f))
        throw Error(request.tracked / name / (frame_name(f) + ".json"),
                    "is missing: frame " + std::to_string(f) + " of take " + name + " has no tracking record, so its "
                    "images have no mesh prior (track the take again)");
    for (const std::string& camera : job.take.cameras) {
      if (!rig.contains(camera)) throw Error(rig_file, "has no camera " + camera + ", which take " + name + " records");
      if (plate_take && !plate_take->has_image(camera, 0))
        throw Error(plate_take->image_path(camera, 0), "is missing: camera " + camera + " has no clean plate");
    }
    for (const auto& [f, frame] : job.frames) images += frame.tracked() ? long(job.take.cameras.size()) : 0;
    jobs.push_back(std::move(job));
  }

  ThreadPool pool(options.threads);
  Progress progress("matte", images, "images");
  const OpenCvSingleThreaded one_opencv_thread;
  for (const TakeJob& job : jobs) {
    ++summary.takes;
    const fs::path options_file = job.out / "options.yaml";
    if (fs::exists(job.out) && (!fs::exists(options_file) || read_text_file(options_file) != made_with))
      remove_tree(job.out);  // made with other options: redone
    fs::create_directories(job.out);
    write_text_atomic(options_file, made_with);
    nlohmann::json not_tracked = nlohmann::json::array();
    for (const auto& [f, frame] : job.frames) {
      if (frame.tracked()) continue;
      not_tracked.push_back({{"frame", f}, {"status", frame.status}, {"reason", frame.reason}});
      ++summary.frames_not_tracked;
    }
    std::vector<const TrackedFrame*> tracked;
    for (const auto& [f, frame] : job.frames)
      if (frame.tracked()) tracked.push_back(&frame);

    std::atomic<int> done{0}, kept{0};
    for (const std::string& camera_name : job.take.cameras) {
      const Camera& camera = rig.camera(camera_name);
      const fs::path dir = job.out / camera_name;
      fs::create_directories(dir);
      const CameraMatting matting(
          camera, plate_take ? read_recorded_rgb(*plate_take, camera_name, 0, camera.width, camera.height) : Image8(),
          options);
      pool.parallel_for(0, int64_t(tracked.size()), [&](int64_t i) {
        const TrackedFrame& frame = *tracked[size_t(i)];
        const fs::path file = dir / (frame_name(frame.frame) + ".png");
        if (!job.take.has_image(camera_name, frame.frame) || fs::exists(file)) {
          if (fs::exists(file)) ++kept;
          progress.advance();
          return;
        }
        const Image8 photo = read_recorded_rgb(job.take, camera_name, frame.frame, camera.width, camera.height);
        const Vertices world = read_vertices_bin(frame.mesh, subject.neutral.num_vertices());
        write_matte(matting.matte(photo, world, subject.neutral.faces), file);
        ++done;
        progress.advance();
      });
    }
    summary.images += done;
    summary.images_kept += kept;
    const nlohmann::json take_summary = {{"take", job.take.name},
                                         {"cameras", job.take.cameras},
                                         {"frames_matted", tracked.size()},
                                         {"frames_not_tracked", not_tracked},
                                         {"clean_plate", plate_take ? plate_take->name : ""},
                                         {"images", "{camera}/{frame:06d}.png"}};
    write_text_atomic(job.out / "mattes.json", take_summary.dump(2) + "\n");
  }
  progress.finish();
  return summary;
}

}  // namespace tega::matting
