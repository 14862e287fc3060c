// Boards drawn by tega and found again: on the printed image itself, under a
// known perspective warp, and in the virtual studio's calibration take
// against its ground truth.

#include <gtest/gtest.h>

#include <opencv2/imgproc.hpp>

#include <cmath>
#include <fstream>
#include <nlohmann/json.hpp>

#include "tega/calibrate/board.h"
#include "tega/calibrate/detection.h"
#include "tega/core/error.h"
#include "tega/core/rig.h"
#include "tega/core/take.h"
#include "tega/synth/charuco_board.h"
#include "tega/synth/virtual_studio.h"
#include "test_support.h"

namespace tega::calibrate {
namespace {

namespace fs = std::filesystem;

constexpr int kDpi = 100;

Board charuco_board() { return make_board(BoardOptions{}); }

Board chessboard() {
  BoardOptions o;
  o.type = "chessboard";
  o.squares_x = 9;
  o.squares_y = 6;
  return make_board(o);
}

// Where draw_board(board, kDpi) puts a corner: square boundaries fall
// between pixels, half a pixel before the pixel (centre) they start at.
Eigen::Vector2d drawn_position(const Board& board, int id) {
  const double pps = std::lround(board.options.square_m / 0.0254 * kDpi);
  const double margin = std::lround(board.options.margin_squares * pps);
  return board.corners[id].head<2>() * (pps / board.options.square_m) + Eigen::Vector2d::Constant(margin - 0.5);
}

cv::Mat as_mat(const Image8& image) {
  return cv::Mat(image.height, image.width, CV_8UC1, const_cast<uint8_t*>(image.pixels.data())).clone();
}

Image8 as_image(const cv::Mat& m) {
  Image8 image(m.cols, m.rows, 1);
  for (int y = 0; y < m.rows; ++y) std::copy_n(m.ptr<uint8_t>(y), m.cols, &image.at(0, y, 0));
  return image;
}

void expect_every_corner_where_drawn(const Board& board) {
  const Image8 image = draw_board(board, kDpi);
  const BoardView view = detect_board(image, board);
  ASSERT_EQ(view.ids.size(), board.corners.size());
  for (size_t i = 0; i < view.ids.size(); ++i)
    EXPECT_LT((view.pixels[i] - drawn_position(board, view.ids[i])).norm(), 0.1)
        << "corner " << view.ids[i] << " at " << view.pixels[i].transpose() << ", drawn at "
        << drawn_position(board, view.ids[i]).transpose();
}

TEST(Detection, FindsEveryCornerOfADrawnCharucoBoardWhereItIsDrawn) { expect_every_corner_where_drawn(charuco_board()); }

TEST(Detection, FindsEveryCornerOfADrawnChessboardWhereItIsDrawn) { expect_every_corner_where_drawn(chessboard()); }

// The drawn board seen at an angle, turned a quarter and a half turn: ids
// stay on their corners (for the chessboard, by its colours alone).
void expect_ids_follow_warp(const Board& board) {
  const Image8 image = draw_board(board, kDpi);
  const float w = float(image.width), h = float(image.height);
  const cv::Point2f from[] = {{-0.5f, -0.5f}, {w - 0.5f, -0.5f}, {w - 0.5f, h - 0.5f}, {-0.5f, h - 0.5f}};
  const std::vector<std::vector<cv::Point2f>> tos = {
      {{150, 120}, {1050, 60}, {1000, 830}, {110, 700}},   // perspective
      {{1000, 800}, {100, 850}, {160, 100}, {1050, 180}},  // and a half turn
      {{980, 60}, {1000, 900}, {200, 820}, {220, 120}},    // and a quarter turn
  };
  for (const auto& to : tos) {
    const cv::Mat H = cv::getPerspectiveTransform(from, to.data());
    // Warped at 4 x 4 samples a pixel and averaged: a plain bilinear warp
    // of the sharp board aliases its edges by a quarter pixel. Pixel (x, y)
    // averages the fine pixels whose centres lie around (4x + 1.5, 4y + 1.5).
    const cv::Mat fine = (cv::Mat_<double>(3, 3) << 4, 0, 1.5, 0, 4, 1.5, 0, 0, 1);
    cv::Mat supersampled, warped;
    cv::warpPerspective(as_mat(image), supersampled, fine * H, cv::Size(4 * 1150, 4 * 950), cv::INTER_LINEAR,
                        cv::BORDER_CONSTANT, cv::Scalar(128));
    cv::resize(supersampled, warped, cv::Size(1150, 950), 0, 0, cv::INTER_AREA);
    const BoardView view = detect_board(as_image(warped), board);
    ASSERT_EQ(view.ids.size(), board.corners.size()) << "warped to " << to[0] << " ...";
    for (size_t i = 0; i < view.ids.size(); ++i) {
      const Eigen::Vector2d p = drawn_position(board, view.ids[i]);
      const cv::Mat q = H * (cv::Mat_<double>(3, 1) << p.x(), p.y(), 1.0);
      const Eigen::Vector2d expected(q.at<double>(0) / q.at<double>(2), q.at<double>(1) / q.at<double>(2));
      EXPECT_LT((view.pixels[i] - expected).norm(), 0.3)
          << "corner " << view.ids[i] << " at " << view.pixels[i].transpose() << ", expected "
          << expected.transpose() << " (warped to " << to[0] << " ...)";
    }
  }
}

TEST(Detection, WarpedCharucoBoardKeepsItsIds) { expect_ids_follow_warp(charuco_board()); }

TEST(Detection, WarpedChessboardKeepsItsIds) { expect_ids_follow_warp(chessboard()); }

TEST(Detection, BlankImageHasNoView) {
  const Image8 blank(320, 240, 3, 200);
  EXPECT_TRUE(detect_board(blank, charuco_board()).ids.empty());
  EXPECT_TRUE(detect_board(blank, chessboard()).ids.empty());
}

TEST(Board, CornersAreInBoardCoordinates) {
  const Board board = chessboard();
  ASSERT_EQ(board.corners.size(), 8u * 5u);
  EXPECT_TRUE(board.corners[0].isApprox(Eigen::Vector3d(0.04, 0.04, 0)));
  EXPECT_TRUE(board.corners[3 * 8 + 2].isApprox(Eigen::Vector3d(3 * 0.04, 4 * 0.04, 0)));
  const synth::CharucoBoardSpec spec;
  EXPECT_EQ(charuco_board().corners, synth::charuco_corners(spec));
}

std::string error_of(const BoardOptions& o) {
  try {
    make_board(o, "studio.yaml");
  } catch (const Error& e) {
    return e.what();
  }
  return "";
}

TEST(Board, RejectsImpossibleBoards) {
  BoardOptions even;
  even.squares_y = 6;
  EXPECT_NE(error_of(even).find("odd squares_y"), std::string::npos) << error_of(even);
  EXPECT_NE(error_of(even).find("studio.yaml"), std::string::npos);
  even.type = "chessboard";
  EXPECT_EQ(error_of(even), "");

  BoardOptions big_marker;
  big_marker.marker_m = big_marker.square_m;
  EXPECT_NE(error_of(big_marker).find("marker_m"), std::string::npos) << error_of(big_marker);

  BoardOptions dictionary;
  dictionary.dictionary = "DICT_9X9_1";
  EXPECT_NE(error_of(dictionary).find("DICT_9X9_1"), std::string::npos) << error_of(dictionary);

  BoardOptions type;
  type.type = "circles";
  EXPECT_NE(error_of(type).find("circles"), std::string::npos) << error_of(type);

  BoardOptions small;
  small.squares_x = 2;
  EXPECT_NE(error_of(small).find("at least 3"), std::string::npos) << error_of(small);
}

TEST(Board, LoadsYamlAndNamesTheFileOfAnUnknownKey) {
  test::TempDir tmp;
  test::write_text(tmp / "board.yaml", "type: chessboard\nsquares_x: 10\nsquares_y: 7\nsquare_m: 0.025\n");
  const Board board = load_board(tmp / "board.yaml");
  EXPECT_EQ(board.options.type, "chessboard");
  EXPECT_EQ(board.corners.size(), 9u * 6u);
  EXPECT_DOUBLE_EQ(board.options.square_m, 0.025);

  test::write_text(tmp / "typo.yaml", "squares_x: 7\nsquare_size: 0.04\n");
  try {
    load_board(tmp / "typo.yaml");
    FAIL() << "no error";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("typo.yaml"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("square_size"), std::string::npos) << e.what();
  }

  test::write_text(tmp / "even.yaml", "squares_y: 4\n");
  try {
    load_board(tmp / "even.yaml");
    FAIL() << "no error";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("even.yaml"), std::string::npos) << e.what();
  }
}

RigidTransform pose_from_json(const nlohmann::json& rows) {
  Eigen::Matrix<double, 3, 4> m;
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 4; ++c) m(r, c) = rows[r][c];
  return RigidTransform::from_matrix(m);
}

TEST(Detection, FindsTheVirtualStudiosBoardWhereTheGroundTruthPutsIt) {
  if (!synth::charuco_texture_available()) GTEST_SKIP() << "tega_synth built without OpenCV: no calibration take";
  test::TempDir tmp;
  synth::Options o;
  o.studio.cameras = 3;
  o.studio.width = 640;
  o.studio.height = 480;
  o.calibration_frames = 4;
  o.frames = 1;
  o.takes = {"expressions"};
  o.test_takes = {};
  o.fine_subdivisions = 0;
  const fs::path root = tmp / "capture";
  synth::render_virtual_studio(o, root);

  const Rig rig = read_rig_json(root / "rig.json");
  std::ifstream in(root / "ground_truth/calibration/frames.json");
  const nlohmann::json gt = nlohmann::json::parse(in);
  BoardOptions bo;
  for (const char* key : {"squares_x", "squares_y"}) ASSERT_TRUE(gt["board"].contains(key));
  bo.squares_x = gt["board"]["squares_x"];
  bo.squares_y = gt["board"]["squares_y"];
  bo.square_m = gt["board"]["square_m"];
  bo.marker_m = gt["board"]["marker_m"];
  bo.dictionary = gt["board"]["dictionary"];
  const Board board = make_board(bo);
  std::map<int, RigidTransform> board_to_world;
  for (const auto& f : gt["frames"]) board_to_world[f["index"]] = pose_from_json(f["board_to_world"]);

  const TakeInfo take = read_take(root / "takes/calibration");
  const std::vector<BoardView> views = detect_board_in_take(take, board, 2);
  ASSERT_GE(views.size(), 4u) << "views with the board";
  double squared = 0;
  int corners = 0;
  for (size_t v = 0; v < views.size(); ++v) {
    const BoardView& view = views[v];
    if (v > 0) EXPECT_LT(std::pair(views[v - 1].camera, views[v - 1].frame), std::pair(view.camera, view.frame));
    EXPECT_GE(view.ids.size(), 6u);
    const Camera& camera = rig.camera(take.cameras[view.camera]);
    for (size_t i = 0; i < view.ids.size(); ++i) {
      const auto p = camera.project(board_to_world.at(view.frame).apply(board.corners[view.ids[i]]));
      ASSERT_TRUE(p);
      squared += (view.pixels[i] - *p).squaredNorm();
      ++corners;
    }
  }
  const double rms = std::sqrt(squared / corners);
  EXPECT_LT(rms, 0.5) << "pixels RMS over " << corners << " corners in " << views.size() << " views";
}

}  // namespace
}  // namespace tega::calibrate
