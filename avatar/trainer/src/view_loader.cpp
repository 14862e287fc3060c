#include "tega/trainer/view_loader.h"

#include <ATen/ATen.h>

#include <algorithm>
#include <numeric>
#include <random>

#include "tega/core/error.h"

namespace tega::trainer {

ViewLoader::ViewLoader(const Dataset& dataset, std::vector<View> views, uint64_t seed, int threads, int prefetch,
                       bool pin_memory)
    : dataset_(dataset), views_(std::move(views)), seed_(seed), prefetch_(std::max(1, prefetch)),
      pin_memory_(pin_memory) {
  if (views_.empty()) throw Error(dataset.root, "has no training views (empty train split)");
  threads = std::max(1, threads);
  for (int i = 0; i < threads; ++i) workers_.emplace_back([this] { work(); });
}

ViewLoader::~ViewLoader() {
  {
    std::lock_guard lock(mutex_);
    stopping_ = true;
  }
  wake_workers_.notify_all();
  for (auto& w : workers_) w.join();
}

View ViewLoader::view_at(int64_t position) const {
  const auto n = static_cast<int64_t>(views_.size());
  const int64_t epoch = position / n;
  // A fresh permutation per epoch, from a generator seeded by (seed, epoch):
  // O(n) per call, which is negligible next to decoding one image.
  std::vector<int> order(views_.size());
  std::iota(order.begin(), order.end(), 0);
  std::mt19937_64 rng(seed_ * 0x9E3779B97F4A7C15ull + static_cast<uint64_t>(epoch));
  for (int64_t i = n - 1; i > 0; --i) {
    std::uniform_int_distribution<int64_t> pick(0, i);
    std::swap(order[i], order[pick(rng)]);
  }
  return views_[order[position % n]];
}

int64_t ViewLoader::position() const {
  std::lock_guard lock(mutex_);
  return position_;
}

void ViewLoader::seek(int64_t position) {
  {
    std::lock_guard lock(mutex_);
    position_ = next_to_schedule_ = position;
    slots_.clear();
    ++generation_;
  }
  wake_workers_.notify_all();
}

void ViewLoader::work() {
  std::unique_lock lock(mutex_);
  for (;;) {
    wake_workers_.wait(lock, [this] { return stopping_ || next_to_schedule_ < position_ + prefetch_; });
    if (stopping_) return;
    const int64_t position = next_to_schedule_++;
    const uint64_t generation = generation_;
    slots_[position];  // reserve, so next() knows it is in flight
    lock.unlock();

    const View view = view_at(position);
    Slot result;
    try {
      const auto& camera = dataset_.rig.cameras[view.camera];
      const auto path = dataset_.image_path(camera.name, dataset_.frames[view.frame].id);
      auto image = std::make_shared<Image8>(read_image_u8(path));
      if (image->channels != 4 || image->width != camera.width || image->height != camera.height) {
        throw Error(path, "is not a " + std::to_string(camera.width) + "x" + std::to_string(camera.height) +
                              " RGBA image");
      }
      result.rgba = at::from_blob(
          image->pixels.data(), {image->height, image->width, 4}, [image](void*) {}, at::TensorOptions(at::kByte));
      if (pin_memory_) result.rgba = result.rgba.pin_memory();
    } catch (const std::exception& e) {
      result.error = e.what();
    }
    result.ready = true;

    lock.lock();
    if (generation == generation_) {
      slots_[position] = std::move(result);
      wake_consumer_.notify_all();
    }
  }
}

LoadedView ViewLoader::next() {
  std::unique_lock lock(mutex_);
  const int64_t position = position_;
  wake_consumer_.wait(lock, [&] {
    auto it = slots_.find(position);
    return it != slots_.end() && it->second.ready;
  });
  Slot slot = std::move(slots_[position]);
  slots_.erase(position);
  ++position_;
  lock.unlock();
  wake_workers_.notify_all();
  if (!slot.error.empty()) throw Error(slot.error);

  return {view_at(position), slot.rgba};
}

}  // namespace tega::trainer
