#include "tega/capture/take_writer.h"

#include <cstdio>
#include <cstring>

#include "disk_space.h"
#include "tega/core/error.h"
#include "tega/core/image.h"
#include "tega/core/take_images.h"
#include "tega/core/thread_pool.h"

namespace tega::capture {

namespace fs = std::filesystem;

namespace {

constexpr int kSpaceCheckInterval = 32;  // images between free-space checks

// Holds converted pixels when the camera's buffer cannot be stored as is.
struct Converted {
  std::vector<uint8_t> bytes;
  PixelView view;
};

Converted convert(const Frame& frame, const PixelFormatInfo& format, bool debayer) {
  Converted out;
  const int bytes_per_sample = format.bits / 8;
  out.view = {frame.pixels, frame.width, frame.height, format.channels, format.bits,
              size_t(frame.width) * format.bytes_per_pixel};
  if (format.bgr) {
    out.bytes.assign(frame.pixels, frame.pixels + out.view.row_bytes * frame.height);
    for (size_t i = 0; i + 2 < out.bytes.size(); i += 3) std::swap(out.bytes[i], out.bytes[i + 2]);
    out.view.data = out.bytes.data();
  } else if (debayer && !format.bayer.empty()) {
    out.bytes.resize(size_t(frame.width) * frame.height * 3 * bytes_per_sample);
    demosaic(frame.pixels, frame.width, frame.height, bytes_per_sample, format.name, out.bytes.data());
    out.view = {out.bytes.data(), frame.width, frame.height, 3, format.bits, size_t(frame.width) * 3 * bytes_per_sample};
  }
  return out;
}

template <typename T>
ImageBuffer<T> copy_of(const PixelView& view) {
  ImageBuffer<T> image(view.width, view.height, view.channels);
  const size_t row = size_t(view.width) * view.channels * sizeof(T);
  for (int y = 0; y < view.height; ++y)
    std::memcpy(&image.at(0, y, 0), static_cast<const uint8_t*>(view.data) + y * view.row_bytes, row);
  return image;
}

}  // namespace

TakeWriter::TakeWriter(fs::path take_folder, std::vector<Camera> cameras, const WriterOptions& options)
    : folder_(std::move(take_folder)),
      cameras_(std::move(cameras)),
      options_(options),
      extension_(options.format == "tiff" ? ".tif" : ".png"),
      pool_(std::make_unique<ThreadPool>(options.threads)) {
  if (options_.format == "tiff" && !image_format_supported("x.tif"))
    throw Error("writer.format tiff needs a build with OpenImageIO; use png");
  for (const auto& c : cameras_)
    if (options_.debayer && !c.format.bayer.empty() && !demosaicing_available())
      throw Error("writer.debayer needs a build with OpenCV (camera " + c.name + " is " + c.format.name + ")");
  for (const auto& c : cameras_) {
    fs::create_directories(folder_ / c.name);
    queued_.push_back(std::make_unique<std::atomic<int>>(0));
  }
}

TakeWriter::~TakeWriter() { finish(); }

bool TakeWriter::submit(const FrameSet& set, int index) {
  if (failed_) return false;
  for (size_t c = 0; c < cameras_.size(); ++c)
    if (set.frames[c] && queued_[c]->load() >= options_.queue_depth) return false;
  {
    std::lock_guard lock(mutex_);
    if (written_.size() <= size_t(index)) written_.resize(index + 1, std::vector<uint8_t>(cameras_.size(), 0));
  }
  for (size_t c = 0; c < cameras_.size(); ++c) {
    if (!set.frames[c]) continue;
    ++*queued_[c];
    ++in_flight_;
    pool_->submit([this, frame = *set.frames[c], index] {
      write(frame, index);
      --*queued_[frame.camera];
      std::lock_guard lock(idle_mutex_);
      if (--in_flight_ == 0) idle_.notify_all();
    });
  }
  return true;
}

void TakeWriter::write(const Frame& frame, int index) {
  if (failed_) return;
  const auto& camera = cameras_[frame.camera];
  char name[32];
  std::snprintf(name, sizeof name, "%06d", index);
  const fs::path file = folder_ / camera.name / (name + extension_);
  try {
    const size_t expected = size_t(frame.width) * frame.height * camera.format.bytes_per_pixel;
    if (frame.size < expected)
      throw Error(file, "camera " + camera.name + " delivered " + std::to_string(frame.size) + " bytes for a " +
                            std::to_string(frame.width) + "x" + std::to_string(frame.height) + " " +
                            camera.format.name + " frame (" + std::to_string(expected) + " expected)");
    if (++writes_since_space_check_ % kSpaceCheckInterval == 0 && options_.min_free_mb > 0) {
      const double free = free_mb(folder_);
      if (free >= 0 && free < options_.min_free_mb)
        throw Error(folder_, "disk nearly full: " + std::to_string(int(free)) + " MB free, writer.min_free_mb is " +
                                 std::to_string(int(options_.min_free_mb)));
    }
    if (before_write) before_write(file);
    const Converted pixels = convert(frame, camera.format, options_.debayer);
    if (extension_ == ".png") {
      write_png_view(pixels.view, file, options_.png_compression);
    } else if (pixels.view.bit_depth == 16) {
      write_image(copy_of<uint16_t>(pixels.view), file);
    } else {
      write_image(copy_of<uint8_t>(pixels.view), file);
    }
    bytes_ += fs::file_size(file);
    std::lock_guard lock(mutex_);
    written_[index][frame.camera] = 1;
  } catch (const std::exception& e) {
    fail(e.what());
  }
}

void TakeWriter::fail(const std::string& message) {
  std::lock_guard lock(mutex_);
  if (!failed_.exchange(true)) error_ = message;
}

std::string TakeWriter::error() const {
  std::lock_guard lock(mutex_);
  return error_;
}

void TakeWriter::finish() {
  std::unique_lock lock(idle_mutex_);
  idle_.wait(lock, [this] { return in_flight_.load() == 0; });
}

bool TakeWriter::written(int index, int camera) const {
  std::lock_guard lock(mutex_);
  return size_t(index) < written_.size() && written_[index][camera];
}

}  // namespace tega::capture
