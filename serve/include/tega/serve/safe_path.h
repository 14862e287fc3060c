#pragma once
// Paths built from what a request names, checked before anything is read.

#include <filesystem>
#include <optional>

namespace tega::serve {

// `root / relative` resolved (symlinks followed) when it exists and lies
// inside root's own resolution; nullopt for an absolute `relative`, any
// ".." component, a missing file or a link that leads out of root.
std::optional<std::filesystem::path> resolve_inside(const std::filesystem::path& root,
                                                    const std::filesystem::path& relative);

}  // namespace tega::serve
