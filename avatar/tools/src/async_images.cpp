#include "async_images.h"

#include <memory>
#include <stdexcept>

#include "image_tensors.h"
#include "tega/core/image.h"

namespace tega::tools::detail {

namespace fs = std::filesystem;

namespace {

constexpr int kRenderPngLevel = 1;  // the capture writer's: several times faster than zlib's default

}  // namespace

BackgroundImageWriter::BackgroundImageWriter(int threads) : pool_(threads) {}

void BackgroundImageWriter::write(const at::Tensor& rgb, const fs::path& file) {
  if (file.extension() == ".exr") {
    auto image = std::make_shared<ImageF>(to_image(rgb));
    submit([image, file] { write_image(*image, file); });
  } else {
    auto image = std::make_shared<Image8>(to_image8(rgb));
    submit([image, file] {
      write_png_view({image->pixels.data(), image->width, image->height, image->channels, 8,
                      size_t(image->width) * image->channels},
                     file, kRenderPngLevel);
    });
  }
}

void BackgroundImageWriter::submit(std::function<void()> task) {
  while (pending_.size() >= static_cast<size_t>(pool_.size())) wait_for_oldest();
  pending_.push_back(pool_.submit(std::move(task)));
}

void BackgroundImageWriter::finish() {
  while (!pending_.empty()) wait_for_oldest();
}

void BackgroundImageWriter::wait_for_oldest() {
  std::future<void> oldest = std::move(pending_.front());
  pending_.pop_front();
  oldest.get();
}

ImagePrefetcher::ImagePrefetcher(std::vector<fs::path> files, int threads)
    : files_(std::move(files)), pool_(threads) {
  request_more();
}

void ImagePrefetcher::request_more() {
  while (requested_ < files_.size() && ready_.size() < static_cast<size_t>(pool_.size())) {
    ready_.push_back(pool_.submit([file = files_[requested_]] { return read_rgba(file); }));
    ++requested_;
  }
}

at::Tensor ImagePrefetcher::next() {
  if (ready_.empty()) throw std::out_of_range("ImagePrefetcher: every file was read");
  std::future<at::Tensor> front = std::move(ready_.front());
  ready_.pop_front();
  request_more();
  return front.get();
}

}  // namespace tega::tools::detail
