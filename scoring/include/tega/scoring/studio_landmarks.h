#pragma once
// The true 68 landmarks of a virtual-studio capture's photos
// (docs/virtual-studio.md): the true coarse mesh's landmark vertices
// (the model's idx_to_landmark_verts) projected through the true rig's
// distorted cameras. Training samples for a landmark predictor and the truth
// a detected landmark is scored against.

#include <Eigen/Core>
#include <filesystem>
#include <map>
#include <string>
#include <vector>

#include "tega/core/mesh.h"
#include "tega/core/rig.h"
#include "tega/core/take.h"
#include "tega/scoring/studio_truth.h"
#include "tega/landmarks/landmarks.h"

namespace tega::scoring {

// The model's 68 landmark vertices, dlib's order (vertex_indices.json's
// idx_to_landmark_verts). Throws tega::Error naming the file.
std::vector<int> model_landmark_vertices(const std::filesystem::path& model_directory);

// One performance frame's true landmarks in the world.
struct StudioFrameLandmarks {
  std::string take;
  int frame = 0;
  std::vector<Eigen::Vector3d> positions, normals;  // 68, metres
  Eigen::Vector3d face_front;                       // unit: where the face looks (head space +z)
  Eigen::Vector3d centre;                           // the landmarks' mean
};

// A capture's truth, read once for the many images of a training set.
class StudioLandmarkTruth {
 public:
  // `landmark_vertices`: the model's numbering (model_landmark_vertices).
  // Throws tega::Error naming the file that is missing or malformed.
  StudioLandmarkTruth(const std::filesystem::path& capture, const std::vector<int>& landmark_vertices);

  const Rig& rig() const { return rig_; }
  StudioFrameLandmarks frame(const std::string& take, int frame) const;
  // Degrees between the face's front and the direction to the camera.
  double view_angle_deg(const StudioFrameLandmarks& frame, const std::string& camera) const;
  // The photo with its landmarks; those on the far side of the head (normal
  // facing away from the camera) are NaN. The box: all 68 grown by 15 %, the
  // convention of landmarks::train_landmark_predictor.
  landmarks::LandmarkSample sample(const StudioFrameLandmarks& frame, const std::string& camera) const;

 private:
  std::filesystem::path truth_;
  Rig rig_;
  std::map<std::string, TakeInfo> takes_;                     // the performance takes
  std::map<std::string, std::map<int, Eigen::Matrix3d>> head_rotations_;  // take -> frame -> of head_to_world
  std::vector<int> studio_landmark_vertices_;                 // the template's numbering
  Mesh template_;
};

// One photo's sample; reads the whole truth: for a few images, not a training set.
landmarks::LandmarkSample studio_landmark_sample(const std::filesystem::path& capture, const std::string& take,
                                      const std::string& camera, int frame, const std::vector<int>& landmark_vertices);

}  // namespace tega::scoring
