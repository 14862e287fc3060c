#include "tega/capture/frame_set_assembler.h"

#include <algorithm>
#include <climits>
#include <cstdlib>

namespace tega::capture {

FrameSetAssembler::FrameSetAssembler(int cameras, int64_t tolerance, int64_t set_timeout_ns)
    : cameras_(cameras),
      tolerance_(tolerance),
      timeout_ns_(set_timeout_ns),
      active_(cameras, true),
      latest_key_(cameras, INT64_MIN),
      first_key_(cameras, INT64_MAX),
      late_(cameras, 0) {}

bool FrameSetAssembler::closable(const OpenSet& open, int64_t now_ns) const {
  if (now_ns - open.opened_ns >= timeout_ns_) return true;
  for (int c = 0; c < cameras_; ++c) {
    if (open.set.frames[c] || !active_[c]) continue;
    // A camera's frames arrive in order: once it delivered a later frame it
    // will never fill this set.
    if (latest_key_[c] <= open.set.key + tolerance_) return false;
  }
  return true;
}

std::vector<FrameSet> FrameSetAssembler::close_ready(int64_t now_ns) {
  std::vector<FrameSet> closed;
  while (!open_.empty() && closable(open_.front(), now_ns)) {
    FrameSet& set = open_.front().set;
    for (int c = 0; c < cameras_; ++c)
      if (!set.frames[c] && active_[c] && first_key_[c] > set.key + tolerance_) set.before_all_streaming = true;
    last_emitted_key_ = set.key;
    emitted_any_ = true;
    closed.push_back(std::move(open_.front().set));
    open_.erase(open_.begin());
  }
  return closed;
}

std::vector<FrameSet> FrameSetAssembler::add(Frame frame, int64_t key, int64_t now_ns) {
  const int c = frame.camera;
  latest_key_[c] = std::max(latest_key_[c], key);
  first_key_[c] = std::min(first_key_[c], key);
  if (!active_[c] || (emitted_any_ && key <= last_emitted_key_ + tolerance_)) {
    ++late_[c];
    return close_ready(now_ns);
  }
  OpenSet* best = nullptr;
  for (auto& open : open_) {
    const int64_t distance = std::llabs(open.set.key - key);
    if (distance <= tolerance_ && !open.set.frames[c] &&
        (!best || distance < std::llabs(best->set.key - key)))
      best = &open;
  }
  if (best) {
    best->set.frames[c] = std::move(frame);
  } else {
    auto at = std::upper_bound(open_.begin(), open_.end(), key,
                               [](int64_t k, const OpenSet& open) { return k < open.set.key; });
    OpenSet fresh{FrameSet{key, std::vector<std::optional<Frame>>(cameras_)}, now_ns};
    fresh.set.frames[c] = std::move(frame);
    open_.insert(at, std::move(fresh));
  }
  return close_ready(now_ns);
}

std::vector<FrameSet> FrameSetAssembler::tick(int64_t now_ns) { return close_ready(now_ns); }

std::vector<FrameSet> FrameSetAssembler::drop_camera(int camera, int64_t now_ns) {
  active_[camera] = false;
  return close_ready(now_ns);
}

std::vector<FrameSet> FrameSetAssembler::flush() {
  std::vector<FrameSet> closed;
  for (auto& open : open_) closed.push_back(std::move(open.set));
  open_.clear();
  return closed;
}

int64_t FrameIdUnwrapper::operator()(uint64_t raw) {
  if (period_ > 0 && seen_ && raw < last_ && last_ - raw > static_cast<uint64_t>(period_ / 2)) offset_ += period_;
  seen_ = true;
  last_ = raw;
  return static_cast<int64_t>(raw) + offset_;
}

}  // namespace tega::capture
