#pragma once
// Where the subject is in a view: the pixels that differ from the clean plate
// (the same camera's image of the empty studio), cleaned up and with holes
// filled. Work outside the mask is skipped; a frame whose subject too few
// views see is refused.

#include <cstdint>
#include <vector>

#include "tega/core/image.h"

namespace tega::mvs {

struct MaskOptions {
  bool use_clean_plate = true;       // with a clean_plate take in the capture
  double threshold = 0.08;           // colour difference (largest channel, [0, 1]) that counts as subject
  int close_px = 4;                  // gaps narrower than this are closed
  int dilate_px = 6;                 // the mask grows by this much, to keep edges
  double min_view_share = 0.002;     // a view sees the subject when its mask covers this share of the image

  template <class V>
  void visit(V& v) {
    v("use_clean_plate", use_clean_plate, "Mask each view by its difference from the capture's clean plate, when it has one.");
    v("threshold", threshold, "Colour difference from the clean plate (largest channel, 0..1) that counts as subject.");
    v("close_px", close_px, "Close gaps in the mask narrower than this many pixels.");
    v("dilate_px", dilate_px, "Grow the mask by this many pixels.");
    v("min_view_share", min_view_share, "A view sees the subject when its mask covers at least this share of it.");
  }
};

// Both images undistorted RGB of one camera. 255 = subject, 0 = not.
std::vector<uint8_t> subject_mask(const Image8& frame, const Image8& clean_plate, const MaskOptions& options);

}  // namespace tega::mvs
