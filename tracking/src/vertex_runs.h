#pragma once
// Vertex index sets stored compactly in JSON, as sorted [first, last] runs.

#include <algorithm>
#include <nlohmann/json.hpp>
#include <vector>

namespace tega::tracking {

inline nlohmann::json vertex_runs(std::vector<int> vertices) {
  std::sort(vertices.begin(), vertices.end());
  nlohmann::json runs = nlohmann::json::array();
  for (size_t i = 0; i < vertices.size();) {
    size_t j = i;
    while (j + 1 < vertices.size() && vertices[j + 1] <= vertices[j] + 1) ++j;
    runs.push_back({vertices[i], vertices[j]});
    i = j + 1;
  }
  return runs;
}

}  // namespace tega::tracking
