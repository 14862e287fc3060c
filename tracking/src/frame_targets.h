#pragma once
// The targets a frame gives the fits: scan correspondences for the surface
// term, detected landmarks and followed flow for the image terms.

#include <vector>

#include "model_fit.h"
#include "optical_flow.h"
#include "surface_query.h"
#include "tega/landmarks/landmarks.h"
#include "tega/tracking/options.h"
#include "tega/tracking/tracker.h"

namespace tega::tracking {

// The posed model with its vertex normals, where the targets are sought from.
struct PosedModel {
  Vertices world;
  Vertices normals;
};
PosedModel posed_model(const HeadModel& model, const Vertices& world);

// Closest scan points of `vertices` within `max_distance_m` whose normals agree.
Term<SurfaceTarget> surface_targets(const PosedModel& posed, const std::vector<int>& vertices, const SurfaceQuery& scan,
                                    double max_distance_m, const SurfaceTermOptions& options);

// Distances of the fit vertices to the scan and how many found it.
void surface_residuals(const PosedModel& posed, const HeadModel& model, const SurfaceQuery& scan,
                       const SurfaceTermOptions& options, FrameResiduals& residuals);

// Whether each of `vertices` faces camera `eye` and is not hidden behind the scan.
std::vector<bool> visible_from(const Eigen::Vector3d& eye, const PosedModel& posed, const std::vector<int>& vertices,
                               const SurfaceQuery& scan);

// The inner landmarks (brows, eyes, nose, mouth: dlib's 17..67; the jaw line
// slides along the silhouette) detected in every camera with a photo, in a
// box around where the posed model's landmarks project.
Term<ImageTarget> landmark_targets(const HeadModel& model, const PosedModel& posed, const FrameObservation& frame,
                                   const std::vector<Camera>& cameras, const SurfaceQuery& scan,
                                   const landmarks::LandmarkDetector& detector, const LandmarkOptions& options);

// Where every vertex_step-th fit vertex, visible in a camera at the previous
// frame, went by that camera's flow.
Term<ImageTarget> flow_targets(const HeadModel& model, const PosedModel& previous, const SurfaceQuery& previous_scan,
                               const std::vector<Image8>& previous_images, const std::vector<Image8>& images,
                               const std::vector<Camera>& cameras, const FlowOptions& options);

// Root-mean-square reprojection error of image targets (pixels), -1 for none.
double reprojection_rms(const Term<ImageTarget>& term, const Vertices& world, const std::vector<Camera>& cameras);

TermScale scale_of(const ImageTermOptions& options);
TermScale scale_of(const SurfaceTermOptions& options);

}  // namespace tega::tracking
