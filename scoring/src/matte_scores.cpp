#include "tega/scoring/matte_scores.h"

#include <algorithm>
#include <vector>
#include <opencv2/imgproc.hpp>

#include "tega/core/error.h"
#include "tega/core/image.h"
#include "tega/core/progress.h"
#include "tega/core/thread_pool.h"

namespace tega::scoring {
namespace fs = std::filesystem;

namespace {

cv::Mat alpha_of(const fs::path& file) {
  const Image8 image = read_image_u8(file);
  if (image.channels != 1) throw Error(file, "is not a one-channel matte");
  cv::Mat alpha;
  cv::Mat(image.height, image.width, CV_8U, const_cast<uint8_t*>(image.pixels.data())).convertTo(alpha, CV_32F, 1.0 / 255);
  return alpha;
}

}  // namespace

MatteScores score_mattes(const fs::path& mattes, const fs::path& capture, const std::string& take, int boundary_px) {
  const fs::path truth_root = capture / "ground_truth" / take / "alpha";
  std::vector<fs::path> files;
  for (const auto& camera_dir : fs::directory_iterator(mattes / take)) {
    if (!camera_dir.is_directory()) continue;
    for (const auto& entry : fs::directory_iterator(camera_dir.path()))
      if (entry.path().extension() == ".png") files.push_back(entry.path());
  }
  if (files.empty()) throw Error(mattes / take, "holds no matte to score");
  std::sort(files.begin(), files.end());  // the same sums whatever order the folders list

  struct ImageScores {
    double mean, boundary, iou;
  };
  std::vector<ImageScores> per_image(files.size());
  Progress progress("scoring the mattes of take " + take + " against the studio's alpha", int64_t(files.size()),
                    "images");
  ThreadPool pool;
  pool.parallel_for(0, int64_t(files.size()), [&](int64_t i) {
    const fs::path& file = files[size_t(i)];
    const cv::Mat alpha = alpha_of(file);
    const cv::Mat truth = alpha_of(truth_root / file.parent_path().filename() / file.filename());
    if (alpha.size() != truth.size()) throw Error(file, "differs in size from the true alpha");
    cv::Mat error;
    cv::absdiff(alpha, truth, error);
    const cv::Mat inside = truth >= 0.5f;
    cv::Mat to_edge_inside, to_edge_outside;
    cv::distanceTransform(inside, to_edge_inside, cv::DIST_L2, cv::DIST_MASK_PRECISE);
    cv::distanceTransform(inside == 0, to_edge_outside, cv::DIST_L2, cv::DIST_MASK_PRECISE);
    const cv::Mat near_edge = ((to_edge_inside <= boundary_px) & inside) | ((to_edge_outside <= boundary_px) & (inside == 0));
    const cv::Mat ours = alpha >= 0.5f;
    const double union_pixels = cv::countNonZero(ours | inside);
    per_image[size_t(i)] = {cv::mean(error)[0], cv::countNonZero(near_edge) ? cv::mean(error, near_edge)[0] : 0.0,
                            union_pixels > 0 ? cv::countNonZero(ours & inside) / union_pixels : 1.0};
    progress.advance();
  });
  progress.finish();

  MatteScores scores;
  scores.worst_iou = 1;
  for (size_t i = 0; i < per_image.size(); ++i) {
    const ImageScores& image = per_image[i];
    const std::string name = (files[i].parent_path().filename() / files[i].filename()).string();
    ++scores.images;
    scores.mean_error += image.mean;
    scores.boundary_error += image.boundary;
    scores.iou += image.iou;
    if (image.mean >= scores.worst_mean_error) {
      scores.worst_mean_error = image.mean;
      scores.worst_mean_image = name;
    }
    if (image.boundary >= scores.worst_boundary_error) {
      scores.worst_boundary_error = image.boundary;
      scores.worst_boundary_image = name;
    }
    if (image.iou <= scores.worst_iou) {
      scores.worst_iou = image.iou;
      scores.worst_iou_image = name;
    }
  }
  scores.mean_error /= scores.images;
  scores.boundary_error /= scores.images;
  scores.iou /= scores.images;
  return scores;
}

}  // namespace tega::scoring
