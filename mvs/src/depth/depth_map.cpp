#include "tega/mvs/depth_map.h"

#include <algorithm>

namespace tega::mvs {

int64_t DepthMap::valid_pixels() const {
  return std::count_if(depth.begin(), depth.end(), [](float d) { return d > 0; });
}

}  // namespace tega::mvs
