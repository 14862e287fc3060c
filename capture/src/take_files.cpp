#include "take_files.h"

#include <fcntl.h>
#include <unistd.h>

#include <sstream>

#include "rig_stream.h"
#include "tega/capture/take_writer.h"
#include "tega/core/error.h"
#include "tega/core/files.h"
#include "tega/core/take.h"

namespace tega::capture {

namespace fs = std::filesystem;

namespace {

constexpr off_t kReserveBytes = 16 << 20;  // the manifest of ~100k frame sets of 13 cameras

std::string stored_pixel_format(const PixelFormatInfo& format, bool debayered) {
  if (!debayered || format.bayer.empty()) return format.bgr ? "RGB8" : format.name;
  return format.bits == 16 ? "RGB16" : "RGB8";
}

nlohmann::json camera_json(const CameraOutcome& c, const CameraConfig& config, const RigStream& stream, int index) {
  nlohmann::json j = {{"name", c.name},
                      {"serial", config.serial},
                      {"camera", stream.description(index)},
                      {"settings_read_back", stream.read_back(index)},
                      {"frames_received", c.frames_received},
                      {"frames_written", c.frames_written},
                      {"stream_failures", c.stream_failures},
                      {"stream_underruns", c.stream_underruns},
                      {"late_frames", c.late_frames},
                      {"lost", nullptr}};
  if (c.lost) j["lost"] = {{"reason", c.lost_reason}, {"from_frame", c.lost_from_frame}};
  return j;
}

}  // namespace

SetRecord TakeFiles::record(const FrameSet& set) const {
  SetRecord r;
  r.key = set.key;
  for (const auto& f : set.frames) {
    if (f) {
      r.cameras.push_back(SetRecord::Stamp{f->frame_id, f->device_ns, f->host_ns});
    } else {
      r.cameras.push_back(std::nullopt);
    }
  }
  return r;
}

int TakeFiles::finalise(const fs::path& folder, const RigConfig& rig, const TakeRequest& request,
                        const RigStream& stream, const TakeWriter& writer, TakeOutcome& outcome) {
  int frames = 0;
  for (const auto& s : sets_) frames = std::max(frames, s.frame + 1);
  // A write error can leave the last frame sets without a single image: they are not part of the take.
  const auto any_written = [&](int i) {
    for (size_t c = 0; c < cameras_; ++c)
      if (writer.written(i, int(c))) return true;
    return false;
  };
  while (frames > 0 && !any_written(frames - 1)) --frames;

  TakeInfo take;
  take.name = request.name;
  take.kind = request.kind;
  for (const auto& c : rig.cameras) take.cameras.push_back(c.name);
  take.frames = frames;
  take.fps = rig.settings.frame_rate;
  take.images = "{camera}/{frame:06d}" + writer.extension();
  take.pixel_format = stored_pixel_format(stream.format(0), rig.writer.debayer);
  take.bit_depth = stream.format(0).bits;
  for (size_t c = 0; c < cameras_; ++c) {
    int written = 0;
    for (int i = 0; i < frames; ++i) {
      if (writer.written(i, int(c))) {
        ++written;
      } else {
        take.missing[rig.cameras[c].name].push_back(i);
      }
    }
    outcome.cameras[c].frames_written = written;
  }
  write_take(take, folder);

  nlohmann::json cameras = nlohmann::json::array();
  for (size_t c = 0; c < cameras_; ++c) cameras.push_back(camera_json(outcome.cameras[c], rig.cameras[c], stream, int(c)));
  nlohmann::json events = nlohmann::json::array();
  for (const auto& e : events_) events.push_back({{"t", e.t}, {"message", e.message}});
  const nlohmann::json manifest = {
      {"format", "tega-take-manifest"},
      {"version", 1},
      {"take", request.name},
      {"kind", request.kind},
      {"trigger", to_string(request.trigger)},
      {"synchronised", request.trigger == Trigger::hardware},
      {"source", rig.source},
      {"sync",
       {{"group_by", rig.sync.group_by},
        {"timestamp_source", rig.sync.timestamp_source},
        {"tolerance_ms", rig.sync.tolerance_ms > 0 ? rig.sync.tolerance_ms : 500.0 / rig.settings.frame_rate},
        {"incomplete_sets", rig.sync.incomplete_sets}}},
      {"writer",
       {{"format", rig.writer.format},
        {"png_compression", rig.writer.png_compression},
        {"debayer", rig.writer.debayer},
        {"bytes", outcome.bytes}}},
      {"frames", frames},
      {"seconds", outcome.seconds},
      {"stop_reason", outcome.stop_reason},
      {"error", outcome.error.empty() ? nlohmann::json(nullptr) : nlohmann::json(outcome.error)},
      {"counts",
       {{"frame_sets_seen", outcome.sets_seen},
        {"before_all_streaming", outcome.before_all_streaming},
        {"incomplete", outcome.incomplete_sets},
        {"incomplete_dropped", outcome.incomplete_dropped},
        {"writer_full_dropped", outcome.writer_full_dropped}}},
      {"cameras", cameras},
      {"events", events},
      {"frame_sets", "frame_sets.csv"}};
  write_text_atomic(folder / "manifest.json", manifest.dump(2) + "\n");

  std::ostringstream csv;
  csv << "set,key,status,frame";
  for (const auto& c : rig.cameras) csv << "," << c.name << "_frame_id," << c.name << "_device_ns," << c.name << "_host_ns";
  csv << "\n";
  for (size_t s = 0; s < sets_.size(); ++s) {
    const auto& r = sets_[s];
    csv << s << "," << r.key << "," << r.status << "," << (r.frame < frames ? r.frame : -1);
    for (const auto& stamp : r.cameras) {
      if (stamp) {
        csv << "," << stamp->frame_id << "," << stamp->device_ns << "," << stamp->host_ns;
      } else {
        csv << ",,,";
      }
    }
    csv << "\n";
  }
  write_text_atomic(folder / "frame_sets.csv", csv.str());
  return frames;
}

TakeFiles::Reserve::Reserve(const fs::path& folder) : file_(folder / ".reserve") {
  const int fd = ::open(file_.c_str(), O_CREAT | O_WRONLY | O_TRUNC, 0644);
  if (fd < 0) throw Error(file_, "cannot be created");
  const int failed = posix_fallocate(fd, 0, kReserveBytes);
  ::close(fd);
  if (failed != 0) {
    fs::remove(file_);
    throw Error(folder, "cannot reserve " + std::to_string(kReserveBytes >> 20) + " MB for the take's manifest");
  }
}

void TakeFiles::Reserve::release() {
  std::error_code ignored;
  fs::remove(file_, ignored);
}

}  // namespace tega::capture
