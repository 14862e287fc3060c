// Built only with OpenCV (TEGA_HAVE_OPENCV): draws the board with OpenCV
// 4.6's own CharucoBoard, so that its detector agrees with what we print.

#include <opencv2/aruco/charuco.hpp>
#include <opencv2/core.hpp>

#include <cmath>
#include <map>

#include "tega/core/error.h"
#include "tega/synth/charuco_board.h"

namespace tega::synth {

bool charuco_texture_available() { return true; }

ImageF charuco_texture(const CharucoBoardSpec& b) {
  static const std::map<std::string, cv::aruco::PREDEFINED_DICTIONARY_NAME> dictionaries = {
      {"DICT_4X4_50", cv::aruco::DICT_4X4_50},   {"DICT_4X4_100", cv::aruco::DICT_4X4_100},
      {"DICT_5X5_50", cv::aruco::DICT_5X5_50},   {"DICT_5X5_100", cv::aruco::DICT_5X5_100},
      {"DICT_6X6_100", cv::aruco::DICT_6X6_100}, {"DICT_6X6_250", cv::aruco::DICT_6X6_250}};
  const auto it = dictionaries.find(b.dictionary);
  if (it == dictionaries.end()) throw Error("unknown ArUco dictionary '" + b.dictionary + "'");
  const auto dictionary = cv::aruco::getPredefinedDictionary(it->second);
  const auto board = cv::aruco::CharucoBoard::create(b.squares_x, b.squares_y, float(b.square_m), float(b.marker_m),
                                                     dictionary);
  const int pps = b.pixels_per_square;
  cv::Mat squares;
  board->draw(cv::Size(b.squares_x * pps, b.squares_y * pps), squares, 0, 1);

  const int margin = static_cast<int>(std::lround(b.margin_squares * pps));
  ImageF out(squares.cols + 2 * margin, squares.rows + 2 * margin, 1, 1.0f);
  for (int y = 0; y < squares.rows; ++y)
    for (int x = 0; x < squares.cols; ++x) out.at(x + margin, y + margin, 0) = squares.at<uint8_t>(y, x) / 255.0f;
  return out;
}

}  // namespace tega::synth
