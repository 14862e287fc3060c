#pragma once
// The calibration take's ChArUco board: its geometry in OpenCV 4.6's board
// coordinates (x right, y down across the printed side, z into the board,
// origin at the corner of the squares; inner corner id = y * (squares_x - 1)
// + x at ((x + 1), (y + 1)) * square), poses through the capture volume, and
// its printed texture, drawn by OpenCV (only when built with OpenCV).

#include <cstdint>
#include <string>
#include <vector>

#include "tega/core/geometry.h"
#include "tega/core/image.h"
#include "tega/core/mesh.h"

namespace tega::synth {

struct CharucoBoardSpec {
  int squares_x = 7;
  int squares_y = 5;  // odd: OpenCV 4.6 changed the layout of boards with an even count
  double square_m = 0.04;
  double marker_m = 0.03;
  std::string dictionary = "DICT_5X5_100";
  double margin_squares = 0.5;  // white border around the squares
  int pixels_per_square = 120;  // of the texture
};

// Inner chessboard corners in board coordinates, indexed by ChArUco id.
std::vector<Eigen::Vector3d> charuco_corners(const CharucoBoardSpec& board);

// Board-to-world poses: the board's centre wanders through a box around the
// head's position, its printed side tilted towards the cameras.
std::vector<RigidTransform> charuco_board_poses(const CharucoBoardSpec& board, int frames, uint64_t seed);

// The printed side (border included) as a grid of quads wound
// counter-clockwise seen from the front (-z in board coordinates), with UVs
// over the texture; `back` winds the other way for the unprinted side.
Mesh charuco_board_mesh(const CharucoBoardSpec& board, int cells_x, int cells_y, bool back);

// Whether this build can draw the board (OpenCV with aruco).
bool charuco_texture_available();
// Grey texture, border included, row 0 at the board's top (y = -margin).
// Throws tega::Error without OpenCV or for an unknown dictionary.
ImageF charuco_texture(const CharucoBoardSpec& board);

}  // namespace tega::synth
