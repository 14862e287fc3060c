#include "tega/capture/recorder.h"

#include <chrono>
#include <cmath>
#include <condition_variable>
#include <cstdio>
#include <mutex>
#include <thread>

#include "disk_space.h"
#include "live_status.h"
#include "preview.h"
#include "rig_stream.h"
#include "take_files.h"
#include "tega/capture/frame_set_assembler.h"
#include "tega/capture/take_writer.h"
#include "tega/core/error.h"
#include "tega/core/files.h"
#include "tega/core/interrupt.h"
#include "tega/core/log.h"
#include "tega/core/take.h"

namespace tega::capture {

namespace fs = std::filesystem;
using Clock = std::chrono::steady_clock;

namespace {

constexpr auto kLoopInterval = std::chrono::milliseconds(20);
constexpr auto kStatusInterval = std::chrono::milliseconds(500);
constexpr auto kPreviewInterval = std::chrono::seconds(3);

double seconds_since(Clock::time_point t) { return std::chrono::duration<double>(Clock::now() - t).count(); }

void check_request(const TakeRequest& r) {
  if (r.name.empty() || r.name.find_first_of("/\\ ") != std::string::npos || r.name[0] == '.')
    throw Error("take name '" + r.name + "' must be a plain folder name");
  if (r.kind != "performance" && r.kind != "calibration" && r.kind != "clean_plate")
    throw Error("take kind must be performance, calibration or clean_plate, not '" + r.kind + "'");
  if (r.frames < 0 || r.seconds < 0) throw Error("--frames and --seconds must not be negative");
}

void check_free_space(const fs::path& folder, double min_free_mb) {
  const double free = free_mb(folder);
  if (free >= 0 && free < min_free_mb)
    throw Error(folder, "only " + std::to_string(int(free)) + " MB free, writer.min_free_mb is " +
                            std::to_string(int(min_free_mb)) + ": free some space or record elsewhere");
}

// A preview that cannot be written (a bad path, a full disk) must not end the take.
void update_preview(const std::optional<FrameSet>& latest, const std::vector<PixelFormatInfo>& formats,
                    const fs::path& file) {
  if (!latest) return;
  try {
    write_contact_sheet(*latest, formats, file);
  } catch (const std::exception& e) {
    logging::warn("preview not updated: %s", e.what());
  }
}

// The recorded frame set handling and the bookkeeping the manifest needs.
class Recording {
 public:
  Recording(const RigConfig& rig, const TakeRequest& request, RigStream& stream, TakeWriter& writer)
      : rig_(rig), request_(request), stream_(stream), writer_(writer), files_(rig.cameras.size()) {
    outcome_.cameras.resize(rig.cameras.size());
    for (size_t c = 0; c < rig.cameras.size(); ++c) outcome_.cameras[c].name = rig.cameras[c].name;
  }

  // Called by the stream, serialised, for every closed frame set.
  void on_set(FrameSet set) {
    std::lock_guard lock(mutex_);
    if (target_reached()) return;
    ++outcome_.sets_seen;
    SetRecord record = files_.record(set);
    bool gap_only = true;  // missing only cameras already lost: the take goes on without them
    for (size_t c = 0; c < set.frames.size(); ++c)
      if (!set.frames[c] && !outcome_.cameras[c].lost) gap_only = false;
    if (!gap_only && set.before_all_streaming) {
      ++outcome_.before_all_streaming;
      record.status = "before_all_streaming";
      files_.add(std::move(record));
      return;
    }
    const bool incomplete = !set.complete() && !gap_only;
    if (incomplete) ++outcome_.incomplete_sets;
    if (incomplete && rig_.sync.incomplete_sets == "drop") {
      ++outcome_.incomplete_dropped;
      record.status = "incomplete_dropped";
    } else if (writer_.submit(set, frames_)) {
      record.status = set.complete() ? "complete" : (incomplete ? "incomplete_kept" : "complete_without_lost");
      record.frame = frames_++;
      latest_ = std::move(set);
    } else if (!writer_.failed()) {
      ++outcome_.writer_full_dropped;
      record.status = "writer_full_dropped";
    } else {
      record.status = "not_written";
    }
    files_.add(std::move(record));
  }

  bool target_reached() const { return request_.frames > 0 && frames_ >= request_.frames; }

  void camera_lost(int camera, const std::string& reason, double t) {
    std::lock_guard lock(mutex_);
    auto& c = outcome_.cameras[camera];
    if (c.lost) return;
    c.lost = true;
    c.lost_reason = reason;
    c.lost_from_frame = frames_;
    event(t, "camera " + c.name + " lost: " + reason);
    logging::warn("camera %s lost: %s; the take goes on with the others", c.name.c_str(), reason.c_str());
  }

  void event(double t, std::string message) { files_.event(t, std::move(message)); }

  bool any_lost() const {
    std::lock_guard lock(mutex_);
    for (const auto& c : outcome_.cameras)
      if (c.lost) return true;
    return false;
  }
  std::optional<FrameSet> latest() {
    std::lock_guard lock(mutex_);
    return latest_;
  }
  TakeOutcome& outcome() { return outcome_; }
  TakeFiles& files() { return files_; }

  std::vector<std::string> status_lines(double elapsed) {
    std::lock_guard lock(mutex_);
    std::vector<std::string> lines;
    char line[256];
    std::snprintf(line, sizeof line, "take %s  %.1f s  %d frame sets written  %lld incomplete  %lld dropped  %.1f MB/s",
                  request_.name.c_str(), elapsed, frames_.load(), (long long)outcome_.incomplete_sets,
                  (long long)(outcome_.incomplete_dropped + outcome_.writer_full_dropped),
                  elapsed > 0 ? writer_.bytes_written() / elapsed / 1e6 : 0.0);
    lines.push_back(line);
    const auto now = Clock::now();
    const double interval = std::chrono::duration<double>(now - last_status_).count();
    last_status_ = now;
    received_before_.resize(outcome_.cameras.size(), 0);
    for (size_t c = 0; c < outcome_.cameras.size(); ++c) {
      const auto& cam = outcome_.cameras[c];
      const auto stats = stream_.statistics(int(c));
      const double fps = interval > 0 ? (stats.received - received_before_[c]) / interval : 0;
      received_before_[c] = stats.received;
      std::snprintf(line, sizeof line, "  %-10s %6.1f fps  %5llu drops  queue %2d/%d%s", cam.name.c_str(), fps,
                    (unsigned long long)(stats.failures + stats.underruns + stats.late), writer_.queued(int(c)),
                    rig_.writer.queue_depth, cam.lost ? "  LOST" : "");
      lines.push_back(line);
    }
    return lines;
  }

 private:
  const RigConfig& rig_;
  const TakeRequest& request_;
  RigStream& stream_;
  TakeWriter& writer_;
  mutable std::mutex mutex_;
  TakeFiles files_;
  TakeOutcome outcome_;
  std::atomic<int> frames_{0};  // the main loop reads it to stop at --frames
  std::optional<FrameSet> latest_;
  Clock::time_point last_status_ = Clock::now();
  std::vector<uint64_t> received_before_;
};

}  // namespace

TakeOutcome record_take(const RigConfig& rig, const TakeRequest& request, const fs::path& capture_root,
                        const RecordHooks& hooks) {
  check_request(request);
  const fs::path takes = capture_root / "takes";
  const fs::path final_folder = takes / request.name;
  const fs::path recording_folder = takes / (request.name + ".recording");
  if (fs::exists(final_folder))
    throw Error(final_folder, "already exists: choose another take name (nothing was recorded)");
  if (fs::exists(recording_folder))
    throw Error(recording_folder, "holds an interrupted recording: move it away or delete it first");
  fs::create_directories(takes);
  check_free_space(takes, rig.writer.min_free_mb);

  RigStream stream(rig, request.trigger);  // opens and configures every camera, or throws
  std::vector<TakeWriter::Camera> writer_cameras;
  for (size_t c = 0; c < rig.cameras.size(); ++c) writer_cameras.push_back({rig.cameras[c].name, stream.format(int(c))});
  const std::string pixel_format = stream.format(0).name;
  for (const auto& c : writer_cameras)
    if (c.format.name != pixel_format)
      throw Error(rig.file, "every camera of a take must use one pixel format (" + rig.cameras[0].name + " uses " +
                                pixel_format + ", " + c.name + " uses " + c.format.name + ")");

  fs::create_directories(recording_folder);
  TakeFiles::Reserve reserve(recording_folder);
  TakeWriter writer(recording_folder, writer_cameras, rig.writer);
  writer.before_write = hooks.before_write;
  Recording recording(rig, request, stream, writer);
  auto& outcome = recording.outcome();

  InterruptGuard interrupt;
  LiveStatus status(request.live_status);
  const auto start = Clock::now();
  auto last_status = start, last_preview = start;
  recording.event(0, "acquisition started, trigger " + to_string(request.trigger));
  logging::info("recording take %s (%s, %s trigger%s) from %zu cameras into %s", request.name.c_str(),
                request.kind.c_str(), to_string(request.trigger).c_str(),
                request.trigger == Trigger::hardware ? "" : ", NOT synchronised", rig.cameras.size(),
                final_folder.c_str());
  try {
    stream.start([&](FrameSet set) { recording.on_set(std::move(set)); },
                 [&](int camera, const std::string& reason) { recording.camera_lost(camera, reason, seconds_since(start)); });
  } catch (...) {
    stream.stop();
    writer.finish();
    remove_tree(recording_folder);  // nothing was recorded: leave no interrupted recording behind
    throw;
  }

  while (true) {
    std::this_thread::sleep_for(kLoopInterval);
    stream.tick();
    const double elapsed = seconds_since(start);
    if (recording.target_reached()) {
      outcome.stop_reason = std::to_string(request.frames) + " frame sets written";
    } else if (request.seconds > 0 && elapsed >= request.seconds) {
      outcome.stop_reason = "recorded for " + std::to_string(int(std::lround(request.seconds))) + " s";
    } else if (InterruptGuard::requested() || (hooks.stop && hooks.stop->load())) {
      outcome.stop_reason = "stopped by the operator";
    } else if (writer.failed()) {
      outcome.stop_reason = "write error";
      outcome.error = writer.error();
    } else if (stream.active_cameras() == 0) {
      outcome.stop_reason = "every camera was lost";
    } else if (rig.sync.stop_on_camera_loss && recording.any_lost()) {
      outcome.stop_reason = "a camera was lost (sync.stop_on_camera_loss)";
    }
    if (!outcome.stop_reason.empty()) break;
    if (Clock::now() - last_status >= kStatusInterval) {
      status.show(recording.status_lines(elapsed));
      last_status = Clock::now();
    }
    if (!request.preview.empty() && Clock::now() - last_preview >= kPreviewInterval) {
      update_preview(recording.latest(), stream.formats(), request.preview);
      last_preview = Clock::now();
    }
  }
  stream.stop();  // the last sets it closes still reach recording.on_set
  writer.finish();
  if (writer.failed() && outcome.error.empty()) outcome.error = writer.error();
  status.show(recording.status_lines(seconds_since(start)));
  status.finish();
  recording.event(seconds_since(start), "acquisition stopped: " + outcome.stop_reason +
                                            (outcome.error.empty() ? "" : " (" + outcome.error + ")"));
  if (!request.preview.empty()) update_preview(recording.latest(), stream.formats(), request.preview);

  outcome.seconds = seconds_since(start);
  outcome.bytes = writer.bytes_written();
  for (size_t c = 0; c < rig.cameras.size(); ++c) {
    const auto stats = stream.statistics(int(c));
    auto& cam = outcome.cameras[c];
    cam.frames_received = stats.received;
    cam.stream_failures = stats.failures;
    cam.stream_underruns = stats.underruns;
    cam.late_frames = stats.late;
  }
  reserve.release();
  outcome.frames = recording.files().finalise(recording_folder, rig, request, stream, writer, outcome);
  fs::rename(recording_folder, final_folder);
  outcome.folder = final_folder;
  record_take_in_capture(capture_root, read_take(final_folder), stream.width(0), stream.height(0),
                         std::string("tega capture ") + TEGA_VERSION);
  return outcome;
}

nlohmann::json check_rig(const RigConfig& rig, Trigger trigger) {
  RigStream stream(rig, trigger);
  std::mutex mutex;
  std::condition_variable got;
  std::optional<FrameSet> first;
  stream.start(
      [&](FrameSet set) {
        std::lock_guard lock(mutex);
        if (!first && set.complete()) {
          first = std::move(set);
          got.notify_all();
        }
      },
      [](int, const std::string&) {});
  const double wait_s = rig.sync.camera_timeout_ms / 1000 + 2 / rig.settings.frame_rate;
  const auto deadline = Clock::now() + std::chrono::milliseconds(int(wait_s * 1000));
  {
    std::unique_lock lock(mutex);
    while (!first && Clock::now() < deadline) {
      lock.unlock();
      stream.tick();
      lock.lock();
      got.wait_for(lock, kLoopInterval);
    }
  }
  stream.stop();
  nlohmann::json report = {{"trigger", to_string(trigger)}, {"cameras", nlohmann::json::array()}};
  for (size_t c = 0; c < rig.cameras.size(); ++c) {
    nlohmann::json camera = {{"name", rig.cameras[c].name},
                             {"camera", stream.description(int(c))},
                             {"settings", stream.read_back(int(c))}};
    if (first && first->frames[c]) {
      const auto& f = *first->frames[c];
      camera["frame"] = {{"frame_id", f.frame_id}, {"width", f.width}, {"height", f.height},
                         {"host_timestamp_ns", f.host_ns}};
    }
    report["cameras"].push_back(camera);
  }
  if (!first)
    throw Error(rig.file, "no complete frame set within " + std::to_string(int(std::ceil(wait_s))) +
                              " s; cameras that sent nothing: " + stream.silent_cameras() +
                              (trigger == Trigger::hardware ? " (is the trigger generator running and wired?)" : ""));
  uint64_t earliest = UINT64_MAX, latest = 0;
  for (const auto& f : first->frames) earliest = std::min(earliest, f->host_ns), latest = std::max(latest, f->host_ns);
  report["frame_set_spread_ms"] = (latest - earliest) / 1e6;
  return report;
}

}  // namespace tega::capture
