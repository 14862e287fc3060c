#pragma once
// Fills a UvTriangleLookup from a template mesh (CPU, double precision).

#include <vector>

#include "tega/uvd/uv_lookup.h"

namespace tega::uvd {

struct LookupBuilder {
  static void build(UvTriangleLookup& lookup, const Mesh& mesh, const UvLookupOptions& options,
                    const std::vector<int32_t>& active_faces);
};

}  // namespace tega::uvd
