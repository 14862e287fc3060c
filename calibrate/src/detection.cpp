#include "tega/calibrate/detection.h"

#include <opencv2/calib3d.hpp>
#include <opencv2/imgproc.hpp>

#include <algorithm>
#include <cmath>
#include <utility>

#include <Eigen/Dense>

#include "aruco_board.h"
#include "tega/core/error.h"
#include "tega/core/progress.h"
#include "tega/core/take_images.h"
#include "tega/core/thread_pool.h"

namespace tega::calibrate {
namespace {

// The image in grey; a grey image is wrapped, not copied.
cv::Mat grey_mat(const Image8& image) {
  const cv::Mat m(image.height, image.width, CV_8UC(image.channels), const_cast<uint8_t*>(image.pixels.data()));
  cv::Mat grey;
  switch (image.channels) {
    case 1: return m;
    case 2: cv::extractChannel(m, grey, 0); break;  // grey + alpha
    case 3: cv::cvtColor(m, grey, cv::COLOR_RGB2GRAY); break;
    case 4: cv::cvtColor(m, grey, cv::COLOR_RGBA2GRAY); break;
    default: throw Error("detect_board: an image of " + std::to_string(image.channels) + " channels");
  }
  return grey;
}

// A chessboard corner is a saddle of the (slightly blurred) intensity: fit a
// quadratic to a window centred on the estimate, move to its saddle point,
// repeat. `radius` keeps the window off the markers and the next corners. A
// corner whose fit is no saddle, or jumps out of the window, stays put.
constexpr double kSaddleBlurSigma = 1.2;

void refine_saddle(const cv::Mat& grey, std::vector<cv::Point2f>& corners, int radius, double sigma) {
  cv::Mat smooth;
  grey.convertTo(smooth, CV_32F);
  cv::GaussianBlur(smooth, smooth, cv::Size(0, 0), sigma);
  const int side = 2 * radius + 1;
  Eigen::MatrixXd A(side * side, 6);
  for (int dy = -radius, row = 0; dy <= radius; ++dy)
    for (int dx = -radius; dx <= radius; ++dx, ++row) A.row(row) << dx * dx, dx * dy, dy * dy, dx, dy, 1;
  const auto solver = A.colPivHouseholderQr();
  for (auto& corner : corners) {
    Eigen::Vector2d p(corner.x, corner.y);
    bool ok = true;
    for (int iteration = 0; iteration < 6 && ok; ++iteration) {
      // The window centred on the estimate itself, so that the fit is symmetric about it.
      cv::Mat patch;
      cv::getRectSubPix(smooth, cv::Size(side, side), cv::Point2f(float(p.x()), float(p.y())), patch, CV_32F);
      Eigen::VectorXd b(side * side);
      for (int y = 0, row = 0; y < side; ++y)
        for (int x = 0; x < side; ++x, ++row) b(row) = patch.at<float>(y, x);
      const Eigen::VectorXd q = solver.solve(b);
      Eigen::Matrix2d H;
      H << 2 * q(0), q(1), q(1), 2 * q(2);
      const Eigen::Vector2d offset = H.determinant() < 0 ? Eigen::Vector2d(-H.inverse() * Eigen::Vector2d(q(3), q(4)))
                                                         : Eigen::Vector2d::Constant(1e9);
      ok = offset.cwiseAbs().maxCoeff() <= radius;
      if (ok) p += offset;
      if (offset.norm() < 1e-3) break;
    }
    if (ok) corner = cv::Point2f(float(p.x()), float(p.y()));
  }
}

// What detection needs of a board, made once: OpenCV's ChArUco board and
// dictionary are only read while detecting, so every thread shares them.
class Detector {
 public:
  explicit Detector(const Board& board)
      : board_(board), charuco_(board.options.type == "charuco" ? detail::aruco_board(board.options) : nullptr) {}

  BoardView detect(const cv::Mat& grey, int min_corners) const {
    BoardView view = charuco_ ? detect_charuco(grey) : detect_chessboard(grey);
    if (int(view.ids.size()) < min_corners) return {};
    return view;
  }

 private:
  BoardView detect_charuco(const cv::Mat& grey) const {
    std::vector<std::vector<cv::Point2f>> marker_corners;
    std::vector<int> marker_ids;
    // Parameters per call: cheap, and nothing is shared that OpenCV might write.
    cv::aruco::detectMarkers(grey, charuco_->dictionary, marker_corners, marker_ids,
                             cv::aruco::DetectorParameters::create());
    BoardView view;
    if (marker_ids.empty()) return view;
    std::vector<cv::Point2f> corners;
    cv::aruco::interpolateCornersCharuco(marker_corners, marker_ids, grey, charuco_, corners, view.ids);
    // OpenCV 4.6 leaves its ChArUco corners half a pixel down and right of
    // where they are (opencv/opencv#25539) and ~0.18 px from them on rendered
    // boards; the saddle fit below starts from them and lands within ~0.09 px.
    double marker_px = 0;
    for (const auto& m : marker_corners) marker_px += cv::norm(m[0] - m[1]) / marker_corners.size();
    const double square_px = marker_px * board_.options.square_m / board_.options.marker_m;
    refine_saddle(grey, corners, square_px >= 14 ? 3 : 2, kSaddleBlurSigma);
    for (const auto& c : corners) view.pixels.emplace_back(c.x, c.y);
    return view;
  }

  BoardView detect_chessboard(const cv::Mat& grey) const {
    const int nx = board_.options.squares_x - 1, ny = board_.options.squares_y - 1;
    std::vector<cv::Point2f> found;
    if (!cv::findChessboardCorners(grey, cv::Size(nx, ny), found,
                                   cv::CALIB_CB_ADAPTIVE_THRESH | cv::CALIB_CB_NORMALIZE_IMAGE))
      return {};
    const auto at = [&](int x, int y) { return found[y * nx + x]; };

    // The refinement window must not reach the next corner.
    double spacing = INFINITY;
    for (int y = 0; y < ny; ++y)
      for (int x = 0; x < nx; ++x) {
        if (x + 1 < nx) spacing = std::min(spacing, cv::norm(at(x + 1, y) - at(x, y)));
        if (y + 1 < ny) spacing = std::min(spacing, cv::norm(at(x, y + 1) - at(x, y)));
      }
    const int half = std::clamp(int(spacing / 2), 1, 5);  // 11 x 11 at most
    cv::cornerSubPix(grey, found, cv::Size(half, half), cv::Size(-1, -1),
                     cv::TermCriteria(cv::TermCriteria::EPS | cv::TermCriteria::COUNT, 50, 0.001));

    // Row by row, as the ids run: OpenCV starts at the corner next to the
    // black top-left square of a board with squares_x + squares_y odd,
    // whichever way it is turned (tests/calibrate/detection_test.cpp); a
    // symmetric board starts at the top of the image (make_board warns).
    BoardView view;
    for (int id = 0; id < nx * ny; ++id) {
      view.ids.push_back(id);
      view.pixels.emplace_back(found[id].x, found[id].y);
    }
    return view;
  }

  const Board& board_;
  cv::Ptr<cv::aruco::CharucoBoard> charuco_;
};

}  // namespace

BoardView detect_board(const Image8& image, const Board& board, int min_corners) {
  return Detector(board).detect(grey_mat(image), min_corners);
}

std::vector<BoardView> detect_board_in_take(const TakeInfo& take, const Board& board, int threads, int min_corners) {
  std::vector<std::pair<int, int>> images;  // camera, frame: in the order of the result
  for (int c = 0; c < int(take.cameras.size()); ++c)
    for (int f = 0; f < take.frames; ++f)
      if (take.has_image(take.cameras[c], f)) images.emplace_back(c, f);
  const bool bayer = is_bayer(take.pixel_format);

  const Detector detector(board);
  std::vector<BoardView> views(images.size());
  Progress progress("detecting board", int64_t(images.size()), "images");
  ThreadPool pool(threads);
  pool.parallel_for(0, int64_t(images.size()), [&](int64_t i) {
    const auto [camera, frame] = images[i];
    Image8 image = read_image_u8(take.image_path(take.cameras[camera], frame));
    // Raw Bayer frames, made grey without moving a pixel.
    if (bayer && image.channels == 1) image = debayer_grey(image, take.pixel_format);
    views[i] = detector.detect(grey_mat(image), min_corners);
    views[i].camera = camera;
    views[i].frame = frame;
    progress.advance();
  });
  progress.finish();
  std::erase_if(views, [](const BoardView& v) { return v.ids.empty(); });
  return views;
}

}  // namespace tega::calibrate
