#pragma once
// Finding the board's inner corners in the images of a calibration take.
#include <string>
#include <vector>

#include "tega/calibrate/board.h"
#include "tega/core/image.h"
#include "tega/core/take.h"

namespace tega::calibrate {

// The corners of the board one camera saw in one frame.
struct BoardView {
  int camera = 0;  // index into the take's cameras
  int frame = 0;
  std::vector<int> ids;                  // corner ids (Board::corners)
  std::vector<Eigen::Vector2d> pixels;   // sub-pixel positions, pixel (0,0) = centre of the top-left pixel
};

// The corners in one image (grey or RGB, 8-bit); none when the board is not
// seen or fewer than `min_corners` corners are found. ChArUco corners are
// corrected for OpenCV 4.6's +0.5 px refinement bias (opencv/opencv#25539).
BoardView detect_board(const Image8& image, const Board& board, int min_corners = 6);

// Every image of the take, on `threads` workers (0 = all) with progress.
// Returns the views with corners, ordered by camera then frame.
std::vector<BoardView> detect_board_in_take(const TakeInfo& take, const Board& board, int threads = 0,
                                            int min_corners = 6);

}  // namespace tega::calibrate
