#include "tega/calibrate/board.h"

#include <cmath>
#include <map>

#include "aruco_board.h"
#include "tega/core/error.h"
#include "tega/core/log.h"
#include "tega/core/options.h"

namespace tega::calibrate {

namespace detail {

// The dictionaries tega synth prints boards with.
cv::Ptr<cv::aruco::Dictionary> aruco_dictionary(const std::string& name) {
  static const std::map<std::string, cv::aruco::PREDEFINED_DICTIONARY_NAME> dictionaries = {
      {"DICT_4X4_50", cv::aruco::DICT_4X4_50},   {"DICT_4X4_100", cv::aruco::DICT_4X4_100},
      {"DICT_5X5_50", cv::aruco::DICT_5X5_50},   {"DICT_5X5_100", cv::aruco::DICT_5X5_100},
      {"DICT_6X6_100", cv::aruco::DICT_6X6_100}, {"DICT_6X6_250", cv::aruco::DICT_6X6_250}};
  const auto it = dictionaries.find(name);
  if (it == dictionaries.end()) {
    std::string known;
    for (const auto& [key, value] : dictionaries) known += (known.empty() ? "" : ", ") + key;
    throw Error("unknown ArUco dictionary '" + name + "' (known: " + known + ")");
  }
  return cv::aruco::getPredefinedDictionary(it->second);
}

cv::Ptr<cv::aruco::CharucoBoard> aruco_board(const BoardOptions& o) {
  return cv::aruco::CharucoBoard::create(o.squares_x, o.squares_y, float(o.square_m), float(o.marker_m),
                                         aruco_dictionary(o.dictionary));
}

}  // namespace detail

Board make_board(const BoardOptions& o, const std::string& source) {
  const auto fail = [&](const std::string& message) { throw Error(source, message); };
  if (o.type != "charuco" && o.type != "chessboard") fail("type '" + o.type + "' is neither charuco nor chessboard");
  if (o.squares_x < 3 || o.squares_y < 3)
    fail("squares_x and squares_y must be at least 3, not " + std::to_string(o.squares_x) + " x " +
         std::to_string(o.squares_y));
  if (!(o.square_m > 0)) fail("square_m must be positive");
  if (!(o.margin_squares >= 0)) fail("margin_squares must not be negative");
  if (o.type == "charuco") {
    if (o.squares_y % 2 == 0)
      fail("a charuco board needs an odd squares_y, not " + std::to_string(o.squares_y) +
           ": OpenCV 4.6 lays out boards with an even row count differently from other versions, so their "
           "corners would not be where other tools expect them");
    if (!(o.marker_m > 0 && o.marker_m < o.square_m))
      fail("marker_m (" + std::to_string(o.marker_m) + ") must be positive and smaller than square_m (" +
           std::to_string(o.square_m) + ")");
    cv::Ptr<cv::aruco::Dictionary> dictionary;
    try {
      dictionary = detail::aruco_dictionary(o.dictionary);
    } catch (const Error& e) {
      fail(e.what());
    }
    const int markers = o.squares_x * o.squares_y / 2;  // one in every white square
    if (dictionary->bytesList.rows < markers)
      fail("dictionary " + o.dictionary + " has " + std::to_string(dictionary->bytesList.rows) +
           " markers, fewer than the board's " + std::to_string(markers));
  }
  if (o.type == "chessboard" && (o.squares_x + o.squares_y) % 2 == 0)
    logging::warn("%s: a %d x %d chessboard looks the same turned half a turn, so its corner ids follow the image "
                  "(first row at the top) and differ between cameras that see it turned; one odd and one even "
                  "count (e.g. 10 x 7) tells its ends apart",
                  source.c_str(), o.squares_x, o.squares_y);
  Board board{o, {}};
  for (int y = 1; y < o.squares_y; ++y)
    for (int x = 1; x < o.squares_x; ++x) board.corners.emplace_back(x * o.square_m, y * o.square_m, 0.0);
  return board;
}

Board load_board(const std::filesystem::path& file) {
  BoardOptions options;
  load_options(options, file);
  return make_board(options, file.string());
}

Image8 draw_board(const Board& board, int dpi) {
  const BoardOptions& o = board.options;
  if (dpi <= 0) throw Error("draw_board: dpi must be positive, not " + std::to_string(dpi));
  const int pps = static_cast<int>(std::lround(o.square_m / 0.0254 * dpi));  // pixels per square
  const int margin = static_cast<int>(std::lround(o.margin_squares * pps));
  const int width = o.squares_x * pps, height = o.squares_y * pps;
  cv::Mat squares;
  if (o.type == "charuco") {
    detail::aruco_board(o)->draw(cv::Size(width, height), squares, 0, 1);
  } else {
    // Top-left square black, as OpenCV's (and its ChArUco) boards are.
    squares = cv::Mat(height, width, CV_8UC1, cv::Scalar(255));
    for (int y = 0; y < o.squares_y; ++y)
      for (int x = y % 2; x < o.squares_x; x += 2) squares(cv::Rect(x * pps, y * pps, pps, pps)).setTo(0);
  }
  Image8 out(width + 2 * margin, height + 2 * margin, 1, 255);
  for (int y = 0; y < height; ++y)
    std::copy_n(squares.ptr<uint8_t>(y), width, &out.at(margin, y + margin, 0));
  return out;
}

}  // namespace tega::calibrate
