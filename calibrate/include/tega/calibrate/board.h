#pragma once
// Calibration boards (docs/calibration.md#board-files): a ChArUco board (the
// studio's) or a plain chessboard, from YAML. Board coordinates are
// OpenCV's: x right, y down across the printed side, z into the board,
// origin at the outer corner of the squares; inner corner id
// y * (squares_x - 1) + x sits at ((x + 1), (y + 1)) * square_m.
#include <filesystem>
#include <string>
#include <vector>

#include "tega/core/geometry.h"
#include "tega/core/image.h"

namespace tega::calibrate {

struct BoardOptions {
  std::string type = "charuco";  // charuco | chessboard
  int squares_x = 7;
  int squares_y = 5;  // charuco: odd (OpenCV 4.6 lays out even counts differently)
  double square_m = 0.04;
  double marker_m = 0.03;  // charuco only
  std::string dictionary = "DICT_5X5_100";  // charuco only
  double margin_squares = 0.5;  // white border of the printed board, in squares
  template <class V>
  void visit(V& v) {
    v("type", type, "charuco or chessboard.");
    v("squares_x", squares_x, "Squares across (inner corners: squares_x - 1).");
    v("squares_y", squares_y, "Squares down (inner corners: squares_y - 1); odd for charuco.");
    v("square_m", square_m, "Side of a square in metres, as printed (measure it): the rig's scale.");
    v("marker_m", marker_m, "charuco: side of an ArUco marker in metres.");
    v("dictionary", dictionary, "charuco: ArUco dictionary, e.g. DICT_5X5_100, DICT_4X4_50, DICT_6X6_250.");
    v("margin_squares", margin_squares, "White border around the squares, in squares (printing only).");
  }
};

struct Board {
  BoardOptions options;
  std::vector<Eigen::Vector3d> corners;  // board coordinates (z = 0), indexed by corner id
};

// Throws tega::Error naming `source` for an impossible board (even charuco
// rows, marker not smaller than the square, unknown dictionary ...).
Board make_board(const BoardOptions& options, const std::string& source = "board");
Board load_board(const std::filesystem::path& file);  // the whole file is the board's options

// The printable board at `dpi`, border included: grey, 8-bit.
Image8 draw_board(const Board& board, int dpi);

}  // namespace tega::calibrate
