#pragma once
// OpenCV's own ChArUco board for a charuco Board: drawing and detection both
// go through it, so that what we print is what the detector looks for.
#include <opencv2/aruco/charuco.hpp>

#include "tega/calibrate/board.h"

namespace tega::calibrate::detail {

// Throws tega::Error for an unknown dictionary.
cv::Ptr<cv::aruco::Dictionary> aruco_dictionary(const std::string& name);
cv::Ptr<cv::aruco::CharucoBoard> aruco_board(const BoardOptions& options);

}  // namespace tega::calibrate::detail
