// Multiface KRT rig files (docs/rig-files.md#multiface-krt).
#include <string>

#include "rig_text.h"
#include "tega/core/error.h"
#include "tega/core/files.h"
#include "tega/core/rig.h"

namespace tega {
namespace {

// KRT translations are in millimetres; tega works in metres.
constexpr double kMillimetresPerMetre = 1000.0;

}  // namespace

Rig read_krt(const std::filesystem::path& file, int width, int height) {
  rig_text::LineReader in(file);
  Rig rig;
  while (const std::optional<std::string> name_line = in.next()) {
    const std::vector<std::string_view> words = rig_text::split_words(*name_line);
    if (words.empty()) continue;
    if (words.size() != 1) in.fail("expected a camera name (one word), found '" + *name_line + "'");

    Camera camera;
    camera.name = std::string(words[0]);
    camera.width = width;
    camera.height = height;
    const std::string of_camera = " of camera '" + camera.name + "'";
    const auto row = [&](size_t count, const std::string& what) {
      const std::optional<std::string> line = in.next();
      if (!line) in.fail("expected " + what + of_camera + ", found the end of the file");
      return in.numbers(*line, count, what + of_camera);
    };
    for (int r = 0; r < 3; ++r) {
      const std::vector<double> k = row(3, "row " + std::to_string(r + 1) + " of K");
      camera.K.row(r) << k[0], k[1], k[2];
    }
    const std::vector<double> d = row(5, "the distortion k1 k2 p1 p2 k3");
    std::copy(d.begin(), d.end(), camera.distortion.begin());
    for (int r = 0; r < 3; ++r) {
      const std::vector<double> rt = row(4, "row " + std::to_string(r + 1) + " of [R|t]");
      camera.world_to_camera.R.row(r) << rt[0], rt[1], rt[2];
      camera.world_to_camera.t(r) = rt[3] / kMillimetresPerMetre;
    }
    if (const std::optional<std::string> end = in.next();
        end && !rig_text::split_words(*end).empty())
      in.fail("expected a blank line after camera '" + camera.name + "', found '" + *end + "'");
    rig.cameras.push_back(std::move(camera));
  }
  rig.validate(file);
  return rig;
}

void write_krt(const Rig& rig, const std::filesystem::path& file) {
  rig.validate(file);
  std::string text;
  for (const Camera& c : rig.cameras) {
    const Eigen::Matrix3d& K = c.K;
    const Eigen::Matrix3d& R = c.world_to_camera.R;
    const Eigen::Vector3d t_mm = c.world_to_camera.t * kMillimetresPerMetre;
    text += c.name + "\n";
    for (int r = 0; r < 3; ++r) text += rig_text::format_numbers({K(r, 0), K(r, 1), K(r, 2)}) + "\n";
    text += rig_text::format_numbers({c.distortion.begin(), c.distortion.end()}) + "\n";
    for (int r = 0; r < 3; ++r)
      text += rig_text::format_numbers({R(r, 0), R(r, 1), R(r, 2), t_mm(r)}) + "\n";
    text += "\n";
  }
  write_text_atomic(file, text);
}

}  // namespace tega
