#pragma once
// Encoded frames kept for reuse within a byte budget, least recently used
// evicted first. Thread-safe.

#include <cstdint>
#include <list>
#include <memory>
#include <mutex>
#include <string>
#include <unordered_map>

namespace tega::serve {

class FrameCache {
 public:
  explicit FrameCache(int64_t budget_bytes) : budget_(budget_bytes) {}

  std::shared_ptr<const std::string> find(const std::string& key) {
    std::lock_guard lock(mutex_);
    const auto it = entries_.find(key);
    if (it == entries_.end()) return nullptr;
    order_.splice(order_.begin(), order_, it->second.position);
    return it->second.bytes;
  }

  void insert(const std::string& key, std::shared_ptr<const std::string> bytes) {
    std::lock_guard lock(mutex_);
    if (entries_.count(key)) return;
    used_ += static_cast<int64_t>(bytes->size());
    order_.push_front(key);
    entries_[key] = {std::move(bytes), order_.begin()};
    while (used_ > budget_ && !order_.empty()) {
      const auto oldest = entries_.find(order_.back());
      used_ -= static_cast<int64_t>(oldest->second.bytes->size());
      entries_.erase(oldest);
      order_.pop_back();
    }
  }

 private:
  struct Entry {
    std::shared_ptr<const std::string> bytes;
    std::list<std::string>::iterator position;
  };
  std::mutex mutex_;
  int64_t budget_, used_ = 0;
  std::list<std::string> order_;  // most recently used first
  std::unordered_map<std::string, Entry> entries_;
};

}  // namespace tega::serve
