#include "rig_stream.h"

#include <chrono>

#include "tega/core/error.h"

namespace tega::capture {

namespace {

constexpr int kPopTimeoutMs = 100;
constexpr int kExtraStreamBuffers = 8;  // beyond the writer queue: sets being assembled

int64_t now_ns() {
  return std::chrono::duration_cast<std::chrono::nanoseconds>(std::chrono::steady_clock::now().time_since_epoch())
      .count();
}

}  // namespace

RigStream::RigStream(const RigConfig& rig, Trigger trigger) : rig_(rig), trigger_(trigger) {
  std::vector<CameraDescription> discovered;
  if (rig.source == "aravis") {
    std::vector<std::string> serials;
    for (const auto& c : rig.cameras) serials.push_back(c.serial);
    discovered = discover_cameras(serials);
  }
  std::string refused;
  for (size_t c = 0; c < rig.cameras.size(); ++c) {
    const auto& config = rig.cameras[c];
    cameras_.push_back(std::make_unique<Camera>(config, int(c), rig.source, discovered));
    for (const auto& problem : cameras_.back()->configure(config.settings, trigger))
      refused += "\n  camera " + config.name + " (serial " + config.serial + "): " + problem;
    unwrappers_.emplace_back(16);  // GigE Vision 1.x block ids are 16-bit; wider counters never wrap here
    last_frame_ns_.push_back(std::make_unique<std::atomic<int64_t>>(0));
    received_.push_back(std::make_unique<std::atomic<uint64_t>>(0));
    late_.push_back(std::make_unique<std::atomic<uint64_t>>(0));
  }
  if (!refused.empty()) throw Error(rig.file, "cameras refused settings; nothing was recorded:" + refused);
  lost_ = std::make_unique<std::atomic<bool>[]>(cameras_.size());
  const double period_ns = 1e9 / rig.settings.frame_rate;
  const int64_t tolerance = rig.sync.group_by == "frame_id" ? 0
                            : rig.sync.tolerance_ms > 0   ? int64_t(rig.sync.tolerance_ms * 1e6)
                                                          : int64_t(period_ns / 2);
  assembler_ = std::make_unique<FrameSetAssembler>(int(cameras_.size()), tolerance,
                                                   int64_t(rig.sync.set_timeout_ms * 1e6));
}

RigStream::~RigStream() { stop(); }

void RigStream::start(SetCallback on_set, LostCallback on_lost) {
  on_set_ = std::move(on_set);
  on_lost_ = std::move(on_lost);
  for (auto& camera : cameras_) camera->start(rig_.writer.queue_depth + kExtraStreamBuffers);
  started_ns_ = now_ns();
  running_ = true;
  for (size_t c = 0; c < cameras_.size(); ++c) threads_.emplace_back([this, c] { grab(int(c)); });
  if (trigger_ == Trigger::software) {
    const auto first = std::chrono::steady_clock::now();
    for (size_t c = 0; c < cameras_.size(); ++c)
      threads_.emplace_back([this, c, first] { fire_software_triggers(int(c), first); });
  }
}

void RigStream::stop() {
  if (!running_.exchange(false)) return;
  for (auto& t : threads_) t.join();
  threads_.clear();
  for (auto& camera : cameras_) camera->stop();
  std::lock_guard lock(mutex_);
  assembler_->flush();  // dropped: see the header
}

int64_t RigStream::key_of(const Frame& frame) {
  if (rig_.sync.group_by == "frame_id") return unwrappers_[frame.camera](frame.frame_id);
  return int64_t(rig_.sync.timestamp_source == "device" ? frame.device_ns : frame.host_ns);
}

void RigStream::deliver(std::vector<FrameSet> sets) {
  for (size_t c = 0; c < cameras_.size(); ++c) late_[c]->store(uint64_t(assembler_->late_frames()[c]));
  for (auto& set : sets) on_set_(std::move(set));
}

void RigStream::grab(int camera) {
  while (running_) {
    auto frame = cameras_[camera]->next_frame(kPopTimeoutMs);
    if (!frame) continue;
    ++*received_[camera];
    last_frame_ns_[camera]->store(now_ns());
    std::lock_guard lock(mutex_);
    const int64_t key = key_of(*frame);
    deliver(assembler_->add(std::move(*frame), key, now_ns()));
  }
}

// A thread per camera: a camera that stops answering blocks only its own
// trigger. The commands still reach the cameras milliseconds apart: never a
// synchronised rig.
void RigStream::fire_software_triggers(int camera, std::chrono::steady_clock::time_point first) {
  const auto period = std::chrono::nanoseconds(int64_t(1e9 / rig_.settings.frame_rate));
  auto next = first;
  while (running_ && !lost_[camera]) {
    cameras_[camera]->software_trigger();
    next += period;
    if (next < std::chrono::steady_clock::now()) next = std::chrono::steady_clock::now();  // no burst after a stall
    std::this_thread::sleep_until(next);
  }
}

void RigStream::lose(int camera, const std::string& reason) {
  lost_[camera] = true;
  on_lost_(camera, reason);
  deliver(assembler_->drop_camera(camera, now_ns()));
}

void RigStream::tick() {
  std::lock_guard lock(mutex_);
  const int64_t now = now_ns();
  const auto timeout = int64_t(rig_.sync.camera_timeout_ms * 1e6);
  // Silence is only a loss while others deliver: with no trigger pulses at all, every camera is silent.
  bool someone_delivers = false;
  for (size_t c = 0; c < cameras_.size(); ++c)
    if (!lost_[c] && last_frame_ns_[c]->load() > 0 && now - last_frame_ns_[c]->load() < timeout)
      someone_delivers = true;
  for (size_t c = 0; c < cameras_.size(); ++c) {
    if (lost_[c]) continue;
    if (cameras_[c]->control_lost()) {
      lose(int(c), "its control connection dropped");
    } else if (someone_delivers) {
      const int64_t last = last_frame_ns_[c]->load();
      if (now - (last > 0 ? last : started_ns_) >= timeout)
        lose(int(c), "no frame for " + std::to_string(int(rig_.sync.camera_timeout_ms)) + " ms while the others delivered");
    }
  }
  deliver(assembler_->tick(now));
}

RigStream::Statistics RigStream::statistics(int camera) const {
  const auto s = cameras_[camera]->statistics();
  return {received_[camera]->load(), s.failures, s.underruns, late_[camera]->load()};
}

int RigStream::active_cameras() const {
  int n = 0;
  for (size_t c = 0; c < cameras_.size(); ++c) n += lost_[c] ? 0 : 1;
  return n;
}

std::string RigStream::silent_cameras() const {
  std::string names;
  for (size_t c = 0; c < cameras_.size(); ++c)
    if (received_[c]->load() == 0) names += (names.empty() ? "" : ", ") + rig_.cameras[c].name;
  return names.empty() ? "none" : names;
}

std::vector<PixelFormatInfo> RigStream::formats() const {
  std::vector<PixelFormatInfo> formats;
  for (const auto& c : cameras_) formats.push_back(c->format());
  return formats;
}

}  // namespace tega::capture
