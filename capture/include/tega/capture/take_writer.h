#pragma once
// Writes frame sets into a take folder as lossless images,
// <camera>/<index:06d>.png (or .tif), on a pool of threads. Each camera has a
// bounded queue: a frame set that finds any camera's queue full is refused
// whole (the recorder counts it as dropped), so a slow disk costs whole sets,
// never single images. The first write error (a full disk, an I/O error)
// fails the writer: queued images are not written, and the recorder stops.
#include <atomic>
#include <condition_variable>
#include <cstdint>
#include <filesystem>
#include <functional>
#include <memory>
#include <mutex>
#include <string>
#include <vector>

#include "tega/capture/frame.h"
#include "tega/capture/options.h"
#include "tega/capture/pixel_format.h"

namespace tega {
class ThreadPool;
}

namespace tega::capture {

class TakeWriter {
 public:
  struct Camera {
    std::string name;
    PixelFormatInfo format;
  };
  TakeWriter(std::filesystem::path take_folder, std::vector<Camera> cameras, const WriterOptions& options);
  ~TakeWriter();  // waits for queued writes
  TakeWriter(const TakeWriter&) = delete;
  TakeWriter& operator=(const TakeWriter&) = delete;

  // Queues the set's frames as frame `index` (indices count up from 0).
  // False, with nothing queued, when a camera's queue is full or the writer failed.
  bool submit(const FrameSet& set, int index);
  void finish();  // waits until every queued image is written or abandoned

  bool failed() const { return failed_.load(); }
  std::string error() const;
  int queued(int camera) const { return queued_[camera]->load(); }
  uint64_t bytes_written() const { return bytes_.load(); }
  // Whether the image of (frame index, camera) is on disk; valid after finish().
  bool written(int index, int camera) const;
  std::string extension() const { return extension_; }

  // Called before each image is written, with its final path; tests throw
  // from it to inject a write error.
  std::function<void(const std::filesystem::path&)> before_write;

 private:
  void write(const Frame& frame, int index);
  void fail(const std::string& message);

  std::filesystem::path folder_;
  std::vector<Camera> cameras_;
  WriterOptions options_;
  std::string extension_;
  std::vector<std::unique_ptr<std::atomic<int>>> queued_;
  std::atomic<bool> failed_{false};
  std::atomic<uint64_t> bytes_{0};
  std::atomic<int> writes_since_space_check_{0};
  mutable std::mutex mutex_;  // error_, written_
  std::string error_;
  std::vector<std::vector<uint8_t>> written_;  // [index][camera]
  std::atomic<int> in_flight_{0};
  std::condition_variable idle_;
  std::mutex idle_mutex_;
  std::unique_ptr<ThreadPool> pool_;
};

}  // namespace tega::capture
