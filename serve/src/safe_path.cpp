#include "tega/serve/safe_path.h"

#include <algorithm>

namespace tega::serve {

namespace fs = std::filesystem;

std::optional<fs::path> resolve_inside(const fs::path& root, const fs::path& relative) {
  if (relative.empty() || relative.has_root_path()) return std::nullopt;
  for (const fs::path& part : relative)
    if (part == "..") return std::nullopt;
  std::error_code error;
  const fs::path base = fs::canonical(root, error);
  if (error) return std::nullopt;
  const fs::path resolved = fs::canonical(base / relative, error);
  if (error) return std::nullopt;
  // Component-wise, so that /data/run2 is not taken to lie inside /data/run.
  const auto [base_end, resolved_end] = std::mismatch(base.begin(), base.end(), resolved.begin(), resolved.end());
  if (base_end != base.end()) return std::nullopt;
  return resolved;
}

}  // namespace tega::serve
