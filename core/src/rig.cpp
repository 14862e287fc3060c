#include "tega/core/rig.h"

#include <spdlog/fmt/fmt.h>

#include <Eigen/LU>
#include <algorithm>
#include <cctype>
#include <cmath>
#include <set>

#include "tega/core/error.h"

namespace tega {
namespace {

// Rotations read from files carry float32 round-off (Multiface stores ~7
// digits), so orthonormality is checked loosely; anything worse is a wrong
// matrix, not round-off.
constexpr double kRotationTolerance = 1e-5;

std::string name_problem(const std::string& name) {
  if (name.empty()) return "is empty";
  if (name == "." || name == "..") return "is not a usable directory name";
  if (std::any_of(name.begin(), name.end(), [](unsigned char c) { return std::isspace(c); }))
    return "contains whitespace";
  if (name.find_first_of("/\\") != std::string::npos) return "contains a path separator";
  return {};
}

void validate_camera(const Camera& camera, const std::filesystem::path& source) {
  const auto fail = [&](const std::string& what) {
    throw Error(source, "camera '" + camera.name + "': " + what);
  };
  if (const std::string problem = name_problem(camera.name); !problem.empty())
    fail("field 'name' " + problem);
  if (camera.width <= 0 || camera.height <= 0)
    fail(fmt::format("'width' and 'height' must be positive, got {} x {}", camera.width,
                     camera.height));
  const Eigen::Matrix3d& K = camera.K;
  if (!K.allFinite()) fail("field 'K' has a non-finite value");
  if (K(1, 0) != 0 || K(2, 0) != 0 || K(2, 1) != 0 || K(2, 2) != 1)
    fail("field 'K' must have the form [[fx, s, cx], [0, fy, cy], [0, 0, 1]]");
  if (!(K(0, 0) > 0) || !(K(1, 1) > 0))
    fail(fmt::format("field 'K' has a non-positive focal length (fx = {}, fy = {})", K(0, 0),
                     K(1, 1)));
  for (double c : camera.distortion)
    if (!std::isfinite(c)) fail("field 'distortion' has a non-finite value");
  const Eigen::Matrix3d& R = camera.world_to_camera.R;
  if (!R.allFinite()) fail("field 'R' has a non-finite value");
  const double error = (R.transpose() * R - Eigen::Matrix3d::Identity()).cwiseAbs().maxCoeff();
  if (error > kRotationTolerance)
    fail(fmt::format("field 'R' is not orthonormal (max |R^T R - I| = {:.3g})", error));
  if (R.determinant() < 0) fail("field 'R' is a reflection (determinant -1), not a rotation");
  if (!camera.world_to_camera.t.allFinite()) fail("field 't' has a non-finite value");
}

}  // namespace

const Camera& Rig::camera(std::string_view name) const {
  for (const Camera& c : cameras)
    if (c.name == name) return c;
  throw Error("the rig has no camera named '" + std::string(name) + "'");
}

bool Rig::contains(std::string_view name) const {
  return std::any_of(cameras.begin(), cameras.end(), [&](const Camera& c) { return c.name == name; });
}

std::vector<std::string> Rig::camera_names() const {
  std::vector<std::string> names;
  names.reserve(cameras.size());
  for (const Camera& c : cameras) names.push_back(c.name);
  return names;
}

void Rig::validate(const std::filesystem::path& source) const {
  if (cameras.empty()) throw Error(source, "the rig has no cameras");
  std::set<std::string_view> seen;
  for (const Camera& c : cameras) {
    validate_camera(c, source);
    if (!seen.insert(c.name).second)
      throw Error(source, "camera '" + c.name + "': duplicate camera name");
  }
}

}  // namespace tega
