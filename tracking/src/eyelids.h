#pragma once
// How far each eyelid is closed, seen in the photos. A closing lid slides
// over the eyeball along the surface, so the scan barely tells an open eye
// from a closed one; the photos do: where the open model shows eyeball, the
// photo shows eye (sclera, iris) or, under a closed lid, skin. For each eye
// the fraction of its open aperture that the photos show covered is
// compared with the fraction the model's lid covers at each value of the
// eye's blink shape, which gives the range of blink values that agree.

#include <map>
#include <string>
#include <vector>

#include "tega/core/camera.h"
#include "tega/core/image.h"
#include "tega/tracking/head_model.h"
#include "tega/tracking/options.h"
#include "tega/tracking/tracker.h"

namespace tega::tracking {

// One eye of the model, found once (head space of the model's mean head).
struct ModelEye {
  int blink = -1;                     // the expression shape that closes it
  std::vector<int> eyeball_samples;   // eyeball vertices whose visibility is tested
  std::vector<int> skin_ring;         // skin around the eye that the blink does not move: the skin's colour
};

struct ModelEyes {
  std::vector<ModelEye> eyes;
  Triangles lids;  // skin triangles around the eyes: all that can hide an eyeball
};

// The model's eyes: its eyeball vertices split into left and right, each
// paired with the shape of `options.shapes` that moves the skin around it
// most. Throws tega::Error naming the model directory when a shape is
// missing, there are no eyeball vertices, or two eyes pair with one shape.
ModelEyes find_model_eyes(const HeadModel& model, const EyelidOptions& options);

// What the photos say of one eye in one frame.
struct EyelidObservation {
  int blink = -1;            // the eye's blink shape
  int samples = 0;           // eyeball points the open model shows to the cameras
  double seen_covered = 0;   // the fraction of them the photos show as skin
  double covered = 0;        // ... measured from the subject's open eye (0: as open, 1: closed)
  double low = 0, high = 1;  // blink values whose lid covers as much (within options.tolerance)
};

// Observes every eye in the frame's photos with the model posed in `state`
// (`head`: the head-space vertices of that state, expressions and
// corrections included). `open_eyes_covered` (per blink shape, see
// SubjectIdentity) is where closing starts; empty when fitting the identity.
// An eye fewer than options.min_samples points of which are seen is left out.
std::vector<EyelidObservation> observe_eyelids(const ModelEyes& eyes, const HeadModel& model, const Vertices& head,
                                               const HeadState& state, const std::vector<Image8>& images,
                                               const std::vector<Camera>& cameras,
                                               const std::map<std::string, double>& open_eyes_covered,
                                               const EyelidOptions& options);

}  // namespace tega::tracking
