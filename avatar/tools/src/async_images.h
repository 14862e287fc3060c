#pragma once
// Image files read and written on worker threads while the GPU renders (private to tega_tools).
// At the studio's size a PNG takes longer to encode or decode than a view takes to render and
// score: `tega render` and `tega eval` ran at 1.3 and 3.5 images a second on an H200 with the
// files handled in line.

#include <ATen/ATen.h>

#include <deque>
#include <filesystem>
#include <functional>
#include <future>
#include <vector>

#include "tega/core/thread_pool.h"

namespace tega::tools::detail {

// Renders written as PNG (8-bit RGB, zlib level 1, as the capture writes) or EXR (float), a few
// at a time. write() waits while as many files as there are threads are still in hand; finish()
// waits for all. Either rethrows the first failed write's error, which names the file.
class BackgroundImageWriter {
 public:
  explicit BackgroundImageWriter(int threads = 0);  // 0: default_thread_count()
  // A float RGB [3,H,W] tensor in [0,1], on any device: copied to the host before it returns.
  void write(const at::Tensor& rgb, const std::filesystem::path& file);
  void finish();

 private:
  void submit(std::function<void()> task);
  void wait_for_oldest();  // rethrows its error

  ThreadPool pool_;
  std::deque<std::future<void>> pending_;
};

// Dataset images (uint8 RGBA [H,W,4], as read_rgba) read in the order given, up to one per
// thread ahead of the one asked for.
class ImagePrefetcher {
 public:
  explicit ImagePrefetcher(std::vector<std::filesystem::path> files, int threads = 0);
  // The next file's image; rethrows its read error. Throws std::out_of_range past the last.
  at::Tensor next();

 private:
  void request_more();

  std::vector<std::filesystem::path> files_;
  size_t requested_ = 0;
  ThreadPool pool_;
  std::deque<std::future<at::Tensor>> ready_;
};

}  // namespace tega::tools::detail
