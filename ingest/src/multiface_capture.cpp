#include "tega/ingest/multiface_capture.h"

#include <Eigen/SVD>

#include <charconv>
#include <cmath>
#include <sstream>

#include "tega/core/error.h"
#include "tega/core/files.h"

namespace tega::ingest {
namespace fs = std::filesystem;

namespace {

std::vector<std::string> words_of(const std::string& line) {
  std::istringstream in(line);
  std::vector<std::string> words;
  for (std::string w; in >> w;) words.push_back(w);
  return words;
}

double parse_number(const std::string& word, const fs::path& file, int line) {
  double value = 0;
  const auto [end, error] = std::from_chars(word.data(), word.data() + word.size(), value);
  if (error != std::errc() || end != word.data() + word.size() || !std::isfinite(value))
    throw Error(file, "line " + std::to_string(line) + ": malformed number '" + word + "'");
  return value;
}

}  // namespace

std::vector<MultifaceFrame> read_frame_list(const fs::path& file) {
  std::istringstream in(read_text_file(file));
  std::vector<MultifaceFrame> frames;
  int number = 0;
  for (std::string line; std::getline(in, line);) {
    ++number;
    const std::vector<std::string> words = words_of(line);
    if (words.empty()) continue;
    if (words.size() != 2) {
      throw Error(file, "line " + std::to_string(number) + ": expected '<expression> <frame>', found '" + line + "'");
    }
    frames.push_back({words[0], words[1]});
  }
  if (frames.empty()) throw Error(file, "lists no frames");
  return frames;
}

RigidTransform read_head_transform(const fs::path& file) {
  std::istringstream in(read_text_file(file));
  std::vector<std::vector<double>> rows;
  int number = 0;
  for (std::string line; std::getline(in, line);) {
    ++number;
    const std::vector<std::string> words = words_of(line);
    if (words.empty()) continue;
    if (words.size() != 4)
      throw Error(file, "line " + std::to_string(number) + ": expected a row of 4 numbers, found '" + line + "'");
    std::vector<double> row;
    for (const auto& w : words) row.push_back(parse_number(w, file, number));
    rows.push_back(row);
  }
  const bool homogeneous_row = rows.size() == 4 && rows[3] == std::vector<double>{0, 0, 0, 1};
  if (rows.size() != 3 && !homogeneous_row)
    throw Error(file, "expected 3 rows of [R | t] (or 4 with 0 0 0 1 last), found " + std::to_string(rows.size()));
  Eigen::Matrix<double, 3, 4> m;
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 4; ++c) m(r, c) = rows[r][c];
  RigidTransform pose = RigidTransform::from_matrix(m);
  if ((pose.R.transpose() * pose.R - Eigen::Matrix3d::Identity()).cwiseAbs().maxCoeff() > 1e-4 ||
      pose.R.determinant() <= 0)
    throw Error(file, "the head pose's 3x3 part is not a rotation");
  // Text files round the rotation; the nearest exact rotation keeps the
  // dataset's poses rigid.
  const Eigen::JacobiSVD<Eigen::Matrix3d> svd(pose.R, Eigen::ComputeFullU | Eigen::ComputeFullV);
  pose.R = svd.matrixU() * svd.matrixV().transpose();
  pose.t *= kMetresPerMillimetre;
  return pose;
}

Vertices read_tracked_vertices(const MultifaceCapture& capture, const MultifaceFrame& frame, int expected_vertices) {
  const fs::path bin = capture.mesh_bin(frame);
  Vertices vertices;
  if (fs::exists(bin)) {
    vertices = read_vertices_bin(bin, expected_vertices);
  } else {
    const fs::path obj = capture.mesh_obj(frame);
    if (!fs::exists(obj)) throw Error(bin, "is missing, and so is " + obj.filename().string() + " (tracked mesh)");
    vertices = read_obj(obj).positions;
    if (expected_vertices > 0 && vertices.rows() != expected_vertices) {
      throw Error(obj, "has " + std::to_string(vertices.rows()) + " vertices; the template has " +
                           std::to_string(expected_vertices));
    }
  }
  vertices *= static_cast<float>(kMetresPerMillimetre);
  return vertices;
}

}  // namespace tega::ingest
