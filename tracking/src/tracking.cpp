#include "tega/tracking/tracking.h"

#include <fcntl.h>
#include <sys/file.h>
#include <unistd.h>

#include <cerrno>
#include <cstdio>
#include <cstring>
#include <nlohmann/json.hpp>
#include <optional>

#include "frame_record.h"
#include "report.h"
#include "tega/core/error.h"
#include "tega/core/files.h"
#include "tega/core/log.h"
#include "tega/core/options.h"
#include "tega/core/progress.h"
#include "tega/core/rig.h"
#include "tega/core/take.h"
#include "tega/core/thread_pool.h"
#include "tega/landmarks/landmarks.h"
#include "tega/tracking/photos.h"

namespace tega::tracking {
namespace fs = std::filesystem;

namespace {

std::string frame_name(int frame, const char* extension) {
  char name[32];
  std::snprintf(name, sizeof name, "%06d%s", frame, extension);
  return name;
}

// The rig's cameras in the take's order; every camera of the take must be in the rig.
std::vector<Camera> take_cameras(const TakeInfo& take, const Rig& rig, const fs::path& rig_file) {
  std::vector<Camera> cameras;
  for (const auto& name : take.cameras) {
    const auto it = std::find_if(rig.cameras.begin(), rig.cameras.end(), [&](const Camera& c) { return c.name == name; });
    if (it == rig.cameras.end())
      throw Error(rig_file, "has no camera " + name + ", which take " + take.name + " records");
    cameras.push_back(*it);
  }
  return cameras;
}

struct TakeContext {
  const TakeInfo& take;
  const std::vector<Camera>& cameras;        // as recorded: the report draws over full-size photos
  int photo_factor;                          // the image terms' photos, downsampled by this ...
  const std::vector<Camera>& photo_cameras;  // ... and their cameras
  const HeadModel& model;
  const SubjectIdentity& subject;
  const landmarks::LandmarkDetector* landmarks;
  fs::path meshes;  // MESHES/<take>
  fs::path out;     // TRACKED/<take>
  std::string made_with;
  int first_frame, end_frame;  // the frames to track, [first, end)
  bool whole_take() const { return first_frame == 0 && end_frame == take.frames; }
};

// An exclusive flock on `file` while the object lives; waits for another process's.
class FileLock {
 public:
  explicit FileLock(const fs::path& file) : fd_(::open(file.c_str(), O_RDWR | O_CREAT | O_CLOEXEC, 0644)) {
    if (fd_ < 0) throw Error(file, std::string("cannot be opened for locking: ") + std::strerror(errno));
    while (::flock(fd_, LOCK_EX) != 0)
      if (errno != EINTR) throw Error(file, std::string("cannot be locked: ") + std::strerror(errno));
  }
  ~FileLock() { ::close(fd_); }  // releases the lock
  FileLock(const FileLock&) = delete;
  FileLock& operator=(const FileLock&) = delete;

 private:
  int fd_;
};

bool needs_photos(const Options& o, const landmarks::LandmarkDetector* landmarks) {
  return o.flow.enabled || o.eyelids.enabled || landmarks;
}

// Frames written with other options or another identity are redone when the whole take is
// tracked. A range never removes them: other ranges may be writing beside it.
void claim_take_folder(const TakeContext& t) {
  const fs::path options_file = t.out / "made_with.yaml";
  const bool recorded = fs::exists(options_file);
  if (fs::exists(t.out) && !(recorded && read_text_file(options_file) == t.made_with)) {
    if (t.whole_take()) {
      remove_tree(t.out);
    } else if (recorded) {
      throw Error(t.out, "holds frames tracked with other options, identity or rig: remove it, or track the whole "
                         "take, which redoes them");
    }  // else another range has only just made the folder
  }
  fs::create_directories(t.out);
  if (!fs::exists(options_file)) write_text_atomic(options_file, t.made_with);  // ranges at once write the same
}

// Every frame's record of the take, read back; nullopt while a frame has none (another range of
// the take is still at work).
std::optional<std::vector<FrameRecord>> take_records(const TakeContext& t) {
  std::vector<FrameRecord> records;
  for (int frame = 0; frame < t.take.frames; ++frame) {
    auto stored = read_frame_record(t.out, frame, t.model);
    if (!stored) return std::nullopt;
    records.push_back(stored->record);
  }
  return records;
}

// The take's report and track.json, last. Two ranges finishing at once may both write them: from
// the same records on disk, the same files.
void write_take_summary(const TakeContext& t, const std::vector<FrameRecord>& records, const Options& options,
                        ThreadPool& pool) {
  write_take_report(t.out / "report", records, t.take, t.cameras, t.model, options.report_overlays, pool);
  nlohmann::json summary_json;
  summary_json["take"] = t.take.name;
  summary_json["frames"] = t.take.frames;
  int tracked = 0;
  for (const auto& r : records) tracked += r.status == "tracked";
  summary_json["tracked"] = tracked;
  summary_json["frames_not_tracked"] = nlohmann::json::array();
  for (const auto& r : records)
    if (r.status != "tracked") summary_json["frames_not_tracked"].push_back({{"frame", r.frame}, {"status", r.status}, {"reason", r.reason}});
  // A take without a single tracked frame is no track; the frames' records
  // stay, and with no track.json a rerun fails the same way.
  if (tracked == 0 && !records.empty())
    throw Error(t.out, "no frame of take " + t.take.name + " was tracked (frame " + std::to_string(records.front().frame) +
                           " " + records.front().status + ": " + records.front().reason + "); see the frame records there");
  write_text_atomic(t.out / "track.json", summary_json.dump(2) + "\n");
}

void track_take(const TakeContext& t, const Options& options, TrackSummary& summary, ThreadPool& pool) {
  const int count = t.end_frame - t.first_frame;
  if (fs::exists(t.out / "track.json") && fs::exists(t.out / "made_with.yaml") &&
      read_text_file(t.out / "made_with.yaml") == t.made_with) {
    logging::info("track: take %s is tracked already with these options", t.take.name.c_str());
    summary.frames_kept += count;
    return;
  }
  claim_take_folder(t);

  // A range starts afresh, as after a failed frame: no earlier frame to follow.
  TakeTracker tracker(t.model, t.subject, t.photo_cameras, options, t.landmarks);
  std::vector<FrameRecord> records;
  Progress progress("track " + t.take.name, count, "frames");
  bool follows = false;  // the next frame follows an accepted one
  for (int frame = t.first_frame; frame < t.end_frame; ++frame) {
    if (auto done = read_frame_record(t.out, frame, t.model, &t.subject)) {
      if (done->record.status == "tracked") {
        tracker.resume_from(done->state);
        follows = false;  // no photos kept: no flow into the next frame
      }
      records.push_back(done->record);
      ++summary.frames_kept;
      progress.advance();
      continue;
    }
    FrameRecord record;
    record.frame = frame;
    const fs::path scan_file = t.meshes / frame_name(frame, ".ply");
    if (!fs::exists(scan_file)) {
      record.status = "skipped";
      record.reason = "no scan: " + scan_file.string() + " is missing";
      logging::warn("track: take %s, frame %d skipped: %s", t.take.name.c_str(), frame, record.reason.c_str());
      write_frame_record(t.out, record, nullptr, t.model);
      records.push_back(record);
      tracker.break_sequence();
      follows = false;
      ++summary.frames_skipped;
      progress.advance();
      continue;
    }
    const Mesh scan = read_mesh(scan_file);
    FrameObservation observation{&scan, {}};
    if (needs_photos(options, t.landmarks)) observation.images = frame_photos(t.take, frame, t.photo_factor, pool);
    if (!follows) tracker.break_sequence();
    const FrameFit fit = tracker.track(observation);
    const auto reason = tracker.rejection(fit);
    record.state = fit.state;
    record.residuals = fit.residuals;
    record.fitted_afresh = fit.fitted_afresh;
    if (reason) {
      record.status = "failed";
      record.reason = *reason;
      logging::warn("track: take %s, frame %d failed: %s", t.take.name.c_str(), frame, reason->c_str());
      write_frame_record(t.out, record, nullptr, t.model);
      tracker.break_sequence();
      follows = false;
      ++summary.frames_failed;
    } else {
      record.status = "tracked";
      write_frame_record(t.out, record, &fit.vertices, t.model);
      tracker.accept(fit, observation);
      follows = true;
      ++summary.frames_tracked;
    }
    records.push_back(record);
    progress.advance();
  }
  progress.finish();
  if (t.whole_take()) {
    write_take_summary(t, records, options, pool);
  } else if (const auto all = take_records(t)) {
    logging::info("track: take %s: frames %d to %d were the last to track; its summary follows", t.take.name.c_str(),
                  t.first_frame, t.end_frame - 1);
    write_take_summary(t, *all, options, pool);
  } else {
    logging::info("track: take %s, frames %d to %d tracked; the range that finishes the take writes its summary",
                  t.take.name.c_str(), t.first_frame, t.end_frame - 1);
  }
}

// The first frames of the first take, each with its scan and photos.
SubjectIdentity identity_of(const TrackRequest& request, const TakeInfo& first, const std::vector<Camera>& cameras,
                            const HeadModel& model, const Options& options, const landmarks::LandmarkDetector* landmarks,
                            ThreadPool& pool) {
  const int photo_factor = photo_downsample(cameras, options.photo_max_side);
  std::vector<Mesh> scans;
  std::vector<std::vector<Image8>> photos;
  for (int frame : options.identity_frames) {
    const fs::path scan_file = request.meshes / first.name / frame_name(frame, ".ply");
    if (!fs::exists(scan_file))
      throw Error(scan_file, "is missing: the identity is fitted to frame " + std::to_string(frame) + " of take " +
                                 first.name + " (identity_frames)");
    scans.push_back(read_mesh(scan_file));
    photos.push_back(needs_photos(options, landmarks) ? frame_photos(first, frame, photo_factor, pool)
                                                      : std::vector<Image8>{});
  }
  std::vector<FrameObservation> frames;
  for (size_t i = 0; i < scans.size(); ++i) frames.push_back({&scans[i], photos[i]});
  logging::info("track: fitting the subject's identity to %zu frame(s) of take %s", frames.size(), first.name.c_str());
  return fit_identity(model, frames, photo_cameras(cameras, photo_factor), options, landmarks);
}

}  // namespace

TrackSummary track_capture(const TrackRequest& request, const Options& options) {
  const CaptureInfo capture = read_capture(request.capture);
  const fs::path rig_file = capture.rig_file(request.rig);
  const Rig rig = read_rig_json(rig_file);
  const std::vector<std::string> takes = capture.performance_takes(request.takes, "to track");
  for (const auto& name : takes)
    if (!fs::is_directory(request.meshes / name))
      throw Error(request.meshes / name, "is missing: take " + name + " has no meshes (run tega mvs first)");

  if (options.model.empty()) throw Error("track: no head model: set the model option (tega track --model DIR)");
  for (const int point : options.landmarks.ignored_points)
    if (point < 0 || point >= 68)
      throw Error("track: landmarks.ignored_points holds " + std::to_string(point) + "; points are numbered 0 to 67");
  const HeadModel model = load_head_model(options.model, options.model_metres_per_unit);
  std::unique_ptr<landmarks::LandmarkDetector> landmarks;
  if (!options.landmarks.model.empty()) landmarks = std::make_unique<tega::landmarks::LandmarkDetector>(options.landmarks.model);
  ThreadPool pool(options.threads);
  fs::create_directories(request.out);

  const TakeInfo first = read_take(capture.root / "takes" / takes.front());
  const fs::path identity_file = request.out / "identity.json";
  SubjectIdentity subject;
  {
    const FileLock identity_lock(request.out / ".identity.lock");  // ranges at once: one fits, the others read it
    if (!options.identity.empty()) {
      subject = read_identity(options.identity, model);
      if (fs::absolute(options.identity) != fs::absolute(identity_file)) write_identity(subject, model, identity_file);
    } else if (fs::exists(identity_file) && fs::exists(request.out / "identity_options.yaml") &&
               read_text_file(request.out / "identity_options.yaml") == options_to_yaml(options)) {
      subject = read_identity(identity_file, model);
    } else {
      subject = identity_of(request, first, take_cameras(first, rig, rig_file), model, options, landmarks.get(), pool);
      write_identity(subject, model, identity_file);
      write_text_atomic(request.out / "identity_options.yaml", options_to_yaml(options));
    }
  }

  const std::string made_with = options_to_yaml(options) + "# identity\n" + read_text_file(identity_file) +
                                "# rig\n" + read_text_file(rig_file);
  TrackSummary summary;
  for (const auto& name : takes) {
    const TakeInfo take = read_take(capture.root / "takes" / name);
    const std::vector<Camera> cameras = take_cameras(take, rig, rig_file);
    const int factor = photo_downsample(cameras, options.photo_max_side);
    const std::vector<Camera> photo_rig = photo_cameras(cameras, factor);
    logging::info("track: take %s, %d frames, %zu cameras, photos at 1/%d size", name.c_str(), take.frames,
                  cameras.size(), factor);
    const int end = request.end_frame < 0 ? take.frames : std::min(request.end_frame, take.frames);
    if (request.first_frame >= take.frames)
      throw Error("track: take " + name + " has frames 0 to " + std::to_string(take.frames - 1) + "; asked for " +
                  std::to_string(request.first_frame) + " on");
    track_take({take, cameras, factor, photo_rig, model, subject, landmarks.get(), request.meshes / name,
                request.out / name, made_with, request.first_frame, end},
               options, summary, pool);
    ++summary.takes;
  }
  return summary;
}

}  // namespace tega::tracking
