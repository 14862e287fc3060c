#include "tega/scoring/matte_scores.h"

#include <algorithm>
#include <opencv2/imgproc.hpp>

#include "tega/core/error.h"
#include "tega/core/image.h"

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
  MatteScores scores;
  scores.worst_iou = 1;
  const fs::path truth_root = capture / "ground_truth" / take / "alpha";
  for (const auto& camera_dir : fs::directory_iterator(mattes / take)) {
    if (!camera_dir.is_directory()) continue;
    for (const auto& entry : fs::directory_iterator(camera_dir.path())) {
      if (entry.path().extension() != ".png") continue;
      const cv::Mat alpha = alpha_of(entry.path());
      const cv::Mat truth = alpha_of(truth_root / camera_dir.path().filename() / entry.path().filename());
      if (alpha.size() != truth.size()) throw Error(entry.path(), "differs in size from the true alpha");
      cv::Mat error;
      cv::absdiff(alpha, truth, error);
      const cv::Mat inside = truth >= 0.5f;
      cv::Mat to_edge_inside, to_edge_outside;
      cv::distanceTransform(inside, to_edge_inside, cv::DIST_L2, cv::DIST_MASK_PRECISE);
      cv::distanceTransform(inside == 0, to_edge_outside, cv::DIST_L2, cv::DIST_MASK_PRECISE);
      const cv::Mat near_edge = ((to_edge_inside <= boundary_px) & inside) | ((to_edge_outside <= boundary_px) & (inside == 0));
      const double mean = cv::mean(error)[0];
      const double boundary = cv::countNonZero(near_edge) ? cv::mean(error, near_edge)[0] : 0.0;
      const cv::Mat ours = alpha >= 0.5f;
      const double union_pixels = cv::countNonZero(ours | inside);
      const double iou = union_pixels > 0 ? cv::countNonZero(ours & inside) / union_pixels : 1.0;
      ++scores.images;
      scores.mean_error += mean;
      scores.boundary_error += boundary;
      scores.iou += iou;
      scores.worst_mean_error = std::max(scores.worst_mean_error, mean);
      scores.worst_boundary_error = std::max(scores.worst_boundary_error, boundary);
      scores.worst_iou = std::min(scores.worst_iou, iou);
    }
  }
  if (scores.images == 0) throw Error(mattes / take, "holds no matte to score");
  scores.mean_error /= scores.images;
  scores.boundary_error /= scores.images;
  scores.iou /= scores.images;
  return scores;
}

}  // namespace tega::scoring
